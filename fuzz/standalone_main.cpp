// A fuzzing driver without libFuzzer, so every build (g++ included) can run the targets: each
// seed once, then random mutations of the seeds (bit flips, interesting values, truncations,
// deleted, repeated and inserted runs of bytes) for a time budget, with a fixed random seed so a
// failure replays. The suite runs it a few seconds per target; scripts/fuzz.sh runs the real
// libFuzzer builds (clang, ASan + UBSan) for as long as asked. A crash or an escaped exception
// ends the process: the test fails, and the input is in the pid's folder (fuzz_input.cpp).
//
//   fuzz_TARGET [--seconds S] [--max-bytes N] [--seed R] SEED_FILE_OR_FOLDER...
#include "fuzz_input.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

namespace {

using Bytes = std::vector<std::uint8_t>;

void addSeed(const std::filesystem::path& path, std::size_t maxBytes, std::vector<Bytes>& seeds) {
    std::ifstream in(path, std::ios::binary);
    Bytes bytes;
    bytes.resize(maxBytes);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(maxBytes));
    bytes.resize(static_cast<std::size_t>(in.gcount()));
    seeds.push_back(std::move(bytes));
}

void mutate(Bytes& bytes, std::mt19937_64& random) {
    const auto pick = [&](std::size_t n) { return n == 0 ? 0 : random() % n; };
    const int rounds = 1 + static_cast<int>(pick(4));
    for (int r = 0; r < rounds; ++r) {
        switch (pick(7)) {
        case 0: // flip a bit
            if (!bytes.empty()) {
                bytes[pick(bytes.size())] ^= static_cast<std::uint8_t>(1u << pick(8));
            }
            break;
        case 1: { // an interesting value over 1, 2, 4 or 8 bytes
            static const std::uint64_t values[] = {0, 1, 0x7f, 0x80, 0xff, 0x7fff, 0xffff,
                                                   0x7fffffff, 0xffffffff, ~0ull};
            const std::size_t width = std::size_t{1} << pick(4);
            if (bytes.size() >= width) {
                const std::uint64_t value = values[pick(std::size(values))];
                std::memcpy(bytes.data() + pick(bytes.size() - width + 1), &value, width);
            }
            break;
        }
        case 2: // truncate
            bytes.resize(pick(bytes.size() + 1));
            break;
        case 3: { // delete a run
            const std::size_t at = pick(bytes.size() + 1);
            const std::size_t count = std::min(bytes.size() - at, pick(64) + 1);
            bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                        bytes.begin() + static_cast<std::ptrdiff_t>(at + count));
            break;
        }
        case 4: { // repeat a run
            if (bytes.empty()) {
                break;
            }
            const std::size_t at = pick(bytes.size());
            const std::size_t count = std::min(bytes.size() - at, pick(256) + 1);
            const Bytes run(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                            bytes.begin() + static_cast<std::ptrdiff_t>(at + count));
            bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(pick(bytes.size() + 1)),
                         run.begin(), run.end());
            break;
        }
        case 5: { // insert random bytes
            const std::size_t count = pick(16) + 1;
            const std::size_t at = pick(bytes.size() + 1);
            for (std::size_t i = 0; i < count; ++i) {
                bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                             static_cast<std::uint8_t>(random()));
            }
            break;
        }
        default: // a random byte
            if (!bytes.empty()) {
                bytes[pick(bytes.size())] = static_cast<std::uint8_t>(random());
            }
        }
    }
}

} // namespace

int main(int argc, char** argv) {
    double seconds = 5.0;
    std::size_t maxBytes = std::size_t{64} << 10;
    std::uint64_t randomSeed = 1;
    std::vector<Bytes> seeds;
    std::string name = std::filesystem::path(argv[0]).filename().string();
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--seconds" && i + 1 < argc) {
            seconds = std::atof(argv[++i]);
        } else if (arg == "--max-bytes" && i + 1 < argc) {
            maxBytes = static_cast<std::size_t>(std::atoll(argv[++i]));
        } else if (arg == "--seed" && i + 1 < argc) {
            randomSeed = static_cast<std::uint64_t>(std::atoll(argv[++i]));
        } else if (std::filesystem::is_directory(arg)) {
            for (const auto& entry : std::filesystem::directory_iterator(arg)) {
                if (entry.is_regular_file()) {
                    addSeed(entry.path(), maxBytes, seeds);
                }
            }
        } else if (std::filesystem::is_regular_file(arg)) {
            addSeed(arg, maxBytes, seeds);
        }
    }
    if (seeds.empty()) {
        std::fprintf(stderr, "%s: no seed input found (../shared/data absent?)\n", name.c_str());
        return 77; // ctest: skipped
    }
    std::mt19937_64 random(randomSeed);
    std::uint64_t runs = 0;
    for (const Bytes& seed : seeds) {
        LLVMFuzzerTestOneInput(seed.data(), seed.size());
        ++runs;
    }
    const auto start = std::chrono::steady_clock::now();
    const auto elapsed = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    Bytes input;
    while (elapsed() < seconds) {
        input = seeds[random() % seeds.size()];
        mutate(input, random);
        LLVMFuzzerTestOneInput(input.data(), input.size());
        ++runs;
    }
    std::printf("fuzz=%s driver=standalone seeds=%zu runs=%llu seconds=%.1f crashes=0\n",
                name.c_str(), seeds.size(), static_cast<unsigned long long>(runs), elapsed());
    return 0;
}
