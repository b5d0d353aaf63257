// LAZ files of the waveform point formats: 4 and 5 (WAVEPACKET13, on the point-wise stream) and
// 9 and 10 (WAVEPACKET14, a layer of its own). No real file at hand has wave packets, so the
// tests encode them (laz_test_encoder): formats 4 and 5 from scratch, 9 and 10 by adding a
// wave packet item to every chunk of the real terrascan_fmt8.laz (its other layers as they
// are). The decoded records must equal the intended records byte for byte, packets included,
// with 1 and 2 threads; the reader delivers the same points as the uncompressed file and says
// that waveforms are ignored.
#include "io/file_stream.hpp"
#include "io/input_error.hpp"
#include "io/las/las_header.hpp"
#include "io/las/las_point_fields.hpp"
#include "io/las/las_writer.hpp"
#include "io/laz/chunk_table.hpp"
#include "io/laz/laszip_vlr.hpp"
#include "io/point_reader.hpp"
#include "io/raw_bytes.hpp"
#include "laz_test_encoder.hpp"
#include "laz_test_records.hpp"
#include "points/cube_transform.hpp"
#include "points/las_fields.hpp"
#include "test_files.hpp"

#include <array>
#include <cstring>
#include <gtest/gtest.h>
#include <string>
#include <tbb/global_control.h>
#include <vector>

namespace omicron {
namespace {

using laz::Item;
using laz::ItemType;
using Packet = std::array<std::uint8_t, 29>;

// Point i's wave packet, after point i - 1's: every way of coding the offset occurs (the same
// offset, right after the last packet, a signed 32-bit difference, a jump beyond 32 bits), and
// sizes, return points and steps vary.
class PacketSequence {
public:
    Packet next(std::uint64_t i) {
        if (i % 7 == 3) {
            // the same offset as the last packet
        } else if (i % 7 == 5) {
            m_offset += 12345 - static_cast<std::int64_t>(i % 3) * 40000;
        } else if (i % 31 == 17) {
            m_offset += (std::uint64_t{1} << 40) + i;
        } else {
            m_offset += m_size;
        }
        m_size = 256 + static_cast<std::uint32_t>(i % 5) * 8;
        Packet packet{};
        packet[0] = static_cast<std::uint8_t>(1 + i % 3);
        storeRaw(packet.data() + 1, m_offset);
        storeRaw(packet.data() + 9, m_size);
        storeRaw(packet.data() + 13, 1000.0f + 0.25f * static_cast<float>(i % 97));
        storeRaw(packet.data() + 17, 1e-3f * static_cast<float>(i % 13));
        storeRaw(packet.data() + 21, -2e-3f * static_cast<float>(i % 11));
        storeRaw(packet.data() + 25, -0.15f);
        return packet;
    }

private:
    std::uint64_t m_offset = 4096;
    std::uint32_t m_size = 0;
};

std::vector<std::uint8_t> slice(const std::vector<std::uint8_t>& bytes, std::uint64_t from,
                                std::uint64_t count) {
    return {bytes.begin() + static_cast<std::ptrdiff_t>(from),
            bytes.begin() + static_cast<std::ptrdiff_t>(from + count)};
}

void appendBytes(std::vector<std::uint8_t>& to, const std::vector<std::uint8_t>& bytes) {
    to.insert(to.end(), bytes.begin(), bytes.end());
}

// The records of both files, decoded with 1 and 2 threads, and the points read.
void expectSameContent(const std::string& lazPath, const std::string& lasPath) {
    const test::Records reference = test::readLasRecords(lasPath);
    for (int threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        EXPECT_TRUE(test::sameRecords(test::decodeLaz(lazPath), reference))
            << threads << " thread(s)";
    }
    const LoadedCloud laz = loadPointCloud(lazPath);
    const LoadedCloud las = loadPointCloud(lasPath);
    EXPECT_NE(laz.info.formatDetail.find("waveform packets ignored"), std::string::npos)
        << laz.info.formatDetail;
    ASSERT_EQ(laz.points.size(), las.points.size());
    EXPECT_TRUE(laz.points.positions == las.points.positions);
    EXPECT_TRUE(laz.points.colors == las.points.colors);
    EXPECT_TRUE(laz.points.las == las.points.las);
}

// Point formats 4 and 5 from scratch: POINT10 and GPSTIME11 (and RGB12) unchanged from each
// chunk's first point but for z, each point with its own wave packet.
class PointwiseWavePackets : public ::testing::TestWithParam<std::uint8_t> {};

TEST_P(PointwiseWavePackets, DecodeByteForByte) {
    const std::uint8_t format = GetParam();
    const std::uint64_t points = 250;
    const std::uint32_t chunkSize = 100; // two full chunks and a partial one
    test::TempDir dir;

    PointBatch batch;
    batch.attributes = las::attributesOfFormat(format, 0);
    LasFields fields;
    fields.classification = 2;
    fields.returns = 1 | 1 << 4;
    fields.gpsTime = 5000.5;
    fields.pointSourceId = 7;
    std::vector<std::uint8_t> column(batch.attributes.lasBytes());
    encodeLasFields(batch.attributes, fields, column.data());
    for (std::uint64_t i = 0; i < points; ++i) {
        batch.positions.emplace_back(0.25f, 0.5f, 0.1f + 0.003f * static_cast<float>(i));
        batch.intensities.push_back(0); // what an unchanged intensity decodes to
        if (batch.attributes.has(Attribute::Color)) {
            batch.colors.emplace_back(10, 200, 30);
        }
        batch.las.insert(batch.las.end(), column.begin(), column.end());
    }
    LasWriteOptions options;
    options.versionMinor = 4;
    options.pointFormat = format;
    const std::string lasPath = dir.file("waveform.las");
    writeLas(lasPath, batch, CubeTransform::fromBounds({glm::dvec3(0.0), glm::dvec3(1.0)}),
             options);

    // The packets go into the LAS file's records: the reference.
    std::vector<std::uint8_t> las = test::readBytes(lasPath);
    FileStream stream(lasPath);
    const las::Header header = las::readHeader(stream);
    const std::size_t packetAt = format == 4 ? 28 : 34;
    ASSERT_EQ(header.recordLength, packetAt + 29);
    PacketSequence sequence;
    for (std::uint64_t i = 0; i < points; ++i) {
        const Packet packet = sequence.next(i);
        std::memcpy(&las[header.recordOffset(i) + packetAt], packet.data(), packet.size());
    }
    test::writeBytes(lasPath, las);

    laz::test::LazAssembly assembly;
    assembly.prefix = slice(las, 0, header.pointDataOffset);
    assembly.vlrCount = loadRaw<std::uint32_t>(&las[las::field::vlrCount]);
    assembly.pointFormat = format;
    assembly.recordLength = header.recordLength;
    assembly.chunkSize = chunkSize;
    assembly.items = {{ItemType::Point10, 20, 2}, {ItemType::GpsTime11, 8, 2}};
    if (format == 5) {
        assembly.items.push_back({ItemType::Rgb12, 6, 2});
    }
    assembly.items.push_back({ItemType::WavePacket13, 29, 1});
    for (std::uint64_t first = 0; first < points; first += chunkSize) {
        const std::uint8_t* firstRecord = &las[header.recordOffset(first)];
        std::vector<std::uint8_t> chunk(firstRecord, firstRecord + header.recordLength);
        laz::test::ArithmeticEncoder encoder;
        laz::test::UnchangedPointwiseEncoder pointEncoder(format, firstRecord);
        laz::test::WavePacketEncoder packetEncoder;
        for (std::uint64_t i = first + 1; i < std::min(points, first + chunkSize); ++i) {
            const std::uint8_t* record = &las[header.recordOffset(i)];
            ASSERT_EQ(std::memcmp(record, firstRecord, 8), 0) << "x and y change";
            ASSERT_EQ(std::memcmp(record + 12, firstRecord + 12, packetAt - 12), 0)
                << "a field other than z and the packet changes";
            pointEncoder.encode(encoder, loadRaw<std::int32_t>(record + 8));
            packetEncoder.encode(encoder, record - header.recordLength + packetAt,
                                 record + packetAt);
        }
        appendBytes(chunk, encoder.finish());
        assembly.chunks.push_back(std::move(chunk));
    }
    const std::string lazPath = dir.file("waveform.laz");
    const std::vector<std::uint8_t> laz = laz::test::assembleLaz(assembly);
    test::writeBytes(lazPath, laz);

    expectSameContent(lazPath, lasPath);
    // A chunk cut short is an error naming the chunk, never garbage records.
    assembly.chunks.back().resize(assembly.chunks.back().size() - 8);
    const std::string truncatedPath = dir.file("truncated.laz");
    test::writeBytes(truncatedPath, laz::test::assembleLaz(assembly));
    try {
        loadPointCloud(truncatedPath);
        ADD_FAILURE() << "a truncated wave packet chunk was read";
    } catch (const InputError& error) {
        EXPECT_EQ(error.kind(), InputErrorKind::CorruptData) << error.what();
        EXPECT_NE(std::string(error.what()).find("LAZ chunk 2 of 3 (points 200 to 249"),
                  std::string::npos)
            << error.what();
    }
    // The fuzz target's seeds in tests/data are these files.
    const std::string seed = "laz/waveform-format" + std::to_string(format) + ".laz";
    EXPECT_TRUE(test::readBytes(test::repoDataFile(seed)) == laz)
        << seed << " is not the file this test makes";
}

INSTANTIATE_TEST_SUITE_P(Formats4And5, PointwiseWavePackets, ::testing::Values(4, 5),
                         [](const ::testing::TestParamInfo<std::uint8_t>& info) {
                             return "Format" + std::to_string(info.param);
                         });

// Point formats 10 (with RGBNIR14) and 9 (without) from terrascan_fmt8.laz: a wave packet
// layer joins each chunk's layers, coded from the packets of its points; chunk 1's packets
// are all its first point's, so its layer is empty, as LASzip writes it.
class LayeredWavePackets : public ::testing::TestWithParam<bool> {};

TEST_P(LayeredWavePackets, DecodeByteForByte) {
    OMICRON_REQUIRE_SHARED_FILE(sourcePath, "laz/terrascan_fmt8.laz");
    OMICRON_REQUIRE_SHARED_FILE(sourceLasPath, "laz/terrascan_fmt8.las");
    const bool withNir = GetParam();
    const std::vector<std::uint8_t> source = test::readBytes(sourcePath);
    FileStream stream(sourcePath);
    const las::Header header = las::readHeader(stream);
    ASSERT_EQ(header.pointFormat, 8);
    ASSERT_EQ(header.recordLength, 41); // POINT14 30, RGBNIR14 8, BYTE14 3
    const laz::LaszipVlr vlr = laz::parseLaszipVlr(
        slice(source, header.laszipRecordOffset, header.laszipRecordLength), sourcePath,
        header.laszipRecordOffset, header.pointFormat, header.recordLength);
    const std::vector<laz::Chunk> chunks =
        laz::readChunkLayout(
            stream, vlr,
            {header.pointDataOffset, stream.size(), header.pointCount, header.recordLength})
            .chunks;
    ASSERT_GE(chunks.size(), 3u);
    const std::uint64_t laszipRecord = header.laszipRecordOffset - las::kVlrHeaderSize;
    ASSERT_EQ(header.laszipRecordOffset + header.laszipRecordLength, header.pointDataOffset)
        << "the 'laszip encoded' record is expected last";

    // The records as they will be: POINT14, RGBNIR14 (format 10), the packet, the extra bytes.
    const test::Records sourceRecords = test::readLasRecords(sourceLasPath);
    const std::uint16_t keptBytes = withNir ? 38 : 30;
    const std::uint16_t recordLength = keptBytes + 29 + 3;
    std::vector<Packet> packets(header.pointCount);
    PacketSequence sequence;
    for (std::uint64_t i = 0; i < header.pointCount; ++i) {
        packets[i] = sequence.next(i);
    }
    const laz::Chunk& constant = chunks[1];
    for (std::uint64_t i = 1; i < constant.pointCount; ++i) {
        packets[constant.firstPoint + i] = packets[constant.firstPoint];
    }
    std::vector<std::uint8_t> records;
    for (std::uint64_t i = 0; i < header.pointCount; ++i) {
        const std::uint8_t* record = &sourceRecords.bytes[i * 41];
        ASSERT_EQ((record[15] >> 4) & 3, 0) << "one scanner channel expected";
        records.insert(records.end(), record, record + keptBytes);
        records.insert(records.end(), packets[i].begin(), packets[i].end());
        records.insert(records.end(), record + 38, record + 41);
    }

    laz::test::LazAssembly assembly;
    assembly.prefix = slice(source, 0, laszipRecord);
    assembly.vlrCount = loadRaw<std::uint32_t>(&source[las::field::vlrCount]) - 1;
    assembly.pointFormat = withNir ? 10 : 9;
    assembly.recordLength = recordLength;
    assembly.compressor = laz::Compressor::LayeredChunked;
    assembly.chunkSize = vlr.chunkSize;
    assembly.items = {{ItemType::Point14, 30, 3}};
    if (withNir) {
        assembly.items.push_back({ItemType::RgbNir14, 8, 3});
    }
    assembly.items.push_back({ItemType::WavePacket14, 29, 3});
    assembly.items.push_back({ItemType::Byte14, 3, 3});
    for (const laz::Chunk& chunk : chunks) {
        const std::vector<std::uint8_t> old = slice(source, chunk.offset, chunk.bytes);
        std::vector<std::uint32_t> sizes(14);
        std::memcpy(sizes.data(), &old[41 + 4], 4 * sizes.size());
        std::vector<std::vector<std::uint8_t>> layers;
        std::uint64_t at = 41 + 4 + 4 * sizes.size();
        for (std::uint32_t size : sizes) {
            layers.push_back(slice(old, at, size));
            at += size;
        }
        std::vector<std::uint8_t> packetLayer;
        bool changed = false;
        laz::test::ArithmeticEncoder encoder;
        laz::test::WavePacketEncoder packetEncoder;
        for (std::uint64_t i = 1; i < chunk.pointCount; ++i) {
            const std::uint64_t point = chunk.firstPoint + i;
            changed = changed || packets[point] != packets[point - 1];
            packetEncoder.encode(encoder, packets[point - 1].data(), packets[point].data());
        }
        if (changed) {
            packetLayer = encoder.finish();
        }
        // POINT14's nine layers, RGBNIR14's two, the packets', BYTE14's three.
        std::vector<std::vector<std::uint8_t>> kept(layers.begin(), layers.begin() + 9);
        if (withNir) {
            kept.push_back(layers[9]);
            kept.push_back(layers[10]);
        }
        kept.push_back(packetLayer);
        kept.insert(kept.end(), layers.begin() + 11, layers.end());

        std::vector<std::uint8_t> bytes = slice(records, chunk.firstPoint * recordLength,
                                                recordLength);         // the first point, raw
        bytes.insert(bytes.end(), old.begin() + 41, old.begin() + 45); // its point count
        for (const std::vector<std::uint8_t>& layer : kept) {
            const auto size = static_cast<std::uint32_t>(layer.size());
            bytes.insert(bytes.end(), reinterpret_cast<const std::uint8_t*>(&size),
                         reinterpret_cast<const std::uint8_t*>(&size) + 4);
        }
        for (const std::vector<std::uint8_t>& layer : kept) {
            appendBytes(bytes, layer);
        }
        assembly.chunks.push_back(std::move(bytes));
    }

    test::TempDir dir;
    const std::string lazPath = dir.file("waveform.laz");
    test::writeBytes(lazPath, laz::test::assembleLaz(assembly));
    // The reference: the same header and VLRs, the records uncompressed.
    std::vector<std::uint8_t> las = assembly.prefix;
    las[las::field::pointFormat] = assembly.pointFormat;
    storeRaw(&las[las::field::recordLength], assembly.recordLength);
    storeRaw(&las[las::field::pointDataOffset], static_cast<std::uint32_t>(laszipRecord));
    storeRaw(&las[las::field::vlrCount], assembly.vlrCount);
    appendBytes(las, records);
    const std::string lasPath = dir.file("waveform.las");
    test::writeBytes(lasPath, las);

    expectSameContent(lazPath, lasPath);
}

INSTANTIATE_TEST_SUITE_P(Formats9And10, LayeredWavePackets, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& info) {
                             return info.param ? "Format10" : "Format9";
                         });

} // namespace
} // namespace omicron
