#include "output_check.hpp"

#include "io/atomic_file_writer.hpp"

namespace omicron::cli {

void checkOutputWritable(const std::string& path) {
    const AtomicFileWriter probe(path); // nameless until committed: dropped without a trace
}

} // namespace omicron::cli
