// Loads a .omh hierarchy file top-down, level by level (the paper's pipeline 3), into an
// omicron::Hierarchy that a render front traverses exactly like a built one.
//
// The loaded hierarchy indexes a cloud in CloudOrder::NodeOrder: the held points of every
// node concatenated in node order (level 0 first). Each loaded node holds a range:
// sampleIndices == nullptr, coveredBegin = its first point in that cloud and coveredCount =
// pointCount (the subtree's input points are not part of a saved hierarchy). Children are
// contiguous via firstChild/childCount and nodes of a level are in Morton order, as built.
//
// Progressive protocol: load() marks the hierarchy complete before it publishes level 0 (so
// every published node counts as settled), then for each level reads and verifies its node
// records and point records, writes the points and splat attributes, publishes the cloud's
// new end and then the level's nodes (publishNodes, release), and calls onLevel. A front
// starts at the root and descends only into children below nodeCount(level + 1).
#pragma once

#include "build/hierarchy.hpp"
#include "formats/omh_format.hpp"
#include "io/file_stream.hpp"

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace omicron {

class OmhRecordDecoder;

// True when `path` should be opened with OmhReader: its first 8 bytes are the .omh magic, or
// its name ends in ".omh" (any case). Never throws.
bool isOmhFile(const std::string& path);

class OmhReader {
public:
    // Reads and checks the header, the level table and the footer (magic, checksums, counts,
    // offsets) and the file size against them. Throws InputError naming the file, the byte
    // and the section: EmptyFile, UnknownFormat, Truncated (the file ends inside SECTION),
    // CountMismatch, UnsupportedFeature (version, byte order), MalformedHeader.
    explicit OmhReader(const std::string& path);

    const omh::Header& header() const { return m_header; }

    // The hierarchy load() fills (created on the first call, any thread). Throws InputError
    // UnsupportedFeature when the file holds 2^32 points or more (nodes index the cloud with
    // 32 bits).
    std::shared_ptr<const Hierarchy> hierarchy();

    // Loads nodes only and pages their points in on demand under `budgetBytes`
    // (formats/omh_pager.hpp): for a file whose points do not fit in memory. Call before
    // hierarchy() and load(). Throws InputError when the file cannot be opened again.
    void pageOnDemand(std::uint64_t budgetBytes);
    bool pagedOnDemand() const { return m_pagedBudget > 0; }
    // Bytes the points of the whole file take in memory once loaded (what paging avoids).
    std::uint64_t residentBytesOfAllPoints() const;

    using LevelCallback = std::function<void(int level)>;

    // Loads every level, top-down, on the calling thread (paged: the node records only) (a renderer may read hierarchy()
    // meanwhile). Each section's checksum is verified before anything of it is published.
    // `cancel` is checked between levels. Call at most once. Throws InputError naming the
    // section: MalformedValue (checksum mismatch, a node or point that breaks the format's
    // rules), Truncated (the file shrank).
    void load(const LevelCallback& onLevel = {}, const std::atomic<bool>* cancel = nullptr);

    // Reads every section and compares its checksum, building nothing (bounded memory).
    // Throws InputError MalformedValue naming the first damaged section.
    void verify();

private:
    void createHierarchy();
    std::vector<OctreeNode> readNodes(int level, std::vector<std::uint8_t>& childMasks,
                                      std::vector<morton::Code>& expectedCodes,
                                      std::uint64_t firstPoint);
    void readPoints(int level, const std::vector<OctreeNode>& nodes, std::uint64_t firstPoint);
    // Version 4: the bytes [begin, end) (fewer than omh::kColumnAlignment) are zero, or an
    // InputError names the first that is not.
    void checkPadding(std::uint64_t begin, std::uint64_t end);
    // A columnar level's checksum against the digests of its columns and sparse splat
    // attributes, or an InputError naming the level's columns.
    void checkColumnarChecksum(const omh::LevelEntry& entry,
                               const std::vector<std::uint64_t>& digests) const;
    // ...and the padding after each column of the columnar level `entry`.
    void checkColumnPadding(const omh::LevelEntry& entry);
    // Version 4's deepest level: its columns straight into the cloud.
    void readColumnarPoints(int level, const std::vector<OctreeNode>& nodes,
                            std::uint64_t firstPoint);
    // Version 3: the splat attributes of the level's sparse nodes, after its records.
    void readSparseSplats(int level, const std::vector<OctreeNode>& nodes,
                          const OmhRecordDecoder& decoder, oms::PayloadChecksum& checksum);

    FileStream m_stream;
    omh::Header m_header;
    omh::RecordLayout m_layout;
    std::once_flag m_created;
    std::shared_ptr<SortedCloud> m_cloud;
    std::shared_ptr<Hierarchy> m_hierarchy;
    std::vector<std::uint8_t> m_block;
    bool m_loadCalled = false;
    std::uint64_t m_pagedBudget = 0; // > 0: points paged in on demand
};

// "the node table of level 3 (bytes 1024-2047)" etc.: the section holding byte `offset`.
std::string omhSectionAt(const omh::Header& header, std::uint64_t offset);
// The section of a level's payload checksum: its point records, and (version 3) its sparse
// nodes' splat attributes when it has any.
std::string omhPayloadName(const omh::Header& header, const omh::LevelEntry& level);

} // namespace omicron
