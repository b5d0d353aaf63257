// Text formatted on every core is written in point order: the file is what a loop over the
// points writes, for counts that fill no chunk, one chunk, whole groups and a ragged end.
#include "io/atomic_file_writer.hpp"
#include "io/parallel_text_writer.hpp"
#include "test_files.hpp"

#include <atomic>
#include <gtest/gtest.h>
#include <string>
#include <vector>

namespace omicron {
namespace {

std::string contentsOf(const std::string& path) {
    const std::vector<std::uint8_t> bytes = test::readBytes(path);
    return {bytes.begin(), bytes.end()};
}

TEST(ParallelTextWriter, TheFileIsThePointsInOrder) {
    test::TempDir dir;
    const std::string path = dir.file("lines.txt");
    for (const std::size_t count : {std::size_t{0}, std::size_t{1}, std::size_t{999},
                                    std::size_t{1000}, std::size_t{100'003}}) {
        std::atomic<std::size_t> formatted{0};
        {
            AtomicFileWriter out(path);
            out.write("header\n");
            writeTextInParallel(out, count, 1000,
                                [&](std::size_t begin, std::size_t end, std::string& text) {
                                    EXPECT_TRUE(text.empty());
                                    for (std::size_t i = begin; i < end; ++i) {
                                        text += std::to_string(i) + '\n';
                                    }
                                    formatted += end - begin;
                                });
            out.commit();
        }
        std::string expected = "header\n";
        for (std::size_t i = 0; i < count; ++i) {
            expected += std::to_string(i) + '\n';
        }
        EXPECT_EQ(contentsOf(path), expected) << count << " points";
        EXPECT_EQ(formatted.load(), count) << "a point formatted twice or not at all";
    }
}

} // namespace
} // namespace omicron
