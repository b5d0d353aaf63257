// Ctrl+C (SIGINT) and SIGTERM for long commands: the first signal only sets a flag, which the
// command checks between batches; it then throws Interrupted, the stack unwinds (temporary
// files are removed by their writers' destructors, so nothing partial is left) and main exits
// with status 130. A second signal ends the process at once, as it would without handlers.
#pragma once

#include "pipeline/build_pipeline.hpp"

#include <atomic>
#include <stdexcept>
#include <string>

namespace omicron::cli {

class Interrupted : public std::runtime_error {
public:
    Interrupted() : std::runtime_error("interrupted") {}
};

// Installs the handlers (once) and returns the flag they set.
const std::atomic<bool>& watchInterrupts();

// Throws Interrupted once a watched signal arrived.
void throwIfInterrupted();

// pipeline.run(path, options) with Ctrl+C watched: a signal cancels the run (the pipeline
// stops at its next batch, chunk or level), which then throws Interrupted.
PipelineResult runInterruptibly(BuildPipeline& pipeline, const std::string& path,
                                const PipelineOptions& options);

} // namespace omicron::cli
