// Every LAS attribute end to end: the LAS column read from LAS and LAZ records of the legacy
// and the LAS 1.4 layouts, carried through the real sorter, a .oms stream and a LAS 1.4
// export byte for byte, and the same from a LAZ file as from its uncompressed twin.
#include "formats/oms_reader.hpp"
#include "formats/oms_writer.hpp"
#include "io/cloud_export.hpp"
#include "io/las/las_extra_bytes.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_point_fields.hpp"
#include "io/las/las_writer.hpp"
#include "io/point_reader.hpp"
#include "points/attribute_statistics.hpp"
#include "sort/morton_sorter.hpp"
#include "test_files.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <gtest/gtest.h>
#include <random>
#include <string>
#include <tuple>
#include <vector>

namespace omicron {
namespace {

// One point as (position bits, LAS column bytes): the sorter permutes points, so clouds are
// compared as sorted lists of these.
using PointKey = std::tuple<std::array<std::uint32_t, 3>, std::vector<std::uint8_t>>;

PointKey keyOf(const glm::vec3& position, const std::uint8_t* las, std::size_t lasBytes) {
    std::array<std::uint32_t, 3> bits;
    std::memcpy(bits.data(), &position, sizeof position);
    return {bits, std::vector<std::uint8_t>(las, las + lasBytes)};
}

std::vector<PointKey> keysOf(const PointBatch& batch) {
    std::vector<PointKey> keys;
    const std::size_t lasBytes = batch.attributes.lasBytes();
    for (std::size_t i = 0; i < batch.size(); ++i) {
        keys.push_back(keyOf(batch.positions[i], batch.las.data() + i * lasBytes, lasBytes));
    }
    std::sort(keys.begin(), keys.end());
    return keys;
}

std::shared_ptr<const SortedCloud> sortFile(const std::string& path) {
    auto reader = openPointCloud(path);
    std::shared_ptr<const SortedCloud> cloud;
    sortPointCloud(*reader, SortOptions{}, [](const SortedCloud&, std::size_t, std::size_t) {},
                   [&](const IncrementalMortonSorter& sorter) { cloud = sorter.cloud(); });
    EXPECT_TRUE(cloud && cloud->complete());
    return cloud;
}

TEST(LasFields, LegacyRecordFieldsSurviveLas14AndBack) {
    // Point format 1: return 2 of 3, scan direction and edge set; class 6 (building),
    // synthetic and withheld; scan angle rank -15 degrees; user data 7; source 1234; GPS time.
    std::array<std::uint8_t, 28> legacy{};
    legacy[14] = 2 | 3 << 3 | 0x40 | 0x80;
    legacy[15] = 6 | 0x20 | 0x80;
    legacy[16] = static_cast<std::uint8_t>(std::int8_t{-15});
    legacy[17] = 7;
    const std::uint16_t source = 1234;
    std::memcpy(&legacy[18], &source, 2);
    const double gps = 123456.789;
    std::memcpy(&legacy[20], &gps, 8);

    const LasFields fields = las::readLasFields(legacy.data(), 1);
    EXPECT_EQ(fields.classification, 6);
    EXPECT_EQ(fields.returnNumber(), 2);
    EXPECT_EQ(fields.numberOfReturns(), 3);
    EXPECT_EQ(fields.flags, las_flag::kSynthetic | las_flag::kWithheld |
                                las_flag::kScanDirection | las_flag::kEdgeOfFlightLine);
    EXPECT_NEAR(fields.scanAngleDegrees(), -15.0, 0.003);
    EXPECT_EQ(fields.userData, 7);
    EXPECT_EQ(fields.pointSourceId, 1234);
    EXPECT_EQ(fields.gpsTime, gps);

    std::array<std::uint8_t, 30> v14{};
    las::writeLasFields(fields, 6, v14.data());
    const LasFields again = las::readLasFields(v14.data(), 6);
    EXPECT_EQ(std::memcmp(&again, &fields, sizeof fields), 0);

    std::array<std::uint8_t, 28> back{};
    las::writeLasFields(again, 1, back.data());
    EXPECT_TRUE(std::equal(legacy.begin() + 14, legacy.end(), back.begin() + 14))
        << "the legacy fields did not read back as written";
}

// Waveform formats (4, 5, 9, 10) are read for their point part, and say so.
TEST(LasFields, WaveformFormatsReadTheirPointsAndSayWaveformsAreIgnored) {
    test::TempDir dir;
    for (std::uint8_t format : {4, 5, 9, 10}) {
        SCOPED_TRACE(static_cast<int>(format));
        const AttributeSet attributes = las::attributesOfFormat(format, 0);
        PointBatch batch;
        batch.attributes = attributes;
        for (int i = 0; i < 10; ++i) {
            batch.positions.emplace_back(0.1f * i, 0.05f * i, 0.5f);
            batch.intensities.push_back(static_cast<std::uint16_t>(100 + i));
            if (attributes.has(Attribute::Color)) {
                batch.colors.emplace_back(i, 2 * i, 3 * i);
            }
            LasFields fields;
            fields.classification = static_cast<std::uint8_t>(i);
            fields.returns = static_cast<std::uint8_t>(1 | 2 << 4);
            fields.gpsTime = 1000.0 + i;
            fields.pointSourceId = 7;
            std::vector<std::uint8_t> column(attributes.lasBytes());
            encodeLasFields(attributes, fields, column.data());
            batch.las.insert(batch.las.end(), column.begin(), column.end());
        }
        LasWriteOptions options;
        options.versionMinor = 4;
        options.pointFormat = format;
        const std::string path = dir.file("waveform.las");
        writeLas(path, batch, CubeTransform::fromBounds({glm::dvec3(0.0), glm::dvec3(1.0)}),
                 options);
        const LoadedCloud read = loadPointCloud(path);
        EXPECT_NE(read.info.formatDetail.find("waveform packets ignored"), std::string::npos)
            << read.info.formatDetail;
        ASSERT_EQ(read.points.size(), 10u);
        EXPECT_TRUE(read.points.las == batch.las);
        EXPECT_EQ(read.points.intensities, batch.intensities);
    }
}

TEST(LasFields, AttributesOfEveryFormat) {
    for (std::uint8_t format = 0; format <= 10; ++format) {
        SCOPED_TRACE(static_cast<int>(format));
        const AttributeSet a = las::attributesOfFormat(format, 100);
        EXPECT_TRUE(a.has(Attribute::Las));
        EXPECT_TRUE(a.has(Attribute::Intensity));
        EXPECT_EQ(a.has(Attribute::GpsTime), format != 0 && format != 2);
        EXPECT_EQ(a.has(Attribute::Nir), format == 8 || format == 10);
        EXPECT_EQ(a.extraBytes(), 100 - las::minimumRecordLength(format));
    }
}

// The reader's hot path equals the field-by-field conversion, for every format and byte.
TEST(LasFields, ReadLasColumnEqualsTheFieldConversion) {
    std::mt19937 random(5);
    for (std::uint8_t format = 0; format <= 10; ++format) {
        SCOPED_TRACE(static_cast<int>(format));
        const std::uint16_t length = las::minimumRecordLength(format) + 3;
        const AttributeSet attributes = las::attributesOfFormat(format, length);
        const LasColumnLayout layout = LasColumnLayout::of(attributes);
        std::vector<std::uint8_t> record(length), column(layout.bytes), expected(layout.bytes);
        for (int trial = 0; trial < 2000; ++trial) {
            for (std::uint8_t& byte : record) {
                byte = static_cast<std::uint8_t>(random());
            }
            las::readLasColumn(record.data(), format, layout, column.data());
            encodeLasFields(attributes, las::readLasFields(record.data(), format), expected.data());
            std::memcpy(expected.data() + layout.extraOffset,
                        record.data() + las::minimumRecordLength(format), 3);
            ASSERT_EQ(column, expected) << "trial " << trial;
        }
    }
}

// A run of records at once (the reader's call per batch) equals the field-by-field
// conversion of each, for every format, with and without extra bytes, records packed or
// further apart than their length.
TEST(LasFields, ReadLasColumnsOfARunEqualTheFieldConversion) {
    std::mt19937 random(7);
    for (std::uint8_t format = 0; format <= 10; ++format) {
        for (const std::uint16_t extra : {0, 3}) {
            for (const std::size_t gap : {0, 5}) {
                SCOPED_TRACE(testing::Message() << "format " << int(format) << ", extra bytes "
                                                << extra << ", gap " << gap);
                const auto length =
                    static_cast<std::uint16_t>(las::minimumRecordLength(format) + extra);
                const AttributeSet attributes = las::attributesOfFormat(format, length);
                const LasColumnLayout layout = LasColumnLayout::of(attributes);
                const std::size_t stride = length + gap;
                constexpr std::size_t kRecords = 37;
                std::vector<std::uint8_t> records(kRecords * stride);
                for (std::uint8_t& byte : records) {
                    byte = static_cast<std::uint8_t>(random());
                }
                std::vector<std::uint8_t> columns(kRecords * layout.bytes, 0xee);
                las::readLasColumns(records.data(), kRecords, stride, format, layout,
                                    columns.data());
                for (std::size_t i = 0; i < kRecords; ++i) {
                    const std::uint8_t* record = records.data() + i * stride;
                    std::vector<std::uint8_t> expected(layout.bytes);
                    encodeLasFields(attributes, las::readLasFields(record, format),
                                    expected.data());
                    std::memcpy(expected.data() + layout.extraOffset,
                                record + las::minimumRecordLength(format), extra);
                    const std::vector<std::uint8_t> column(columns.begin() + i * layout.bytes,
                                                           columns.begin() +
                                                               (i + 1) * layout.bytes);
                    ASSERT_EQ(column, expected) << "record " << i;
                }
            }
        }
    }
}

class LasAttributesEndToEnd : public ::testing::TestWithParam<const char*> {};

TEST_P(LasAttributesEndToEnd, SortOmsAndLasExportKeepEveryFieldByteForByte) {
    OMICRON_REQUIRE_SHARED_FILE(path, GetParam());
    test::TempDir dir;
    const LoadedCloud original = loadPointCloud(path);
    const AttributeSet attributes = original.info.attributes;
    ASSERT_TRUE(attributes.has(Attribute::Las));
    ASSERT_TRUE(original.points.consistent());

    // The sorter permutes every field with its point.
    const auto sorted = sortFile(path);
    ASSERT_EQ(sorted->attributes(), attributes);
    PointBatch sortedPoints;
    sorted->copyRange(0, sorted->sortedEnd(), sortedPoints);
    ASSERT_TRUE(keysOf(sortedPoints) == keysOf(original.points))
        << "the sorted cloud's (position, LAS fields) pairs differ from the file's";

    // .oms stores the column as it is.
    const std::string oms = dir.file("sorted.oms");
    OmsWriter writer;
    writer.open(oms, sorted->cube(), sorted->sourceOffset(), attributes, sorted->sortedEnd());
    writer.append(*sorted, 0, sorted->sortedEnd());
    writer.finish();
    OmsReader reader(oms);
    reader.read([](const SortedCloud&, std::size_t, std::size_t) {});
    ASSERT_EQ(reader.cloud()->attributes(), attributes);
    for (std::size_t i = 0; i < sorted->sortedEnd(); ++i) {
        ASSERT_EQ(
            std::memcmp(reader.cloud()->lasRecord(i), sorted->lasRecord(i), attributes.lasBytes()),
            0)
            << i;
    }

    // A LAS export writes LAS 1.4 with every field and extra byte; read back in the same order.
    const std::string las = dir.file("export.las");
    ASSERT_EQ(exportCloudPoints(las, *sorted), sorted->sortedEnd());
    const LoadedCloud exported = loadPointCloud(las);
    EXPECT_NE(exported.info.formatDetail.find("LAS 1.4"), std::string::npos)
        << exported.info.formatDetail;
    ASSERT_EQ(exported.info.attributes.extraBytes(), attributes.extraBytes());
    // The extra bytes keep their names and types: the source's descriptors are written back.
    EXPECT_TRUE(exported.info.lasExtraBytesDescriptors == original.info.lasExtraBytesDescriptors);
    EXPECT_EQ(original.info.lasExtraBytesDescriptors.empty(), attributes.extraBytes() == 0);
    // And its coordinate system (the shared files all have one: WKT, GeoTIFF keys).
    const auto sourceCrs = parseVariableLengthRecords(original.info.lasProjectionRecords);
    const auto exportedCrs = parseVariableLengthRecords(exported.info.lasProjectionRecords);
    EXPECT_FALSE(sourceCrs.empty());
    ASSERT_EQ(exportedCrs.size(), sourceCrs.size());
    for (std::size_t r = 0; r < sourceCrs.size(); ++r) {
        EXPECT_EQ(exportedCrs[r].userId, "LASF_Projection");
        EXPECT_EQ(exportedCrs[r].recordId, sourceCrs[r].recordId);
        EXPECT_TRUE(exportedCrs[r].payload == sourceCrs[r].payload) << "record " << r;
    }
    EXPECT_EQ(exported.info.attributes.has(Attribute::Nir), attributes.has(Attribute::Nir));
    ASSERT_EQ(exported.points.size(), sorted->sortedEnd());
    // A format without GPS time (0, 2) exports its zero GPS time: compare the common fields.
    const std::size_t n = exported.points.size();
    for (std::size_t i = 0; i < n; ++i) {
        const LasFields want = decodeLasFields(attributes, sorted->lasRecord(i));
        const LasFields got = decodeLasFields(exported.points.attributes,
                                              exported.points.las.data() +
                                                  i * exported.points.attributes.lasBytes());
        ASSERT_EQ(std::memcmp(&got, &want, sizeof got), 0) << "point " << i;
        const LasColumnLayout from = LasColumnLayout::of(attributes);
        const LasColumnLayout to = LasColumnLayout::of(exported.points.attributes);
        ASSERT_EQ(std::memcmp(sorted->lasRecord(i) + from.extraOffset,
                              exported.points.las.data() + i * to.bytes + to.extraOffset,
                              from.extraBytes),
                  0)
            << "the extra bytes of point " << i;
    }
}

INSTANTIATE_TEST_SUITE_P(SharedData, LasAttributesEndToEnd,
                         ::testing::Values("autzen_trim.las", "laz/terrascan_fmt8.laz",
                                           "laz/1.2-with-color.copc.laz"),
                         test::FileParamName());

// terrascan_fmt8 splits its descriptors over two Extra Bytes records, as TerraScan writes them.
TEST(LasAttributes, ExtraBytesDescriptorsNameTheFields) {
    OMICRON_REQUIRE_SHARED_FILE(path, "laz/terrascan_fmt8.laz");
    const CloudInfo info = openPointCloud(path)->info();
    ASSERT_EQ(info.lasExtraBytesDescriptors.size(), 2 * las::kExtraBytesDescriptorBytes);
    const auto fields = las::parseExtraBytesDescriptors(info.lasExtraBytesDescriptors);
    ASSERT_EQ(fields.size(), 2u);
    EXPECT_EQ(fields[0].name, "Deviation");
    EXPECT_EQ(las::extraBytesTypeName(fields[0]), "uint16");
    EXPECT_EQ(fields[0].description, "Pulse shape deviation");
    EXPECT_EQ(fields[1].name, "confidence");
    EXPECT_EQ(las::extraBytesTypeName(fields[1]), "uint8");
    EXPECT_TRUE(las::describesExtraBytes(info.lasExtraBytesDescriptors, 3));
    EXPECT_FALSE(las::describesExtraBytes(info.lasExtraBytesDescriptors, 4))
        << "descriptors of other bytes than the records hold must not be written back";
    // Without descriptors (or with wrong ones), an export describes the bytes as undocumented.
    const LasWriteOptions options =
        lasExportOptions(info.attributes, info.cube, std::vector<std::uint8_t>(192, 0));
    ASSERT_EQ(options.vlrs.size(), 1u);
    const auto undocumented = las::parseExtraBytesDescriptors(options.vlrs[0].payload);
    ASSERT_EQ(undocumented.size(), 1u);
    EXPECT_EQ(undocumented[0].dataType, 0);
    EXPECT_EQ(undocumented[0].bytes, 3u);
}

TEST(LasAttributes, LazColumnEqualsItsUncompressedTwin) {
    OMICRON_REQUIRE_SHARED_FILE(laz, "laz/terrascan_fmt8.laz");
    OMICRON_REQUIRE_SHARED_FILE(las, "laz/terrascan_fmt8.las");
    const LoadedCloud a = loadPointCloud(laz);
    const LoadedCloud b = loadPointCloud(las);
    ASSERT_EQ(a.info.attributes, b.info.attributes);
    EXPECT_EQ(a.info.attributes.extraBytes(), 3);
    EXPECT_TRUE(a.info.attributes.has(Attribute::Nir));
    EXPECT_TRUE(a.points.las == b.points.las);
}

TEST(LasAttributes, StatisticsCountTheClassesOfTheFile) {
    OMICRON_REQUIRE_SHARED_FILE(path, "laz/terrascan_fmt8.laz");
    OMICRON_REQUIRE_SHARED_FILE(reference, "laz/terrascan_fmt8.las");
    const LoadedCloud cloud = loadPointCloud(path);
    AttributeStatistics statistics;
    statistics.add(cloud.points);
    const auto& counts = statistics.classCounts();
    // Counted independently from the uncompressed twin's raw records (decoded by another LAZ
    // implementation): the class byte at offset 16 of a format 8 record.
    const std::vector<std::uint8_t> bytes = test::readBytes(reference);
    std::uint32_t dataOffset;
    std::uint16_t recordLength;
    std::uint64_t count;
    std::memcpy(&dataOffset, &bytes.at(96), 4);
    std::memcpy(&recordLength, &bytes.at(105), 2);
    std::memcpy(&count, &bytes.at(247), 8);
    std::array<std::uint64_t, 256> expected{};
    for (std::uint64_t i = 0; i < count; ++i) {
        ++expected[bytes.at(dataOffset + i * recordLength + 16)];
    }
    EXPECT_TRUE(std::equal(counts.begin(), counts.end(), expected.begin()));
    EXPECT_EQ(statistics.points(), count);
    EXPECT_EQ(lasClassName(2), "Ground");
    bool gps = false;
    for (const NamedRange& range : statistics.ranges()) {
        if (range.name == "gps time") {
            gps = true;
            EXPECT_LT(range.range.min, range.range.max);
        }
    }
    EXPECT_TRUE(gps);
}

} // namespace
} // namespace omicron
