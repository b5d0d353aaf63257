// LAZ through the point-reader interface: format detection, what the info says about the
// compression, batches and cancel as for any reader.
#include "io/point_reader.hpp"
#include "test_files.hpp"

#include <atomic>
#include <gtest/gtest.h>
#include <string>

namespace omicron {
namespace {

void expectMentions(const std::string& text, const std::string& part) {
    EXPECT_NE(text.find(part), std::string::npos) << "expected '" << part << "' in: " << text;
}

TEST(LazReader, LayeredFileDescribesItsCompression) {
    OMICRON_REQUIRE_SHARED_FILE(path, "laz/terrascan_fmt8.laz");
    EXPECT_EQ(detectFormat(path), CloudFormat::Laz);
    auto reader = openPointCloud(path);
    const CloudInfo& info = reader->info();
    EXPECT_EQ(info.format, CloudFormat::Laz);
    EXPECT_STREQ(toString(info.format), "LAZ");
    EXPECT_EQ(info.pointCount, 697721u);
    EXPECT_EQ(info.attributes, (AttributeSet(Attribute::Intensity) | Attribute::Color |
                                Attribute::Las | Attribute::GpsTime | Attribute::Nir)
                                   .setExtraBytes(3));
    EXPECT_TRUE(info.boundsFromHeader);
    expectMentions(info.formatDetail, "LAS 1.4, point format 8, 41-byte records (3 extra bytes)");
    expectMentions(info.formatDetail, "layered chunks (POINT14 v3, RGBNIR14 v3, BYTE14 v3)");
    expectMentions(info.formatDetail, "14 chunks of 50000 points");
    expectMentions(info.formatDetail, "16-bit colour scaled to 8 bits");
}

TEST(LazReader, PointwiseAndCopcFilesDescribeTheirCompression) {
    OMICRON_REQUIRE_SHARED_FILE(pointwise, "laz/autzen_trim.laz");
    OMICRON_REQUIRE_SHARED_FILE(copc, "laz/1.2-with-color.copc.laz");
    const CloudInfo autzen = openPointCloud(pointwise)->info();
    expectMentions(autzen.formatDetail,
                   "point-wise chunks (POINT10 v2, GPSTIME11 v2, RGB12 v2), 3 chunks of 50000 "
                   "points");
    expectMentions(autzen.formatDetail, "8-bit colour in 16-bit fields");
    EXPECT_EQ(detectFormat(copc), CloudFormat::Laz);
    const CloudInfo copcInfo = openPointCloud(copc)->info();
    EXPECT_EQ(copcInfo.format, CloudFormat::Laz);
    expectMentions(copcInfo.formatDetail, "layered chunks (POINT14 v3, RGB14 v3), 65 chunks of "
                                          "variable size");
}

TEST(LazReader, ItemVersion1FileDescribesItsCompression) {
    const std::string path = test::repoDataFile("laz/simple-laszip-v1.laz");
    EXPECT_EQ(detectFormat(path), CloudFormat::Laz);
    const CloudInfo info = openPointCloud(path)->info();
    EXPECT_EQ(info.pointCount, 1065u);
    expectMentions(info.formatDetail, "(POINT10 v1, GPSTIME11 v1, RGB12 v1)");
}

TEST(LazReader, BatchesHoldAtMostBatchPointsAndEveryPointArrives) {
    OMICRON_REQUIRE_SHARED_FILE(path, "laz/autzen_trim.laz");
    auto reader = openPointCloud(path);
    ReadOptions options;
    options.batchPoints = 7000;
    std::size_t points = 0;
    const ReadSummary summary = reader->read(
        [&](const PointBatch& batch) {
            EXPECT_TRUE(batch.consistent());
            EXPECT_LE(batch.size(), 7000u);
            points += batch.size();
        },
        options);
    EXPECT_FALSE(summary.cancelled);
    EXPECT_EQ(points, 110000u);
    EXPECT_EQ(summary.pointsDelivered, 110000u);
    EXPECT_EQ(summary.batches, (110000u + 6999u) / 7000u);
}

} // namespace
} // namespace omicron
