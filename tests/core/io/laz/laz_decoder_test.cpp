// The LAZ decoder against an independent one: every record decoded from the real LAZ/COPC
// files in ../shared/data/laz must equal, byte for byte, the record laz-perf decoded into the
// reference LAS file (see that folder's README); and with 1 and 2 threads alike.
#include "laz_test_records.hpp"
#include "test_files.hpp"

#include <gtest/gtest.h>
#include <string>
#include <tbb/global_control.h>
#include <vector>

namespace omicron {
namespace {

using test::decodeLaz;
using test::readLasRecords;
using test::Records;
using test::sameRecords;

struct ReferencePair {
    const char* laz;
    const char* las;
    std::uint8_t pointFormat;
    std::uint64_t points;
};

void PrintTo(const ReferencePair& pair, std::ostream* out) {
    *out << pair.laz << " vs " << pair.las;
}

class LazDecoder : public ::testing::TestWithParam<ReferencePair> {};

TEST_P(LazDecoder, MatchesReferenceByteForByte) {
    OMICRON_REQUIRE_SHARED_FILE(lazPath, GetParam().laz);
    OMICRON_REQUIRE_SHARED_FILE(lasPath, GetParam().las);
    const Records decoded = decodeLaz(lazPath);
    const Records reference = readLasRecords(lasPath);
    EXPECT_EQ(decoded.header.pointFormat, GetParam().pointFormat);
    EXPECT_EQ(decoded.header.pointCount, GetParam().points);
    ASSERT_EQ(decoded.header.recordLength, reference.header.recordLength);
    ASSERT_EQ(reference.header.pointCount, GetParam().points);
    EXPECT_TRUE(sameRecords(decoded, reference));
}

TEST_P(LazDecoder, SameRecordsWithOneAndTwoThreads) {
    OMICRON_REQUIRE_SHARED_FILE(lazPath, GetParam().laz);
    Records one;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = decodeLaz(lazPath);
    }
    Records two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = decodeLaz(lazPath);
    }
    EXPECT_EQ(one.bytes.size(), GetParam().points * one.header.recordLength);
    EXPECT_TRUE(sameRecords(one, two));
}

// The streaming limits change how chunks are grouped and split, never the records: batches of
// a few chunks, and chunks too large for a batch decoded in slices of a few records.
TEST_P(LazDecoder, SmallBatchesAndSlicesDecodeTheSameRecords) {
    OMICRON_REQUIRE_SHARED_FILE(lazPath, GetParam().laz);
    OMICRON_REQUIRE_SHARED_FILE(lasPath, GetParam().las);
    const Records reference = readLasRecords(lasPath);
    const std::uint64_t recordLength = reference.header.recordLength;

    LazStreaming slices;
    slices.batchBytes = 4096; // most chunks are larger: decoded alone
    slices.sliceBytes = 20 * recordLength;
    const Records sliced = decodeLaz(lazPath, slices);
    EXPECT_TRUE(sameRecords(sliced, reference));
    // At least one block per 20 records of the chunks decoded in slices.
    EXPECT_GE(sliced.blocks, GetParam().points / 20 / 2) << "slices were not used";

    LazStreaming batches;
    batches.batchBytes = 5 << 20; // a few default chunks a batch
    const Records batched = decodeLaz(lazPath, batches);
    EXPECT_TRUE(sameRecords(batched, reference));
}

INSTANTIATE_TEST_SUITE_P(
    SharedLaz, LazDecoder,
    ::testing::Values(ReferencePair{"laz/simple.laz", "laz/simple.las", 3, 1065},
                      ReferencePair{"laz/autzen_trim.laz", "autzen_trim.las", 3, 110000},
                      ReferencePair{"laz/1.2-with-color.copc.laz", "laz/1.2-with-color.copc.las", 7,
                                    1065},
                      ReferencePair{"laz/terrascan_fmt8.laz", "laz/terrascan_fmt8.las", 8, 697721}),
    [](const ::testing::TestParamInfo<ReferencePair>& info) {
        std::string name = info.param.laz + 4; // without "laz/"
        for (char& c : name) {
            if (c == '.' || c == '-') {
                c = '_';
            }
        }
        return name;
    });

// LASzip 1.x's item version 1 (POINT10, GPSTIME11 and RGB12 v1 on one stream, compressor 1,
// no chunk table, chunk size field 0): PDAL's copy of a LASzip 1.2r0 file, kept in tests/data,
// whose points are simple.las's.
TEST(LazItemVersion1, MatchesReferenceByteForByte) {
    OMICRON_REQUIRE_SHARED_FILE(lasPath, "laz/simple.las");
    const std::string lazPath = test::repoDataFile("laz/simple-laszip-v1.laz");
    const Records reference = readLasRecords(lasPath);
    for (int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        const Records decoded = decodeLaz(lazPath);
        EXPECT_EQ(decoded.header.pointFormat, 3);
        ASSERT_EQ(decoded.header.pointCount, 1065u);
        EXPECT_TRUE(sameRecords(decoded, reference)) << threads << " thread(s)";
    }
    LazStreaming slices; // the one chunk decoded in slices of 20 records
    slices.sliceBytes = 20 * reference.header.recordLength;
    slices.batchBytes = 4096;
    EXPECT_TRUE(sameRecords(decodeLaz(lazPath, slices), reference));
}

} // namespace
} // namespace omicron
