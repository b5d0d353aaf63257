// LAS reader, for uncompressed LAS and for LAZ (compressed LAS, COPC included): see
// point_reader.hpp for the contract every reader keeps.
#pragma once

#include "io/point_reader.hpp"

namespace omicron {

// Parses the header (for LAZ also the compression record and the chunk table) and runs the
// bounds pre-pass when needed; throws InputError.
std::unique_ptr<PointReader> openLasReader(const std::string& path, const OpenOptions& options);

} // namespace omicron
