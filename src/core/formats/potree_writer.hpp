// Exports a finished hierarchy in the Potree 2.0 format, so that the result opens in Potree and
// the other viewers that read PotreeConverter 2's output: a folder with
//   metadata.json   version "2.0", points, hierarchy {firstChunkSize, stepSize, depth},
//                   offset, scale, spacing, boundingBox, encoding "DEFAULT", attributes
//   hierarchy.bin   the node records in chunks (formats/potree_hierarchy.hpp)
//   octree.bin      each node's points, uncompressed (formats/potree_attributes.hpp)
//
// The octree is additive, as Potree's is: each input point is stored once, in the shallowest
// node that holds it (formats/potree_additive.hpp), so the node counts and metadata.json's
// "points" add up to the input count, less the points the paper's leaf collapse dropped (the
// summary and metadata.json's description say how many).
//
// Geometry as PotreeConverter 2 writes it: boundingBox is the cubic box (the minimum corner of
// the cloud's bounds, the largest extent on every axis), which is omicron's unit cube in source
// units, so each Potree node's box (halved by Potree's child index) is the omicron cell; offset
// is the box's minimum, spacing its edge / 128, scale edge / 2^30 (PotreeConverter's finest).
// Positions are stored as floor(unit x 2^30): a point stays inside its node's box.
//
// The folder appears complete or not at all: everything is written into a temporary folder
// beside it, renamed into place at the end (io/atomic_folder.hpp); an error or a cancel
// removes the temporary folder and leaves the target as it was.
#pragma once

#include "build/hierarchy.hpp"
#include "formats/potree_attributes.hpp"
#include "io/atomic_file_writer.hpp"
#include "io/atomic_folder.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace omicron {

struct PotreeExportOptions {
    std::string name = "omicron"; // metadata.json's name
    int stepSize = 4;             // hierarchy levels per chunk, as PotreeConverter 2 writes
    // The points the hierarchy was built from, for the count of dropped points. 0: the cloud's
    // point count, right for a built hierarchy; a loaded .omh's cloud holds the parents'
    // copies too, so pass its header's input count.
    std::uint64_t inputPoints = 0;
    // Checked after each node: once set, the export stops with PotreeExportCancelled.
    const std::atomic<bool>* cancel = nullptr;
    // Called on the exporting thread after each node: held points gone through, of all the
    // nodes hold (parents' copies included, so it reaches total exactly at the end).
    std::function<void(std::uint64_t done, std::uint64_t total)> onProgress;
};

struct PotreeExportSummary {
    std::uint64_t nodes = 0;         // nodes in hierarchy.bin
    std::uint64_t points = 0;        // points in octree.bin, each input point once
    std::uint64_t inputPoints = 0;   // what the hierarchy was built from
    std::uint64_t droppedPoints = 0; // inputPoints - points: the paper's leaf collapse
    std::uint64_t chunks = 0;        // hierarchy chunks
    std::uint64_t octreeBytes = 0;
    int depth = 0;
    // How far an exported position (stored x scale + offset) may lie from the input point, in
    // source units: the point store's rounding (a float in the unit cube: 2^-25 of the edge;
    // packed: half a level-21 cell, 2^-22) plus one quantisation step (2^-30). For a loaded
    // .omh, the input is the positions the file stores.
    double positionTolerance = 0.0;
};

// The export stopped because PotreeExportOptions::cancel was set; nothing was left behind.
class PotreeExportCancelled : public std::runtime_error {
public:
    explicit PotreeExportCancelled(const std::string& folder)
        : std::runtime_error(folder + ": export cancelled") {}
};

// Writes the Potree folder `folder` from the complete `hierarchy` (its points in memory). An
// existing `folder` is replaced only when it is empty or holds nothing but a Potree export's
// files (metadata.json, hierarchy.bin, octree.bin, log.txt). Throws OutputError naming the
// folder (an incomplete or paged hierarchy, a hierarchy whose parents are not samples of their
// children, a folder that may not be replaced, a write error) or PotreeExportCancelled.
PotreeExportSummary exportPotree(const Hierarchy& hierarchy, const std::string& folder,
                                 const PotreeExportOptions& options = {});

// The export's target, opened before the hierarchy is built, so that a folder that may not be
// replaced, or beside which nothing can be written, fails before any work: a temporary folder
// beside it (removed unless an export commits it). Throws OutputError naming the folder.
std::unique_ptr<AtomicFolder> openPotreeExportFolder(const std::string& folder);
// The same export into `target` (from openPotreeExportFolder), which it commits.
PotreeExportSummary exportPotree(const Hierarchy& hierarchy, AtomicFolder& target,
                                 const PotreeExportOptions& options = {});

} // namespace omicron
