// Bad LAZ input, made by corrupting copies of the real files in ../shared/data/laz: truncated
// files and chunks, corrupt chunk tables, wrong point counts, unknown compressors, coders, item
// types and versions. Each is an InputError of its kind naming the file and the byte (and the
// chunk, where one is at fault); random corruptions never crash.
#include "io/file_stream.hpp"
#include "io/input_error.hpp"
#include "io/las/las_header.hpp"
#include "io/laz/chunk_table.hpp"
#include "io/laz/laszip_vlr.hpp"
#include "io/point_reader.hpp"
#include "test_files.hpp"

#include <cstring>
#include <functional>
#include <gtest/gtest.h>
#include <random>
#include <string>
#include <vector>

namespace omicron {
namespace {

template <typename T> void put(std::vector<std::uint8_t>& bytes, std::uint64_t at, T value) {
    std::memcpy(&bytes.at(at), &value, sizeof value);
}

template <typename T> T get(const std::vector<std::uint8_t>& bytes, std::uint64_t at) {
    T value;
    std::memcpy(&value, &bytes.at(at), sizeof value);
    return value;
}

// A valid LAZ file's bytes and where its parts are.
struct LazFile {
    std::vector<std::uint8_t> bytes;
    las::Header header;
    std::uint64_t vlr = 0;   // the laszip record's payload
    std::uint64_t table = 0; // the chunk table
    std::vector<laz::Chunk> chunks;

    std::uint64_t item(std::size_t index) const { return vlr + 34 + 6 * index; }
};

LazFile parse(const std::string& path) {
    LazFile file;
    file.bytes = test::readBytes(path);
    FileStream stream(path);
    file.header = las::readHeader(stream);
    file.vlr = file.header.laszipRecordOffset;
    file.table = get<std::uint64_t>(file.bytes, file.header.pointDataOffset);
    const std::vector<std::uint8_t> payload(file.bytes.begin() + file.vlr,
                                            file.bytes.begin() + file.vlr +
                                                file.header.laszipRecordLength);
    const laz::LaszipVlr vlr = laz::parseLaszipVlr(payload, path, file.vlr, file.header.pointFormat,
                                                   file.header.recordLength);
    file.chunks = laz::readChunkLayout(stream, vlr,
                                       {file.header.pointDataOffset, stream.size(),
                                        file.header.pointCount, file.header.recordLength})
                      .chunks;
    return file;
}

// Where the error must be: one byte, or anywhere in [first, last] (inside a chunk whose data
// is garbage, the byte where decoding notices depends on the garbage).
struct Where {
    std::uint64_t first = 0;
    std::uint64_t last = 0;
};
Where at(std::uint64_t byte) {
    return {byte, byte};
}
Where inChunk(const laz::Chunk& chunk) {
    return {chunk.offset, chunk.offset + chunk.bytes};
}

struct Corruption {
    const char* name;
    const char* file; // under ../shared/data/laz
    std::function<Where(LazFile&)> corrupt;
    InputErrorKind kind;
    const char* detail; // a part of the message that says what is wrong
};

void PrintTo(const Corruption& corruption, std::ostream* out) {
    *out << corruption.name;
}

// Opens and reads the whole file: the error may come at either step.
void readWhole(const std::string& path) {
    auto reader = openPointCloud(path);
    reader->read([](const PointBatch&) {});
}

const Corruption kCorruptions[] = {
    // Truncated files and chunks.
    {"FileTruncatedInsideTheChunks", "autzen_trim.laz",
     [](LazFile& f) {
         f.bytes.resize(300000);
         return at(f.header.pointDataOffset);
     },
     InputErrorKind::Truncated, "the file is truncated"},
    {"FileTruncatedInsideTheChunkTableHeader", "terrascan_fmt8.laz",
     [](LazFile& f) {
         f.bytes.resize(f.table + 4);
         return at(f.table);
     },
     InputErrorKind::Truncated, "the file is truncated"},
    {"FileTruncatedInsideTheChunkTableEntries", "terrascan_fmt8.laz",
     [](LazFile& f) {
         f.bytes.resize(f.table + 10);
         return at(f.table);
     },
     InputErrorKind::CorruptData, "the LAZ chunk table is truncated or corrupt"},
    // The last chunk loses its last 1000 bytes; the table follows it as it should.
    {"LastChunkTruncated", "terrascan_fmt8.laz",
     [](LazFile& f) {
         f.bytes.erase(f.bytes.begin() + static_cast<std::ptrdiff_t>(f.table - 1000),
                       f.bytes.begin() + static_cast<std::ptrdiff_t>(f.table));
         put<std::uint64_t>(f.bytes, f.header.pointDataOffset, f.table - 1000);
         return at(f.table - 1000);
     },
     InputErrorKind::CorruptData, "LAZ chunk 13 of 14 at byte"},
    // A layer that ends early (its size shrunk, the next layer's grown: the chunk still adds
    // up).
    {"LayerTruncated", "terrascan_fmt8.laz",
     [](LazFile& f) {
         const std::uint64_t sizes = f.chunks[2].offset + 41 + 4; // after record and count
         const auto xy = get<std::uint32_t>(f.bytes, sizes);
         put<std::uint32_t>(f.bytes, sizes, xy - 100);
         put<std::uint32_t>(f.bytes, sizes + 4, get<std::uint32_t>(f.bytes, sizes + 4) + 100);
         const std::uint64_t layersStart = 41 + 4 + 4 * 14; // POINT14 9, RGBNIR14 2, BYTE14 3
         return at(f.chunks[2].offset + layersStart + xy - 100);
     },
     InputErrorKind::CorruptData, "channel, returns and x/y layer"},
    {"LayerSizesBeyondTheChunk", "terrascan_fmt8.laz",
     [](LazFile& f) {
         const std::uint64_t sizes = f.chunks[0].offset + 41 + 4;
         put<std::uint32_t>(f.bytes, sizes, get<std::uint32_t>(f.bytes, sizes) + 1);
         return at(f.chunks[0].offset + 41 + 4);
     },
     InputErrorKind::CorruptData, "LAZ chunk 0 of 14"},
    {"PointwiseChunkDataGarbage", "simple.laz",
     [](LazFile& f) {
         std::mt19937 random(5);
         const laz::Chunk& chunk = f.chunks[0];
         for (std::uint64_t i = chunk.offset + 600; i < chunk.offset + 3000; ++i) {
             f.bytes[i] = static_cast<std::uint8_t>(random());
         }
         return inChunk(chunk);
     },
     InputErrorKind::CorruptData, "LAZ chunk 0 of 1"},
    {"LayeredChunkDataGarbage", "1.2-with-color.copc.laz",
     [](LazFile& f) {
         std::mt19937 random(6);
         const laz::Chunk& chunk = f.chunks[0];
         for (std::uint64_t i = chunk.offset + 200; i < chunk.offset + chunk.bytes; ++i) {
             f.bytes[i] = static_cast<std::uint8_t>(random());
         }
         return inChunk(chunk);
     },
     InputErrorKind::CorruptData, "LAZ chunk 0 of 65"},

    // Corrupt chunk tables.
    {"ChunkTableOffsetInsideTheHeader", "autzen_trim.laz",
     [](LazFile& f) {
         put<std::uint64_t>(f.bytes, f.header.pointDataOffset, 100);
         return at(f.header.pointDataOffset);
     },
     InputErrorKind::CorruptData, "lies outside the point data"},
    {"ChunkTableVersion", "autzen_trim.laz",
     [](LazFile& f) {
         put<std::uint32_t>(f.bytes, f.table, 7);
         return at(f.table);
     },
     InputErrorKind::CorruptData, "chunk table version 7, expected 0"},
    {"ChunkTableCountBeyondThePointData", "autzen_trim.laz",
     [](LazFile& f) {
         put<std::uint32_t>(f.bytes, f.table + 4, 0xFFFFFF);
         return at(f.table + 4);
     },
     InputErrorKind::CorruptData, "lists 16777215 chunks"},
    {"ChunkTableEntriesGarbage", "terrascan_fmt8.laz",
     [](LazFile& f) {
         for (std::uint64_t i = f.table + 8; i < f.bytes.size(); ++i) {
             f.bytes[i] = static_cast<std::uint8_t>(i * 37);
         }
         return at(f.table);
     },
     InputErrorKind::CorruptData, "chunk table"},

    // Wrong point counts.
    {"HeaderCountMakesMoreFixedChunks", "autzen_trim.laz",
     [](LazFile& f) {
         put<std::uint32_t>(f.bytes, las::field::legacyPointCount, 160001);
         return at(f.table + 4);
     },
     InputErrorKind::CountMismatch, "which make 4 chunks"},
    {"HeaderCountDisagreesWithVariableChunks", "1.2-with-color.copc.laz",
     [](LazFile& f) {
         put<std::uint32_t>(f.bytes, las::field::legacyPointCount, 1066);
         put<std::uint64_t>(f.bytes, las::field::pointCount, 1066);
         return at(f.table);
     },
     InputErrorKind::CountMismatch, "hold 1065 points, but the header declares 1066"},
    {"HeaderCountOneShortOfTheLastLayeredChunk", "terrascan_fmt8.laz",
     [](LazFile& f) {
         put<std::uint64_t>(f.bytes, las::field::pointCount, 697720);
         return at(f.chunks[13].offset + 41);
     },
     InputErrorKind::CountMismatch, "the chunk says it holds 47721 points"},
    {"HeaderCountOneShortOfTheLastPointwiseChunk", "autzen_trim.laz",
     [](LazFile& f) {
         put<std::uint32_t>(f.bytes, las::field::legacyPointCount, 109999);
         return inChunk(f.chunks[2]);
     },
     InputErrorKind::CorruptData, "LAZ chunk 2 of 3"},
    // One point more than the chunks hold: decoding it runs out of data.
    {"HeaderCountOneMoreThanThePointwiseChunks", "autzen_trim.laz",
     [](LazFile& f) {
         put<std::uint32_t>(f.bytes, las::field::legacyPointCount, 110001);
         return at(f.chunks[2].offset + f.chunks[2].bytes);
     },
     InputErrorKind::CorruptData, "the header declares more points than the file holds"},

    // The laszip record.
    {"UnknownCompressor", "simple.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, f.vlr, 9);
         return at(f.vlr);
     },
     InputErrorKind::UnsupportedFeature, "unknown LAZ compressor 9"},
    {"LayeredCompressorForPointFormat3", "simple.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, f.vlr, 3);
         return at(f.vlr);
     },
     InputErrorKind::UnsupportedFeature, "does not fit"},
    {"UnknownCoder", "simple.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, f.vlr + 2, 1);
         return at(f.vlr + 2);
     },
     InputErrorKind::UnsupportedFeature, "LAZ coder 1"},
    {"ChunkSizeZero", "autzen_trim.laz",
     [](LazFile& f) {
         put<std::uint32_t>(f.bytes, f.vlr + 12, 0);
         return at(f.vlr + 12);
     },
     InputErrorKind::MalformedHeader, "chunk size 0"},
    {"UnknownItemType", "simple.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, f.item(0), 99);
         return at(f.item(0));
     },
     InputErrorKind::UnsupportedFeature, "unknown item type 99"},
    {"ItemsOutOfOrder", "simple.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, f.item(1), 8);
         return at(f.item(1));
     },
     InputErrorKind::MalformedHeader, "is RGB12, expected GPSTIME11"},
    {"PointwiseItemVersion3", "simple.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, f.item(0) + 4, 3);
         return at(f.item(0) + 4);
     },
     InputErrorKind::UnsupportedFeature, "POINT10 version 3 is not supported, expected 1 or 2"},
    {"LayeredItemVersion5", "terrascan_fmt8.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, f.item(1) + 4, 5);
         return at(f.item(1) + 4);
     },
     InputErrorKind::UnsupportedFeature, "RGBNIR14 version 5 is not supported"},
    {"ItemSizeWrong", "simple.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, f.item(0) + 2, 21);
         return at(f.item(0) + 2);
     },
     InputErrorKind::MalformedHeader, "POINT10 has size 21, expected 20"},
    {"ItemsDoNotFillTheRecord", "terrascan_fmt8.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, f.item(2) + 2, 4);
         return at(f.vlr + 32);
     },
     InputErrorKind::MalformedHeader, "fill 42-byte records"},
    // Every extra byte has its own models: a huge extra-bytes item would allocate hundreds of
    // megabytes for a file of a few.
    {"TooManyExtraBytes", "terrascan_fmt8.laz",
     [](LazFile& f) {
         put<std::uint16_t>(f.bytes, las::field::recordLength, 38 + 20000);
         put<std::uint16_t>(f.bytes, f.item(2) + 2, 20000);
         return at(f.item(2) + 2);
     },
     InputErrorKind::UnsupportedFeature, "extra bytes item of 20000 bytes"},
};

class LazMalformed : public ::testing::TestWithParam<Corruption> {};

TEST_P(LazMalformed, FailsWithItsKindNamingFileAndByte) {
    const Corruption& corruption = GetParam();
    OMICRON_REQUIRE_SHARED_FILE(source, std::string("laz/") + corruption.file);
    LazFile file = parse(source);
    const Where where = corruption.corrupt(file);
    test::TempDir dir;
    const std::string path = dir.file(std::string(corruption.name) + ".laz");
    test::writeBytes(path, file.bytes);
    try {
        readWhole(path);
        FAIL() << "expected InputError (" << toString(corruption.kind) << ")";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), corruption.kind)
            << "got " << toString(error.kind()) << ": " << error.what();
        EXPECT_EQ(error.path(), path);
        ASSERT_EQ(error.location().unit, InputLocation::Unit::Byte) << error.what();
        EXPECT_GE(error.location().value, where.first) << error.what();
        EXPECT_LE(error.location().value, where.last) << error.what();
        EXPECT_EQ(std::string(error.what()).rfind(path + ": byte ", 0), 0u) << error.what();
        EXPECT_NE(error.detail().find(corruption.detail), std::string::npos)
            << "expected '" << corruption.detail << "' in: " << error.what();
    }
}

INSTANTIATE_TEST_SUITE_P(SharedLaz, LazMalformed, ::testing::ValuesIn(kCorruptions),
                         [](const ::testing::TestParamInfo<Corruption>& info) {
                             return std::string(info.param.name);
                         });

// Random bytes changed anywhere in the file: the read either succeeds (a byte the decoder does
// not check, such as a coordinate in a raw first point) or throws InputError; never a crash, a
// hang or another exception.
TEST(LazMalformed, RandomCorruptionsFailCleanly) {
    std::mt19937 random(19);
    int failures = 0;
    int runs = 0;
    for (const char* name : {"simple.laz", "1.2-with-color.copc.laz"}) {
        OMICRON_REQUIRE_SHARED_FILE(source, std::string("laz/") + name);
        const std::vector<std::uint8_t> original = test::readBytes(source);
        test::TempDir dir;
        for (int run = 0; run < 150; ++run, ++runs) {
            std::vector<std::uint8_t> bytes = original;
            const int changes = 1 + static_cast<int>(random() % 8);
            for (int c = 0; c < changes; ++c) {
                bytes[random() % bytes.size()] = static_cast<std::uint8_t>(random());
            }
            const std::string path = dir.file("corrupt" + std::to_string(run) + ".laz");
            test::writeBytes(path, bytes);
            try {
                readWhole(path);
            } catch (const InputError& error) {
                ++failures;
                EXPECT_EQ(error.path(), path);
                EXPECT_FALSE(error.detail().empty());
            }
        }
    }
    // Most changes land in compressed data and are caught.
    EXPECT_GT(failures, runs / 2) << failures << " of " << runs << " corrupt files were refused";
}

} // namespace
} // namespace omicron
