#include "laz_test_records.hpp"

#include "io/file_stream.hpp"

#include <memory>

namespace omicron::test {

Records decodeLaz(const std::string& path, const LazStreaming& streaming) {
    auto stream = std::make_unique<FileStream>(path);
    Records result;
    result.header = las::readHeader(*stream);
    EXPECT_TRUE(result.header.compressed);
    auto records = openLazRecords(std::move(stream), result.header, streaming);
    std::uint64_t nextIndex = 0;
    records->forEachBlock([&](const LasRecordBlock& block) {
        EXPECT_EQ(block.firstIndex, nextIndex);
        nextIndex += block.count;
        result.bytes.insert(result.bytes.end(), block.records,
                            block.records + block.count * result.header.recordLength);
        ++result.blocks;
        return true;
    });
    return result;
}

Records readLasRecords(const std::string& path) {
    FileStream stream(path);
    Records result;
    result.header = las::readHeader(stream);
    EXPECT_FALSE(result.header.compressed);
    result.bytes.resize(result.header.pointCount * result.header.recordLength);
    stream.seek(result.header.pointDataOffset);
    stream.readExact(result.bytes.data(), result.bytes.size(), "the reference records");
    return result;
}

::testing::AssertionResult sameRecords(const Records& decoded, const Records& reference) {
    const std::size_t length = reference.header.recordLength;
    if (decoded.bytes.size() != reference.bytes.size()) {
        return ::testing::AssertionFailure()
               << "decoded " << decoded.bytes.size() / length << " records, the reference has "
               << reference.bytes.size() / length;
    }
    for (std::size_t i = 0; i < decoded.bytes.size(); ++i) {
        if (decoded.bytes[i] != reference.bytes[i]) {
            return ::testing::AssertionFailure()
                   << "record " << i / length << " differs first at its byte " << i % length
                   << ": decoded " << int(decoded.bytes[i]) << ", reference "
                   << int(reference.bytes[i]);
        }
    }
    return ::testing::AssertionSuccess();
}

} // namespace omicron::test
