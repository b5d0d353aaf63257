// Morton encoding: our byte-table encode vs "magic bits" shifts vs a bit loop, and coding
// over structure-of-arrays positions (our PointBatch) vs packed point records, measured in
// the same run. Prints one machine-readable line per variant.
//
// usage: morton_bench [POINTS]   (default 20,000,000)
#include "bench_timing.hpp"
#include "points/morton.hpp"
#include "points/morton_batch.hpp"

#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <glm/gtc/type_precision.hpp>
#include <glm/vec3.hpp>
#include <random>
#include <vector>

namespace {

using omicron::morton::Code;
using omicron::morton::kMaxLevel;

Code encodeMagic(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    // Magic bits: the shift-and-mask spread, the usual alternative to a table.
    using omicron::morton::detail::spreadBits3Shifts;
    return Code{1} << 63 | spreadBits3Shifts(x) | spreadBits3Shifts(y) << 1 |
           spreadBits3Shifts(z) << 2;
}

Code encodeLoop(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    Code code = 1;
    for (int bit = kMaxLevel - 1; bit >= 0; --bit) {
        code = code << 3 | ((z >> bit) & 1u) << 2 | ((y >> bit) & 1u) << 1 | ((x >> bit) & 1u);
    }
    return code;
}

// What omicron uses (morton.hpp: byte table).
Code encodeOmicron(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return omicron::morton::encode({x, y, z}, kMaxLevel);
}

struct PackedRecord { // what a compact AoS layout of our attributes would be
    glm::vec3 position;
    glm::vec3 normal;
    glm::u8vec3 color;
    std::uint16_t intensity;
};

template <typename Fn> double bestOf3(Fn&& fn) {
    return omicron::bench::bestSeconds(3, fn);
}

void printLine(const char* variant, const char* layout, std::size_t points, double s,
               double baselineS, std::size_t bytesPerPoint, Code checksum) {
    std::printf("bench=morton variant=%s layout=%s points=%zu ms=%.2f mpoints_per_s=%.1f "
                "speedup_vs_loop=%.2f bytes_per_point=%zu checksum=%016llx\n",
                variant, layout, points, s * 1e3, points / s / 1e6, baselineS / s, bytesPerPoint,
                static_cast<unsigned long long>(checksum));
}

} // namespace

int main(int argc, char** argv) {
    const std::size_t points = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 20'000'000;
    std::mt19937 random(1);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<glm::vec3> positions(points);
    std::vector<PackedRecord> records(points);
    for (std::size_t i = 0; i < points; ++i) {
        positions[i] = {unit(random), unit(random), unit(random)};
        records[i] = {positions[i], glm::vec3(0, 0, 1), glm::u8vec3(1, 2, 3), 7};
    }
    std::vector<Code> codes(points);
    const auto codeAll = [&](auto encodeFn) {
        return [&, encodeFn] {
            for (std::size_t i = 0; i < points; ++i) {
                const glm::vec3& p = positions[i];
                codes[i] = encodeFn(omicron::morton::quantize(p.x), omicron::morton::quantize(p.y),
                                    omicron::morton::quantize(p.z));
            }
        };
    };
    const auto checksum = [&] {
        Code sum = 0;
        for (Code c : codes) {
            sum ^= c + 0x9e3779b97f4a7c15ull + (sum << 6) + (sum >> 2);
        }
        return sum;
    };

    const double loopS =
        bestOf3(codeAll([](auto x, auto y, auto z) { return encodeLoop(x, y, z); }));
    const Code loopSum = checksum();
    const double tableS =
        bestOf3(codeAll([](auto x, auto y, auto z) { return encodeOmicron(x, y, z); }));
    const Code tableSum = checksum();
    const double magicS =
        bestOf3(codeAll([](auto x, auto y, auto z) { return encodeMagic(x, y, z); }));
    const Code magicSum = checksum();
    if (loopSum != tableSum || loopSum != magicSum) {
        std::fprintf(stderr, "morton_bench: encoders disagree\n");
        return 1;
    }
    const double batchS = bestOf3([&] { omicron::morton::encodeUnitBatch(positions, codes); });
    if (checksum() != tableSum) {
        std::fprintf(stderr, "morton_bench: the batch encoder disagrees\n");
        return 1;
    }
    printLine("bit_loop", "soa", points, loopS, loopS, sizeof(glm::vec3), loopSum);
    printLine("omicron_byte_table", "soa", points, tableS, loopS, sizeof(glm::vec3), tableSum);
    printLine("magic_bits", "soa", points, magicS, loopS, sizeof(glm::vec3), magicSum);
    printLine("omicron_batch", "soa", points, batchS, loopS, sizeof(glm::vec3), tableSum);

    const double aosS = bestOf3([&] {
        for (std::size_t i = 0; i < points; ++i) {
            const glm::vec3& p = records[i].position;
            codes[i] = encodeOmicron(omicron::morton::quantize(p.x), omicron::morton::quantize(p.y),
                                     omicron::morton::quantize(p.z));
        }
    });
    printLine("omicron_byte_table", "packed_records", points, aosS, loopS, sizeof(PackedRecord),
              checksum());
    std::printf("bench=morton summary soa_vs_packed_speedup=%.2f table_vs_magic_speedup=%.2f "
                "batch_vs_table_speedup=%.2f\n",
                aosS / tableS, magicS / tableS, tableS / batchS);
    return 0;
}
