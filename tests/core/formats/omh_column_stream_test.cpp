// The deepest level of a version 4 .omh written while the hierarchy is built
// (formats/omh_column_stream.hpp): through a real pipeline on real files, into a file on the
// test's temporary folder (direct I/O where its file system allows it).
#include "formats/omh_column_stream.hpp"
#include "formats/omh_reader.hpp"
#include "formats/omh_writer.hpp"
#include "pipeline/build_pipeline.hpp"
#include "test_files.hpp"

#include <fcntl.h>
#include <filesystem>
#include <gtest/gtest.h>
#include <unistd.h>

namespace omicron {
namespace {

using test::readBytes;
using test::TempDir;

PipelineOptions pipelineOptions(LeafCollapse collapse, PointStorage storage) {
    PipelineOptions options;
    options.build.maxLevel = 6;
    options.build.collapse = collapse;
    options.storage = storage;
    options.preview = false;
    return options;
}

// Whether files in `folder` take direct I/O (a disk; a tmpfs since Linux 6.6): there the
// stream writes.
bool directIoIn(const std::filesystem::path& folder) {
    const std::filesystem::path probe = folder / "direct-io-probe";
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_DIRECT | O_CLOEXEC, 0600);
    if (fd < 0) {
        return false;
    }
    ::close(fd);
    std::filesystem::remove(probe);
    return true;
}

struct StreamedSave {
    OmhStreamedColumns streamed;
    std::uint64_t streamBytes = 0;
    OmhSaveReport report;
    std::vector<std::uint8_t> bytes;      // the save with the stream
    std::vector<std::uint8_t> afterBytes; // the same hierarchy saved after the build
    std::uint64_t columnBytes = 0;        // what the deepest level's columns hold
};

// Builds `input` with a stream started before the build, saves with what it wrote, and saves
// the same hierarchy again without it.
StreamedSave buildStreamed(const std::string& input, const TempDir& dir, LeafCollapse collapse,
                           PointStorage storage = PointStorage::Exact) {
    StreamedSave out;
    BuildPipeline pipeline;
    const PipelineOptions options = pipelineOptions(collapse, storage);
    AtomicFileWriter file(dir.file("streamed.omh"));
    OmhColumnStream stream(file, options.build.maxLevel,
                           [&pipeline] { return pipeline.sortedCloud(); });
    const PipelineResult result = pipeline.run(input, options);
    out.streamed = stream.finish();
    out.streamBytes = stream.bytesWritten();
    const omh::BuildInfo info = omhBuildInfo(options.build, result.stats);
    OmhWriteOptions write;
    write.streamedColumns = &out.streamed;
    out.report = writeOmh(file, *pipeline.hierarchy(), info, write);
    writeOmh(dir.file("after.omh"), *pipeline.hierarchy(), info);
    out.bytes = readBytes(dir.file("streamed.omh"));
    out.afterBytes = readBytes(dir.file("after.omh"));
    const omh::Header header = OmhReader(dir.file("after.omh")).header();
    for (const omh::Column& column : header.columns()) {
        out.columnBytes += header.levels.back().points * column.bytes;
    }
    return out;
}

class OmhColumnStreamFiles : public ::testing::TestWithParam<const char*> {};

// LAS (colours, intensities, LAS fields), PLY with normals, LAZ with every field varying.
INSTANTIATE_TEST_SUITE_P(SharedData, OmhColumnStreamFiles,
                         ::testing::Values("autzen_trim.las", "bunny.ply",
                                           "laz/terrascan_fmt8.laz"));

TEST_P(OmhColumnStreamFiles, StreamedDuringTheBuildGivesTheBytesOfASaveAfterIt) {
    OMICRON_REQUIRE_SHARED_FILE(input, GetParam());
    TempDir dir;
    const StreamedSave save = buildStreamed(input, dir, LeafCollapse::Off);
    EXPECT_EQ(save.bytes, save.afterBytes);
    ASSERT_GT(save.columnBytes, 0u);
    if (!directIoIn(dir.path())) {
        EXPECT_EQ(save.streamed.cloud, nullptr) << "no direct I/O here: nothing streams";
        EXPECT_EQ(save.report.streamedBytesUsed, 0u);
        return;
    }
    ASSERT_NE(save.streamed.cloud, nullptr) << "nothing was streamed";
    EXPECT_EQ(save.streamBytes, save.columnBytes);
    EXPECT_EQ(save.report.streamedBytesUsed, save.columnBytes)
        << "the save wrote the columns again instead of using the stream's";
    OmhReader reader(dir.file("streamed.omh"));
    reader.verify();
    EXPECT_EQ(reader.header().version, 4u);
}

TEST(OmhColumnStream, ADeepestLevelThatIsNotTheWholeCloudIsWrittenAgain) {
    OMICRON_REQUIRE_SHARED_FILE(input, "autzen_trim.las");
    TempDir dir;
    // Paper collapse drops points and moves leaves up a level: the stream wrote the cloud,
    // the level holds less.
    const StreamedSave save = buildStreamed(input, dir, LeafCollapse::Paper);
    EXPECT_EQ(save.report.streamedBytesUsed, 0u);
    EXPECT_EQ(save.bytes, save.afterBytes) << "the stream's bytes were left in the file";
    OmhReader(dir.file("streamed.omh")).verify();
}

TEST(OmhColumnStream, APackedCloudIsNotStreamed) {
    OMICRON_REQUIRE_SHARED_FILE(input, "autzen_trim.las");
    TempDir dir;
    const StreamedSave save = buildStreamed(input, dir, LeafCollapse::Off, PointStorage::Packed);
    EXPECT_EQ(save.streamed.cloud, nullptr) << "no array of the packed store is a column";
    EXPECT_EQ(save.streamBytes, 0u);
    EXPECT_EQ(save.bytes, save.afterBytes);
}

TEST(OmhColumnStream, AStreamDroppedBeforeTheBuildEndsLeavesNothingBehind) {
    OMICRON_REQUIRE_SHARED_FILE(input, "autzen_trim.las");
    TempDir dir;
    {
        BuildPipeline pipeline;
        AtomicFileWriter file(dir.file("dropped.omh"));
        OmhColumnStream stream(file, 6, [&pipeline] { return pipeline.sortedCloud(); });
        pipeline.run(input, pipelineOptions(LeafCollapse::Off, PointStorage::Exact));
        // The save fails (not shown): the stream and the file go without finish() or commit().
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

} // namespace
} // namespace omicron
