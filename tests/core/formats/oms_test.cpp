// The .oms sorted stream: what the writer puts on disk reads back bit for bit into a
// SortedCloud, in order and range by range, and every damaged, truncated, padded or unsorted
// file is rejected with its specific error, file name and byte offset.
#include "formats/oms_format.hpp"
#include "formats/oms_reader.hpp"
#include "formats/oms_writer.hpp"
#include "io/input_error.hpp"
#include "io/point_reader.hpp"
#include "run_process.hpp"
#include "sort/morton_sorter.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <functional>
#include <gtest/gtest.h>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace omicron {
namespace {

const CubeTransform kCube{{500000.25, 4000000.5, -12.5}, 123.5};
const glm::dvec3 kOffset{1000.0, 2000.0, 0.0};
const AttributeSet kAllAttributes =
    AttributeSet(Attribute::Normal) | Attribute::Color | Attribute::Intensity;

template <typename T> T field(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
    T value;
    std::memcpy(&value, &bytes.at(offset), sizeof value);
    return value;
}

template <typename T> void setField(std::vector<std::uint8_t>& bytes, std::size_t offset, T value) {
    std::memcpy(&bytes.at(offset), &value, sizeof value);
}

// A scan-like unsorted batch: random positions in the unit cube, exact duplicates, the cube's
// corners (1.0 lands in the last cell), and every requested attribute filled with noise.
PointBatch makeBatch(std::size_t count, AttributeSet attributes, std::uint32_t seed = 11) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    PointBatch batch;
    batch.attributes = attributes;
    for (std::size_t i = 0; i < count; ++i) {
        glm::vec3 p(unit(random), unit(random), 0.6f * unit(random));
        if (i == 0) {
            p = glm::vec3(0.0f);
        } else if (i == 1) {
            p = glm::vec3(1.0f, 1.0f, 0.6f);
        } else if (i % 7 == 0) {
            p = batch.positions[i - 1];
        }
        batch.positions.push_back(p);
        if (attributes.has(Attribute::Normal)) {
            batch.normals.emplace_back(unit(random) - 0.5f, unit(random) - 0.5f, unit(random));
        }
        if (attributes.has(Attribute::Color)) {
            batch.colors.emplace_back(random() % 256, random() % 256, i % 256);
        }
        if (attributes.has(Attribute::Intensity)) {
            batch.intensities.push_back(static_cast<std::uint16_t>(random() % 65536));
        }
        for (std::size_t b = 0; b < attributes.lasBytes(); ++b) {
            batch.las.push_back(static_cast<std::uint8_t>(random()));
        }
    }
    return batch;
}

// Sorts a batch with the real incremental sorter.
std::shared_ptr<const SortedCloud> sortBatch(const PointBatch& batch) {
    CloudInfo info;
    info.path = "generated";
    info.pointCount = batch.size();
    info.attributes = batch.attributes;
    info.cube = kCube;
    info.sourceOffset = kOffset;
    SortOptions options;
    options.chunks = 4;
    IncrementalMortonSorter sorter(info, options);
    sorter.add(batch);
    sorter.sortAndEmit([](const SortedCloud&, std::size_t, std::size_t) {});
    EXPECT_TRUE(sorter.cloud()->complete());
    return sorter.cloud();
}

template <typename T> bool sameBits(std::span<const T> a, std::span<const T> b, std::size_t n) {
    return a.size() >= n && b.size() >= n && std::memcmp(a.data(), b.data(), n * sizeof(T)) == 0;
}

void expectSameCloud(const SortedCloud& expected, const SortedCloud& got) {
    const std::size_t n = expected.sortedEnd();
    ASSERT_EQ(got.sortedEnd(), n);
    EXPECT_EQ(got.cube(), expected.cube());
    EXPECT_EQ(got.sourceOffset(), expected.sourceOffset());
    EXPECT_EQ(got.attributes(), expected.attributes());
    EXPECT_TRUE(sameBits(expected.positions(), got.positions(), n));
    EXPECT_EQ(got.normals().size(), expected.normals().size());
    EXPECT_TRUE(expected.normals().empty() || sameBits(expected.normals(), got.normals(), n));
    EXPECT_EQ(got.colors().size(), expected.colors().size());
    EXPECT_TRUE(expected.colors().empty() || sameBits(expected.colors(), got.colors(), n));
    EXPECT_EQ(got.intensities().empty(), expected.intensities().empty());
    EXPECT_EQ(got.lasColumn().empty(), expected.lasColumn().empty());
    const std::size_t lasBytes = expected.attributes().lasBytes();
    for (std::size_t i = 0; i < n; ++i) {
        if (!expected.intensities().empty()) {
            ASSERT_EQ(got.intensities()[i], expected.intensities()[i]) << i;
        }
        if (lasBytes != 0) {
            ASSERT_EQ(std::memcmp(got.lasRecord(i), expected.lasRecord(i), lasBytes), 0) << i;
        }
    }
}

// What the consumer saw, call by call.
struct RangeLog {
    std::vector<std::pair<std::size_t, std::size_t>> ranges;
    std::vector<std::size_t> sortedEndAtCall;
    std::vector<bool> completeAtCall;

    SortedRangeConsumer consumer() {
        return [this](const SortedCloud& cloud, std::size_t begin, std::size_t end) {
            ranges.emplace_back(begin, end);
            sortedEndAtCall.push_back(cloud.sortedEnd());
            completeAtCall.push_back(cloud.complete());
        };
    }
};

// Every range starts where the previous one ended, is published, and continues the order.
void expectRangesInOrder(const RangeLog& log, const SortedCloud& cloud, std::size_t count) {
    std::size_t previousEnd = 0;
    for (std::size_t r = 0; r < log.ranges.size(); ++r) {
        const auto [begin, end] = log.ranges[r];
        ASSERT_EQ(begin, previousEnd) << "range " << r;
        ASSERT_LT(begin, end) << "range " << r;
        ASSERT_GE(log.sortedEndAtCall[r], end) << "range " << r;
        if (begin > 0) {
            ASSERT_GE(cloud.code(begin), cloud.code(begin - 1)) << "range " << r;
        }
        for (std::size_t i = begin + 1; i < end; ++i) {
            ASSERT_LE(cloud.code(i - 1), cloud.code(i)) << "point " << i;
        }
        previousEnd = end;
    }
    EXPECT_EQ(previousEnd, count);
}

struct ReadBack {
    std::shared_ptr<SortedCloud> cloud;
    OmsInfo info;
    ReadSummary summary;
    RangeLog log;
};

ReadBack readOms(const std::string& path, const ReadOptions& options = {}) {
    ReadBack back;
    OmsReader reader(path);
    back.info = reader.info();
    back.cloud = reader.cloud();
    back.summary = reader.read(back.log.consumer(), options);
    return back;
}

InputError catchInputError(const std::function<void()>& action) {
    try {
        action();
    } catch (const InputError& error) {
        return error;
    }
    ADD_FAILURE() << "expected an InputError, nothing was thrown";
    return InputError(InputErrorKind::CannotOpen, "", InputLocation::none(), "nothing thrown");
}

// Opens and reads the whole file, expecting InputError of `kind` naming `path` (and the byte).
InputError expectReadError(const std::string& path, InputErrorKind kind,
                           std::optional<std::uint64_t> byte = std::nullopt) {
    const InputError error = catchInputError([&] {
        OmsReader reader(path);
        reader.read([](const SortedCloud&, std::size_t, std::size_t) {});
    });
    EXPECT_EQ(error.kind(), kind) << error.what();
    EXPECT_EQ(error.path(), path);
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
    if (byte) {
        EXPECT_EQ(error.location().unit, InputLocation::Unit::Byte) << error.what();
        EXPECT_EQ(error.location().value, *byte) << error.what();
        EXPECT_NE(std::string(error.what()).find("byte " + std::to_string(*byte)),
                  std::string::npos)
            << error.what();
    }
    return error;
}

bool mentions(const InputError& error, const std::string& text) {
    return std::string(error.what()).find(text) != std::string::npos;
}

std::size_t fileCount(const std::filesystem::path& folder) {
    std::size_t count = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(folder)) {
        ++count;
    }
    return count;
}

std::uint64_t footerStart(const std::vector<std::uint8_t>& bytes) {
    return bytes.size() - oms::kFooterBytes;
}

// Rewrites the header checksum after a deliberate edit, so the edit itself is what is tested.
void resealHeader(std::vector<std::uint8_t>& bytes) {
    setField(bytes, oms::header::kChecksum, oms::headerChecksum(bytes.data()));
}

// Rewrites the footer's payload checksum after a deliberate edit of the records.
void resealPayload(std::vector<std::uint8_t>& bytes) {
    oms::PayloadChecksum checksum;
    checksum.update(bytes.data() + oms::kHeaderBytes, footerStart(bytes) - oms::kHeaderBytes);
    setField(bytes, footerStart(bytes) + oms::footer::kChecksum, checksum.digest());
}

// A small valid file with every attribute (29-byte records).
struct SmallFile {
    test::TempDir dir;
    std::shared_ptr<const SortedCloud> cloud;
    std::string path;
    std::vector<std::uint8_t> bytes;

    explicit SmallFile(std::size_t count = 50, AttributeSet attributes = kAllAttributes) {
        cloud = sortBatch(makeBatch(count, attributes));
        path = dir.file("small.oms");
        writeOms(path, *cloud, count);
        bytes = test::readBytes(path);
    }

    // Writes a modified copy beside the original and returns its path.
    std::string variant(const std::string& name, const std::vector<std::uint8_t>& content) const {
        const std::string variantPath = dir.file(name);
        test::writeBytes(variantPath, content);
        return variantPath;
    }
};

// ---------------------------------------------------------------------------------------------

TEST(OmsFormat, RecordLayoutPacksTheAttributesInOrder) {
    EXPECT_EQ(oms::RecordLayout::of({}).bytes, 12u);
    EXPECT_EQ(oms::RecordLayout::of(Attribute::Normal).bytes, 24u);
    EXPECT_EQ(oms::RecordLayout::of(Attribute::Color).bytes, 15u);
    EXPECT_EQ(oms::RecordLayout::of(Attribute::Intensity).bytes, 14u);
    const oms::RecordLayout all = oms::RecordLayout::of(kAllAttributes);
    EXPECT_EQ(all.normalOffset, 12u);
    EXPECT_EQ(all.colorOffset, 24u);
    EXPECT_EQ(all.intensityOffset, 27u);
    EXPECT_EQ(all.bytes, 29u);
}

TEST(OmsFormat, WriterPutsEveryFieldAtItsDocumentedOffset) {
    const SmallFile file;
    const std::vector<std::uint8_t>& bytes = file.bytes;
    ASSERT_EQ(bytes.size(), 128u + 50u * 29u + 24u);
    EXPECT_EQ(std::memcmp(bytes.data(), "OMICRONS", 8), 0);
    EXPECT_EQ(field<std::uint32_t>(bytes, 8), 2u);
    EXPECT_EQ(bytes[12], 0x04);
    EXPECT_EQ(bytes[13], 0x03);
    EXPECT_EQ(bytes[14], 0x02);
    EXPECT_EQ(bytes[15], 0x01);
    EXPECT_EQ(field<std::uint64_t>(bytes, 16), 50u);
    EXPECT_EQ(bytes[24], 21);
    EXPECT_EQ(bytes[25], kAllAttributes.bits());
    EXPECT_EQ(field<std::uint16_t>(bytes, 26), 29u);
    EXPECT_EQ(field<double>(bytes, 32), kCube.origin.x);
    EXPECT_EQ(field<double>(bytes, 40), kCube.origin.y);
    EXPECT_EQ(field<double>(bytes, 48), kCube.origin.z);
    EXPECT_EQ(field<double>(bytes, 56), kCube.edge);
    EXPECT_EQ(field<double>(bytes, 64), kOffset.x);
    EXPECT_EQ(field<double>(bytes, 72), kOffset.y);
    EXPECT_EQ(field<double>(bytes, 80), kOffset.z);
    for (std::size_t at : {28u, 29u, 30u, 31u}) {
        EXPECT_EQ(bytes[at], 0) << "byte " << at;
    }
    for (std::size_t at = 88; at < 120; ++at) {
        EXPECT_EQ(bytes[at], 0) << "byte " << at;
    }
    EXPECT_EQ(field<std::uint64_t>(bytes, 120), oms::headerChecksum(bytes.data()));

    // Record 7: float x y z, float nx ny nz, u8 r g b, u16 intensity.
    const std::size_t record = 128 + 7 * 29;
    EXPECT_EQ(field<glm::vec3>(bytes, record), file.cloud->positions()[7]);
    EXPECT_EQ(field<glm::vec3>(bytes, record + 12), file.cloud->normals()[7]);
    EXPECT_EQ(field<glm::u8vec3>(bytes, record + 24), file.cloud->colors()[7]);
    EXPECT_EQ(field<std::uint16_t>(bytes, record + 27), file.cloud->intensities()[7]);

    const std::size_t footer = 128 + 50 * 29;
    EXPECT_EQ(std::memcmp(bytes.data() + footer, "OMSEND\0\0", 8), 0);
    EXPECT_EQ(field<std::uint64_t>(bytes, footer + 8), 50u);
    oms::PayloadChecksum payload;
    payload.update(bytes.data() + 128, 50 * 29);
    EXPECT_EQ(field<std::uint64_t>(bytes, footer + 16), payload.digest());
}

// ---------------------------------------------------------------------------------------------

class OmsRoundTripAttributes : public ::testing::TestWithParam<std::uint8_t> {};

// The parameter is the attribute bits; with NIR (a LAS 1.4 format 8 cloud) 5 extra bytes too.
TEST_P(OmsRoundTripAttributes, GeneratedCloudReadsBackBitExact) {
    const std::uint8_t bits = GetParam();
    const AttributeSet attributes =
        AttributeSet::fromBits(bits, (bits & static_cast<std::uint8_t>(Attribute::Nir)) ? 5 : 0);
    ASSERT_TRUE(attributes.valid());
    test::TempDir dir;
    const std::string path = dir.file("generated.oms");
    const std::size_t count = 3001;
    const auto sorted = sortBatch(makeBatch(count, attributes, GetParam()));
    writeOms(path, *sorted, count);

    // Random attributes: no column is uniform, every record holds them all.
    EXPECT_EQ(oms::uniformColumnsOf(*sorted).bits, 0);
    const std::size_t recordBytes = oms::RecordLayout::of(attributes).bytes;
    EXPECT_EQ(std::filesystem::file_size(path), 128 + count * recordBytes + 24);
    EXPECT_EQ(fileCount(dir.path()), 1u);

    ReadOptions options;
    options.batchPoints = 500;
    const ReadBack back = readOms(path, options);
    EXPECT_EQ(back.info.path, path);
    EXPECT_EQ(back.info.version, 2u);
    EXPECT_EQ(back.info.pointCount, count);
    EXPECT_EQ(back.info.sortDepth, 21);
    EXPECT_EQ(back.info.attributes, attributes);
    EXPECT_EQ(back.info.recordBytes, recordBytes);
    EXPECT_EQ(back.info.fileBytes, 128 + count * recordBytes + 24);
    EXPECT_EQ(back.info.cube, kCube);
    EXPECT_EQ(back.info.sourceOffset, kOffset);
    EXPECT_EQ(back.summary.pointsDelivered, count);
    EXPECT_EQ(back.summary.batches, 7u);
    EXPECT_FALSE(back.summary.cancelled);
    EXPECT_TRUE(back.cloud->complete());
    expectSameCloud(*sorted, *back.cloud);
    expectRangesInOrder(back.log, *back.cloud, count);
}

INSTANTIATE_TEST_SUITE_P(OmsEveryAttributeSet, OmsRoundTripAttributes,
                         ::testing::Values<std::uint8_t>(0, 1, 2, 3, 4, 5, 6, 7, 0x08, 0x0e,
                                                         0x1e, 0x3e, 0x3f),
                         [](const ::testing::TestParamInfo<std::uint8_t>& info) {
                             return "Bits" + std::to_string(info.param);
                         });

// Pipeline 1 writing pipeline 2's file: the real reader and sorter over a real scan, the
// stream written range by range as the sorter emits it.
void roundTripRealFile(const std::string& source, const test::TempDir& dir) {
    auto reader = openPointCloud(source);
    const std::string streamedPath = dir.file("streamed.oms");
    const std::string wholePath = dir.file("whole.oms");
    OmsWriter writer;
    writer.open(streamedPath, reader->info().cube, reader->info().sourceOffset,
                reader->info().attributes, reader->info().pointCount);
    std::shared_ptr<const SortedCloud> sorted;
    SortOptions options;
    options.batchPoints = 10000;
    const SortSummary summary = sortPointCloud(
        *reader, options,
        [&](const SortedCloud& cloud, std::size_t begin, std::size_t end) {
            writer.append(cloud, begin, end);
        },
        [&](const IncrementalMortonSorter& sorter) { sorted = sorter.cloud(); });
    ASSERT_FALSE(summary.cancelled);
    EXPECT_EQ(writer.pointsWritten(), reader->info().pointCount);
    writer.finish();
    ASSERT_TRUE(sorted->complete());
    writeOms(wholePath, *sorted, sorted->sortedEnd());
    EXPECT_EQ(test::readBytes(streamedPath), test::readBytes(wholePath))
        << "streaming and one-shot writing must produce the same bytes";

    ReadOptions readOptions;
    readOptions.batchPoints = 4096;
    const ReadBack back = readOms(streamedPath, readOptions);
    EXPECT_EQ(back.info.pointCount, reader->info().pointCount);
    EXPECT_EQ(back.info.attributes, reader->info().attributes);
    EXPECT_EQ(back.info.cube, reader->info().cube);
    EXPECT_EQ(back.info.sourceOffset, reader->info().sourceOffset);
    EXPECT_TRUE(back.cloud->complete());
    expectSameCloud(*sorted, *back.cloud);
    expectRangesInOrder(back.log, *back.cloud, sorted->sortedEnd());
}

TEST(OmsRoundTrip, BunnyScanIsBitExact) {
    OMICRON_REQUIRE_SHARED_FILE(source, "bunny.ply");
    test::TempDir dir;
    roundTripRealFile(source, dir);
}

TEST(OmsRoundTrip, LionScanWithColourAndNormalsIsBitExact) {
    OMICRON_REQUIRE_SHARED_FILE(source, "lion.ply");
    test::TempDir dir;
    roundTripRealFile(source, dir);
}

TEST(OmsRoundTrip, WritesAPrefixOfAPartlySortedCloud) {
    test::TempDir dir;
    const auto sorted = sortBatch(makeBatch(1000, AttributeSet(Attribute::Color)));
    const std::string path = dir.file("prefix.oms");
    writeOms(path, *sorted, 400);
    const ReadBack back = readOms(path);
    ASSERT_EQ(back.info.pointCount, 400u);
    EXPECT_TRUE(sameBits(sorted->positions(), back.cloud->positions(), 400));
    EXPECT_TRUE(sameBits(sorted->colors(), back.cloud->colors(), 400));
}

// ---------------------------------------------------------------------------------------------

TEST(OmsReaderStreaming, ConsumerRunsBeforeTheWholeFileIsRead) {
    OMICRON_REQUIRE_SHARED_FILE(source, "bunny.ply");
    test::TempDir dir;
    auto reader = openPointCloud(source);
    std::shared_ptr<const SortedCloud> sorted;
    sortPointCloud(
        *reader, {}, [](const SortedCloud&, std::size_t, std::size_t) {},
        [&](const IncrementalMortonSorter& sorter) { sorted = sorter.cloud(); });
    const std::string path = dir.file("bunny.oms");
    writeOms(path, *sorted, sorted->sortedEnd());

    OmsReader oms(path);
    const std::size_t count = oms.info().pointCount;
    EXPECT_EQ(oms.cloud()->capacity(), count);
    EXPECT_EQ(oms.cloud()->sortedEnd(), 0u);
    RangeLog log;
    ReadOptions options;
    options.batchPoints = 1000;
    oms.read(log.consumer(), options);
    ASSERT_EQ(log.ranges.size(), (count + 999) / 1000);
    EXPECT_EQ(log.sortedEndAtCall.front(), 1000u);
    EXPECT_LT(log.sortedEndAtCall.front(), count);
    EXPECT_FALSE(log.completeAtCall.front());
    EXPECT_FALSE(log.completeAtCall.back()) << "complete only after the payload checksum";
    for (std::size_t r = 0; r < log.ranges.size(); ++r) {
        EXPECT_LE(log.ranges[r].second - log.ranges[r].first, 1000u);
        EXPECT_EQ(log.sortedEndAtCall[r], log.ranges[r].second);
    }
    EXPECT_TRUE(oms.cloud()->complete());
    expectRangesInOrder(log, *oms.cloud(), count);
}

TEST(OmsReaderStreaming, RangesHoldAtMostFourMebibytesOfRecords) {
    test::TempDir dir;
    const std::size_t count = 400000; // 12-byte records: 4.8 MB
    const auto sorted = sortBatch(makeBatch(count, {}));
    const std::string path = dir.file("large.oms");
    writeOms(path, *sorted, count);
    ReadOptions options;
    options.batchPoints = std::size_t{1} << 20;
    const ReadBack back = readOms(path, options);
    ASSERT_EQ(back.log.ranges.size(), 2u);
    EXPECT_EQ(back.log.ranges[0].second, (std::size_t{4} << 20) / 12);
    expectSameCloud(*sorted, *back.cloud);
}

TEST(OmsReaderStreaming, CancelStopsBetweenRangesAndLeavesTheCloudIncomplete) {
    const SmallFile file(3000);
    std::atomic<bool> cancel{false};
    ReadOptions options;
    options.batchPoints = 100;
    options.cancel = &cancel;
    OmsReader reader(file.path);
    std::size_t calls = 0;
    const ReadSummary summary = reader.read(
        [&](const SortedCloud&, std::size_t, std::size_t) {
            ++calls;
            cancel = true;
        },
        options);
    EXPECT_TRUE(summary.cancelled);
    EXPECT_EQ(calls, 1u);
    EXPECT_EQ(summary.pointsDelivered, 100u);
    EXPECT_EQ(reader.cloud()->sortedEnd(), 100u);
    EXPECT_FALSE(reader.cloud()->complete());
}

TEST(OmsReaderStreaming, ReadTwiceIsALogicError) {
    const SmallFile file;
    OmsReader reader(file.path);
    reader.read([](const SortedCloud&, std::size_t, std::size_t) {});
    EXPECT_THROW(reader.read([](const SortedCloud&, std::size_t, std::size_t) {}),
                 std::logic_error);
}

// ---------------------------------------------------------------------------------------------

TEST(OmsReaderErrors, TruncatedAnywhereIsTruncatedAtTheFileEnd) {
    const SmallFile file;
    const std::size_t recordsEnd = 128 + 50 * 29;
    const std::vector<std::size_t> lengths = {1,
                                              4,
                                              7,
                                              8,
                                              12,
                                              16,
                                              60,
                                              119,
                                              120,
                                              127, // inside the header
                                              128,
                                              129,
                                              157,
                                              128 + 10 * 29 + 5,
                                              recordsEnd - 1, // inside the records
                                              recordsEnd,
                                              recordsEnd + 1,
                                              recordsEnd + 8,
                                              recordsEnd + 16,
                                              recordsEnd + 23}; // footer
    for (std::size_t length : lengths) {
        SCOPED_TRACE("truncated to " + std::to_string(length) + " bytes");
        const std::string path = file.variant(
            "cut.oms", std::vector<std::uint8_t>(file.bytes.begin(),
                                                 file.bytes.begin() + static_cast<long>(length)));
        const InputError error = expectReadError(path, InputErrorKind::Truncated, length);
        if (length >= 128 && length < recordsEnd) {
            const std::size_t record = (length - 128) / 29;
            EXPECT_TRUE(mentions(error, "inside record " + std::to_string(record))) << error.what();
        } else if (length >= recordsEnd) {
            EXPECT_TRUE(mentions(error, "inside the 24-byte footer")) << error.what();
        } else {
            EXPECT_TRUE(mentions(error, "128-byte .oms header")) << error.what();
        }
    }
}

TEST(OmsReaderErrors, ExtraTrailingBytesAreACountMismatch) {
    const SmallFile file;
    for (std::size_t extra : {1u, 24u, 29u, 1000u}) {
        std::vector<std::uint8_t> padded = file.bytes;
        padded.resize(padded.size() + extra, 0);
        const std::string path = file.variant("padded.oms", padded);
        const InputError error =
            expectReadError(path, InputErrorKind::CountMismatch, file.bytes.size());
        EXPECT_TRUE(mentions(error, std::to_string(extra) + " more bytes")) << error.what();
    }
}

TEST(OmsReaderErrors, EveryHeaderByteFlipIsDetected) {
    const SmallFile file;
    for (std::uint8_t mask : {std::uint8_t{0x01}, std::uint8_t{0x80}, std::uint8_t{0xff}}) {
        for (std::size_t at = 0; at < oms::kHeaderBytes; ++at) {
            SCOPED_TRACE("byte " + std::to_string(at) + " xor " + std::to_string(mask));
            std::vector<std::uint8_t> damaged = file.bytes;
            damaged[at] ^= mask;
            const std::string path = file.variant("flipped.oms", damaged);
            if (at < 8) {
                const InputError error = expectReadError(path, InputErrorKind::UnknownFormat, 0);
                EXPECT_TRUE(mentions(error, "expected the .oms magic 'OMICRONS'")) << error.what();
            } else if (at < 12) {
                const InputError error =
                    expectReadError(path, InputErrorKind::UnsupportedFeature, 8);
                EXPECT_TRUE(mentions(error, "expected .oms format version 1")) << error.what();
            } else if (at < 16) {
                const InputError error = expectReadError(path, InputErrorKind::MalformedHeader, 12);
                EXPECT_TRUE(mentions(error, "endianness marker")) << error.what();
            } else {
                const InputError error =
                    expectReadError(path, InputErrorKind::MalformedHeader, 120);
                EXPECT_TRUE(mentions(error, "header checksum mismatch")) << error.what();
            }
        }
    }
}

TEST(OmsReaderErrors, EveryPayloadByteFlipIsDetected) {
    const SmallFile file(16);
    const std::size_t recordsEnd = 128 + 16 * 29;
    for (std::size_t at = oms::kHeaderBytes; at < recordsEnd; ++at) {
        SCOPED_TRACE("byte " + std::to_string(at));
        std::vector<std::uint8_t> damaged = file.bytes;
        damaged[at] ^= 0x01; // the smallest change: often not even a different Morton cell
        const std::string path = file.variant("flipped.oms", damaged);
        const InputError error = expectReadError(path, InputErrorKind::MalformedValue);
        const bool inPosition = (at - 128) % 29 < 12;
        if (inPosition) {
            EXPECT_TRUE(mentions(error, "payload checksum mismatch") ||
                        mentions(error, "out of Morton order") ||
                        mentions(error, "expected a finite position"))
                << error.what();
        } else {
            EXPECT_EQ(error.location().value, recordsEnd + 16) << error.what();
            EXPECT_TRUE(mentions(error, "payload checksum mismatch")) << error.what();
        }
    }
}

TEST(OmsReaderErrors, DamagedFooterIsDetectedAtOpen) {
    const SmallFile file;
    const std::size_t footer = footerStart(file.bytes);
    for (std::size_t at = footer; at < file.bytes.size(); ++at) {
        SCOPED_TRACE("byte " + std::to_string(at));
        std::vector<std::uint8_t> damaged = file.bytes;
        damaged[at] ^= 0x10;
        const std::string path = file.variant("footer.oms", damaged);
        if (at < footer + 8) {
            const InputError error = catchInputError([&] { OmsReader reader(path); });
            EXPECT_EQ(error.kind(), InputErrorKind::MalformedValue) << error.what();
            EXPECT_EQ(error.location().value, footer);
            EXPECT_TRUE(mentions(error, "expected the footer magic 'OMSEND\\x00\\x00'"))
                << error.what();
        } else if (at < footer + 16) {
            const InputError error = catchInputError([&] { OmsReader reader(path); });
            EXPECT_EQ(error.kind(), InputErrorKind::CountMismatch) << error.what();
            EXPECT_EQ(error.location().value, footer + 8);
            EXPECT_TRUE(mentions(error, "differs from the header's 50")) << error.what();
        } else {
            const InputError error =
                expectReadError(path, InputErrorKind::MalformedValue, footer + 16);
            EXPECT_TRUE(mentions(error, "payload checksum mismatch")) << error.what();
        }
    }
}

TEST(OmsReaderErrors, UnsortedFileWithValidChecksumsNamesTheRecord) {
    const SmallFile file;
    const SortedCloud& cloud = *file.cloud;
    std::size_t swapAt = 25;
    while (cloud.code(swapAt) == cloud.code(swapAt + 1)) {
        ++swapAt;
    }
    std::vector<std::uint8_t> unsorted = file.bytes;
    std::uint8_t* first = unsorted.data() + 128 + swapAt * 29;
    std::swap_ranges(first, first + 29, first + 29);
    resealPayload(unsorted);
    const std::string path = file.variant("unsorted.oms", unsorted);

    const std::size_t record = swapAt + 1;
    const std::size_t byte = 128 + record * 29;
    RangeLog log;
    OmsReader reader(path);
    const InputError error = catchInputError([&] { reader.read(log.consumer()); });
    EXPECT_EQ(error.kind(), InputErrorKind::MalformedValue);
    EXPECT_EQ(error.location().value, byte);
    EXPECT_TRUE(mentions(error, "record " + std::to_string(record) + " at byte " +
                                    std::to_string(byte) +
                                    " is out of Morton order: the file is not sorted"))
        << error.what();
    EXPECT_TRUE(log.ranges.empty()) << "the range holding the bad record is never handed out";
    EXPECT_FALSE(reader.cloud()->complete());
}

TEST(OmsReaderErrors, NonFinitePositionIsAMalformedValue) {
    const SmallFile file;
    std::vector<std::uint8_t> damaged = file.bytes;
    const std::size_t byte = 128 + 40 * 29;
    setField(damaged, byte + 4, std::numeric_limits<float>::quiet_NaN());
    resealPayload(damaged);
    const std::string path = file.variant("nan.oms", damaged);
    const InputError error = expectReadError(path, InputErrorKind::MalformedValue, byte);
    EXPECT_TRUE(mentions(error, "record 40: expected a finite position")) << error.what();
}

struct HeaderEdit {
    const char* name;
    std::function<void(std::vector<std::uint8_t>&)> edit;
    InputErrorKind kind;
    std::uint64_t byte;
    const char* message;
};

TEST(OmsReaderErrors, ResealedHeaderFieldsAreValidated) {
    const SmallFile file;
    const std::vector<HeaderEdit> edits = {
        {"sort depth", [](auto& b) { b[24] = 20; }, InputErrorKind::UnsupportedFeature, 24,
         "expected sort depth 21, found 20"},
        {"unknown attribute", [](auto& b) { b[25] |= 0x40; }, InputErrorKind::UnsupportedFeature,
         25,
         "expected attribute bits within 0x3f (normal 1, colour 2, intensity 4, LAS 8, GPS time "
         "16, NIR 32), found 0x47"},
        {"GPS time without LAS", [](auto& b) { b[25] |= 0x10; }, InputErrorKind::MalformedHeader,
         25, "need the LAS bit"},
        {"extra bytes without LAS", [](auto& b) { setField<std::uint16_t>(b, 28, 3); },
         InputErrorKind::MalformedHeader, 25, "with 3 extra bytes"},
        {"record size", [](auto& b) { setField<std::uint16_t>(b, 26, 28); },
         InputErrorKind::MalformedHeader, 26, "expected a record size of 29 bytes"},
        {"attributes without record size", [](auto& b) { b[25] = 0; },
         InputErrorKind::MalformedHeader, 26, "expected a record size of 12 bytes"},
        {"reserved 0", [](auto& b) { b[31] = 1; }, InputErrorKind::MalformedHeader, 31,
         "expected reserved header bytes 31-31 to be zero"},
        {"no uniform LAS record", [](auto& b) { b[100] = 7; }, InputErrorKind::MalformedHeader, 100,
         "expected reserved header bytes 88-119 to be zero"},
        {"unknown uniform column", [](auto& b) { b[30] = 4; }, InputErrorKind::MalformedHeader, 30,
         "expected uniform column bits within 0x03 (intensity 1, LAS column 2), found 0x04"},
        {"uniform LAS column without LAS", [](auto& b) { b[30] = 2; },
         InputErrorKind::MalformedHeader, 30,
         "declare a uniform LAS column, but the attribute bits give a LAS column of 0 bytes"},
        {"uniform intensity, records keep it", [](auto& b) { b[30] = 1; },
         InputErrorKind::MalformedHeader, 26,
         "expected a record size of 27 bytes for attribute bits 0x07 and uniform column bits "
         "0x01, found 29"},
        {"zero edge", [](auto& b) { setField(b, 56, 0.0); }, InputErrorKind::MalformedHeader, 56,
         "expected a finite cube edge > 0"},
        {"infinite origin",
         [](auto& b) { setField(b, 40, std::numeric_limits<double>::infinity()); },
         InputErrorKind::MalformedHeader, 32, "expected a finite cube origin"},
        {"NaN offset", [](auto& b) { setField(b, 80, std::numeric_limits<double>::quiet_NaN()); },
         InputErrorKind::MalformedHeader, 64, "expected a finite source offset"},
        {"zero points", [](auto& b) { setField<std::uint64_t>(b, 16, 0); },
         InputErrorKind::NoPoints, 16, "the header declares 0 points"},
        {"one point more", [](auto& b) { setField<std::uint64_t>(b, 16, 51); },
         InputErrorKind::Truncated, 128 + 50 * 29 + 24, "inside record 50"},
        {"one point less", [](auto& b) { setField<std::uint64_t>(b, 16, 49); },
         InputErrorKind::CountMismatch, 128 + 49 * 29 + 24, "29 more bytes"},
        {"overflowing count", [](auto& b) { setField<std::uint64_t>(b, 16, ~0ull / 3); },
         InputErrorKind::Truncated, 128 + 50 * 29 + 24, "larger than 2^64 bytes"},
    };
    for (const HeaderEdit& e : edits) {
        SCOPED_TRACE(e.name);
        std::vector<std::uint8_t> edited = file.bytes;
        e.edit(edited);
        resealHeader(edited);
        const std::string path = file.variant("edited.oms", edited);
        const InputError error = expectReadError(path, e.kind, e.byte);
        EXPECT_TRUE(mentions(error, e.message)) << error.what();
    }
}

TEST(OmsReaderErrors, BigEndianFileIsUnsupported) {
    const SmallFile file;
    std::vector<std::uint8_t> foreign = file.bytes;
    for (std::size_t at = 12; at < 16; ++at) {
        foreign[at] = static_cast<std::uint8_t>(at - 11); // 01 02 03 04
    }
    const std::string path = file.variant("big.oms", foreign);
    const InputError error = expectReadError(path, InputErrorKind::UnsupportedFeature, 12);
    EXPECT_TRUE(mentions(error, "big-endian")) << error.what();
}

TEST(OmsReaderErrors, NewerVersionIsUnsupported) {
    const SmallFile file;
    for (const std::uint32_t version : {0u, 3u}) {
        std::vector<std::uint8_t> other = file.bytes;
        setField<std::uint32_t>(other, 8, version);
        const std::string path = file.variant("other.oms", other);
        const InputError error = expectReadError(path, InputErrorKind::UnsupportedFeature, 8);
        EXPECT_TRUE(mentions(error, "expected .oms format version 1 to 2, found version " +
                                        std::to_string(version)))
            << error.what();
    }
}

TEST(OmsReaderErrors, WrongMagicIsUnknownFormat) {
    test::TempDir dir;
    const std::string path = dir.file("not.oms");
    test::writeText(path, "ply\nformat binary_little_endian 1.0\nend_header\n");
    const InputError error = expectReadError(path, InputErrorKind::UnknownFormat, 0);
    EXPECT_TRUE(mentions(error, "expected the .oms magic 'OMICRONS', found 'ply\\x0aform'"))
        << error.what();
}

TEST(OmsReaderErrors, DirectoryEmptyAndMissingFiles) {
    test::TempDir dir;
    const std::string folder = dir.file("folder.oms");
    std::filesystem::create_directory(folder);
    expectReadError(folder, InputErrorKind::NotARegularFile);

    const std::string empty = dir.file("empty.oms");
    test::writeBytes(empty, {});
    expectReadError(empty, InputErrorKind::EmptyFile);

    expectReadError(dir.file("missing.oms"), InputErrorKind::CannotOpen);
}

// ---------------------------------------------------------------------------------------------

TEST(OmsDetection, IsOmsFileChecksTheMagicOrTheExtension) {
    const SmallFile file;
    EXPECT_TRUE(isOmsFile(file.path));
    const std::string renamed = file.variant("sorted.bin", file.bytes);
    EXPECT_TRUE(isOmsFile(renamed));
    const std::string upper = file.variant("EMPTY.OMS", {});
    EXPECT_TRUE(isOmsFile(upper)) << "a damaged .oms file still goes to the .oms reader";

    const std::string ply = file.dir.file("cloud.ply");
    test::writeText(ply, "ply\nformat ascii 1.0\n");
    EXPECT_FALSE(isOmsFile(ply));
    const std::string shortFile = file.variant("short.bin", {'O', 'M', 'I'});
    EXPECT_FALSE(isOmsFile(shortFile));
    EXPECT_FALSE(isOmsFile(file.dir.file("missing.ply")));
    EXPECT_FALSE(isOmsFile(file.dir.path().string()));
}

TEST(OmsDetection, PointCloudDetectionLeavesOmsToTheOmsReader) {
    const SmallFile file;
    for (const std::string& path : {file.path, file.variant("sorted.bin", file.bytes)}) {
        const InputError error = catchInputError([&] { detectFormat(path); });
        EXPECT_EQ(error.kind(), InputErrorKind::UnknownFormat) << error.what();
    }
}

// ---------------------------------------------------------------------------------------------

TEST(OmsWriter, DestroyedWithoutFinishLeavesNoTemporaryAndKeepsTheTarget) {
    const SmallFile file;
    const auto other = sortBatch(makeBatch(200, {}, 3));
    {
        OmsWriter writer;
        writer.open(file.path, other->cube(), other->sourceOffset(), other->attributes(), 200);
        writer.append(*other, 0, 100);
        EXPECT_EQ(test::openFilesIn(0, file.dir.path()).size(), 1u)
            << "the temporary is beside the target";
        EXPECT_EQ(fileCount(file.dir.path()), 1u) << "the temporary has a name";
    }
    EXPECT_TRUE(test::openFilesIn(0, file.dir.path()).empty());
    EXPECT_EQ(fileCount(file.dir.path()), 1u);
    EXPECT_EQ(test::readBytes(file.path), file.bytes);
    EXPECT_EQ(readOms(file.path).info.pointCount, 50u);
}

TEST(OmsWriter, InvalidUseThrowsAndLeavesNothingBehind) {
    test::TempDir dir;
    const std::string path = dir.file("out.oms");
    const auto sorted = sortBatch(makeBatch(300, AttributeSet(Attribute::Color)));
    const auto expectOutputError = [&](const std::function<void(OmsWriter&)>& misuse,
                                       const std::string& message) {
        SCOPED_TRACE(message);
        OmsWriter writer;
        try {
            misuse(writer);
            ADD_FAILURE() << "expected an OutputError";
        } catch (const OutputError& error) {
            EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
            EXPECT_NE(std::string(error.what()).find(message), std::string::npos) << error.what();
        }
        EXPECT_EQ(fileCount(dir.path()), 0u);
    };
    const auto open = [&](OmsWriter& writer, std::uint64_t count) {
        writer.open(path, sorted->cube(), sorted->sourceOffset(), sorted->attributes(), count);
    };
    expectOutputError([&](OmsWriter& w) { open(w, 0); }, "at least one point, got 0");
    expectOutputError(
        [&](OmsWriter& w) {
            w.open(path, CubeTransform{glm::dvec3(0.0), 0.0}, kOffset, {}, 10);
        },
        "the edge > 0");
    expectOutputError(
        [&](OmsWriter& w) {
            open(w, 300);
            w.append(*sorted, 0, 100);
            w.append(*sorted, 150, 200);
        },
        "expected a published range starting at point 100, got [150, 200)");
    expectOutputError(
        [&](OmsWriter& w) {
            open(w, 100);
            w.append(*sorted, 0, 101);
        },
        "exceeds the 100 points declared at open()");
    expectOutputError(
        [&](OmsWriter& w) {
            oms::UniformColumns uniform;
            uniform.bits = oms::kUniformIntensityBit;
            w.open(path, sorted->cube(), sorted->sourceOffset(), sorted->attributes(), 300,
                   uniform);
        },
        "a uniform intensity for a cloud without intensities");
    expectOutputError(
        [&](OmsWriter& w) {
            open(w, 300);
            w.append(*sorted, 0, 299);
            w.finish();
        },
        "finish() after 299 points, expected the 300 declared at open()");
    expectOutputError(
        [&](OmsWriter& w) {
            w.open(path, sorted->cube(), sorted->sourceOffset(), {}, 300);
            w.append(*sorted, 0, 300);
        },
        "the appended cloud has attribute bits 2, the file was opened with 0");
    expectOutputError([&](OmsWriter&) { writeOms(path, *sorted, 301); },
                      "got [0, 301) with 300 points published");
}

TEST(OmsWriter, RefusesACloudThatIsNotInMortonOrder) {
    test::TempDir dir;
    const std::string path = dir.file("unsorted.oms");
    SortedCloud cloud(kCube, kOffset, {}, 3);
    const std::vector<glm::vec3> positions = {
        {0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}, {0.5f, 0.1f, 0.1f}};
    for (std::size_t i = 0; i < positions.size(); ++i) {
        cloud.mutablePositions()[i] = positions[i];
    }
    cloud.publish(3);
    try {
        writeOms(path, cloud, 3);
        ADD_FAILURE() << "expected an OutputError";
    } catch (const OutputError& error) {
        EXPECT_NE(std::string(error.what()).find("point 2 is out of Morton order"),
                  std::string::npos)
            << error.what();
    }
    EXPECT_EQ(fileCount(dir.path()), 0u);
}

// ---------------------------------------------------------------------------------------------
// Version 2: a column every point shares is stored once, in the header.

constexpr std::array<std::uint8_t, 8> kLasRecord{2, 0x11, 0, 7, 0xfe, 0xff, 0x34, 0x12};

// A sorted cloud with colour, intensity and the LAS column, whose intensities are all 77
// and/or whose LAS records are all kLasRecord.
std::shared_ptr<const SortedCloud> cloudWithUniformColumns(std::size_t count, bool intensity,
                                                           bool las) {
    PointBatch batch =
        makeBatch(count, AttributeSet(Attribute::Color) | Attribute::Intensity | Attribute::Las);
    if (intensity) {
        std::fill(batch.intensities.begin(), batch.intensities.end(), 77);
    }
    for (std::size_t i = 0; las && i < count; ++i) {
        std::copy(kLasRecord.begin(), kLasRecord.end(), batch.las.begin() + i * kLasRecord.size());
    }
    return sortBatch(batch);
}

TEST(OmsUniformColumns, AreStoredOnceInTheHeaderAndReadBack) {
    struct Case {
        bool intensity, las;
        std::uint8_t bits;
        std::size_t recordBytes;
    };
    for (const Case c : {Case{true, true, 0x03, 15}, Case{true, false, 0x01, 23},
                         Case{false, true, 0x02, 17}, Case{false, false, 0x00, 25}}) {
        SCOPED_TRACE(std::to_string(c.bits));
        test::TempDir dir;
        const std::string path = dir.file("uniform.oms");
        const std::size_t count = 9000;
        const auto sorted = cloudWithUniformColumns(count, c.intensity, c.las);
        ASSERT_EQ(sorted->uniformIntensities(), c.intensity);
        ASSERT_EQ(sorted->uniformLasColumn(), c.las);
        writeOms(path, *sorted, count);

        const std::vector<std::uint8_t> bytes = test::readBytes(path);
        ASSERT_EQ(bytes.size(), 128 + count * c.recordBytes + 24);
        EXPECT_EQ(bytes[30], c.bits);
        EXPECT_EQ(bytes[31], 0);
        EXPECT_EQ(field<std::uint16_t>(bytes, 26), c.recordBytes);
        EXPECT_EQ(field<std::uint16_t>(bytes, 88), c.intensity ? 77 : 0);
        for (std::size_t at = 0; at < 30; ++at) {
            EXPECT_EQ(bytes[90 + at], c.las && at < kLasRecord.size() ? kLasRecord[at] : 0)
                << "byte " << 90 + at;
        }
        // Record 5: the position, the colour, then what is not uniform.
        const std::size_t record = 128 + 5 * c.recordBytes;
        EXPECT_EQ(field<glm::vec3>(bytes, record), sorted->positions()[5]);
        EXPECT_EQ(field<glm::u8vec3>(bytes, record + 12), sorted->colors()[5]);
        if (!c.intensity) {
            EXPECT_EQ(field<std::uint16_t>(bytes, record + 15), sorted->intensities()[5]);
        }
        if (!c.las) {
            EXPECT_EQ(std::memcmp(bytes.data() + record + (c.intensity ? 15 : 17),
                                  sorted->lasRecord(5), 8),
                      0);
        }

        ReadOptions options;
        options.batchPoints = 5000; // two ranges, each of several grains
        const ReadBack back = readOms(path, options);
        EXPECT_EQ(back.info.uniform.bits, c.bits);
        EXPECT_EQ(back.info.recordBytes, c.recordBytes);
        EXPECT_EQ(back.cloud->uniformIntensities(), c.intensity);
        EXPECT_EQ(back.cloud->uniformLasColumn(), c.las);
        expectSameCloud(*sorted, *back.cloud);
        expectRangesInOrder(back.log, *back.cloud, count);
    }
}

TEST(OmsUniformColumns, AFileBackedCloudKeepsThemOnceToo) {
    test::TempDir dir;
    const std::string path = dir.file("uniform.oms");
    const std::size_t count = 6000;
    const auto sorted = cloudWithUniformColumns(count, true, true);
    writeOms(path, *sorted, count);

    // A budget far below the cloud: its arrays live in a scratch file.
    OmsReader reader(path, PointStorage::Exact, 4096, dir.path().string());
    ASSERT_TRUE(reader.cloud()->fileBacked());
    reader.read([](const SortedCloud&, std::size_t, std::size_t) {});
    const SortedCloud& cloud = *reader.cloud();
    EXPECT_TRUE(cloud.uniformIntensities());
    EXPECT_TRUE(cloud.uniformLasColumn());
    expectSameCloud(*sorted, cloud);
}

TEST(OmsUniformColumns, Version1FilesStillLoad) {
    const SmallFile file;
    std::vector<std::uint8_t> old = file.bytes;
    setField<std::uint32_t>(old, 8, 1);
    resealHeader(old);
    const ReadBack back = readOms(file.variant("v1.oms", old));
    EXPECT_EQ(back.info.version, 1u);
    EXPECT_EQ(back.info.uniform.bits, 0);
    expectSameCloud(*file.cloud, *back.cloud);

    // In version 1 the uniform column bits are reserved.
    old[30] = 1;
    resealHeader(old);
    const InputError error =
        expectReadError(file.variant("v1-bits.oms", old), InputErrorKind::MalformedHeader, 30);
    EXPECT_TRUE(mentions(error, "expected reserved header bytes 30-31 to be zero")) << error.what();
}

TEST(OmsWriter, RefusesAPointThatBreaksAUniformColumn) {
    test::TempDir dir;
    const std::string path = dir.file("out.oms");
    const auto sorted = cloudWithUniformColumns(100, false, true);
    PointBatch batch;
    sorted->copyRange(0, 100, batch);
    std::fill(batch.intensities.begin(), batch.intensities.end(), 5);
    batch.intensities[63] = 6;
    oms::UniformColumns uniform = oms::uniformColumnsOf(*sorted);
    uniform.bits |= oms::kUniformIntensityBit;
    uniform.intensity = 5;
    OmsWriter writer;
    writer.open(path, sorted->cube(), sorted->sourceOffset(), sorted->attributes(), 100, uniform);
    try {
        writer.append(batch);
        ADD_FAILURE() << "expected an OutputError";
    } catch (const OutputError& error) {
        EXPECT_NE(std::string(error.what())
                      .find("point 63 has intensity 6, not the uniform 5 given at open()"),
                  std::string::npos)
            << error.what();
    }
    EXPECT_EQ(fileCount(dir.path()), 0u);
}

// Records are decoded in grains on every core: whichever grain finds what, the error is the
// file's first bad record, also where a grain's first record breaks the order.
TEST(OmsReaderErrors, TheFirstBadRecordOfTheFileIsNamedWhicheverGrainFindsIt) {
    const std::size_t count = 20000;
    const SmallFile file(count, AttributeSet(Attribute::Color));
    const std::size_t recordBytes = 15;
    const auto recordAt = [&](std::size_t record) {
        return 128 + record * recordBytes;
    };
    const auto edited = [&](const std::function<void(std::vector<std::uint8_t>&)>& edit) {
        std::vector<std::uint8_t> bytes = file.bytes;
        edit(bytes);
        resealPayload(bytes);
        return file.variant("edited.oms", bytes);
    };
    const auto nan = [&](std::vector<std::uint8_t>& bytes, std::size_t record) {
        setField(bytes, recordAt(record), std::numeric_limits<float>::quiet_NaN());
    };
    // Record 0's position (the cube's corner, the lowest code) anywhere later breaks the order.
    const auto lowest = [&](std::vector<std::uint8_t>& bytes, std::size_t record) {
        std::memcpy(bytes.data() + recordAt(record), bytes.data() + recordAt(0), 12);
    };
    const auto expectOrderError = [&](const std::string& path, std::size_t record) {
        const InputError error =
            expectReadError(path, InputErrorKind::MalformedValue, recordAt(record));
        EXPECT_TRUE(mentions(error, "record " + std::to_string(record) + " at byte " +
                                        std::to_string(recordAt(record)) +
                                        " is out of Morton order"))
            << error.what();
    };
    const auto expectNonFinite = [&](const std::string& path, std::size_t record) {
        const InputError error =
            expectReadError(path, InputErrorKind::MalformedValue, recordAt(record));
        EXPECT_TRUE(mentions(error, "record " + std::to_string(record) + ": expected a finite"))
            << error.what();
    };

    // A grain's first record below the last of the grain before.
    expectOrderError(edited([&](auto& b) { lowest(b, 4096); }), 4096);
    expectOrderError(edited([&](auto& b) { lowest(b, 3 * 4096); }), 3 * 4096);
    // A grain's first record not finite: that, not an order error.
    expectNonFinite(edited([&](auto& b) { nan(b, 4096); }), 4096);
    // Two bad records in different grains: the earlier one, whatever its kind.
    expectOrderError(edited([&](auto& b) {
                         lowest(b, 9000);
                         nan(b, 15000);
                     }),
                     9000);
    expectNonFinite(edited([&](auto& b) {
                        nan(b, 5000);
                        lowest(b, 15000);
                    }),
                    5000);
    // Within a grain, the non-finite record before an order break.
    expectNonFinite(edited([&](auto& b) {
                        nan(b, 100);
                        lowest(b, 101);
                    }),
                    100);
}

} // namespace
} // namespace omicron
