// SymbolModel's decoder table, which the decoder trusts to bound its search: after every update,
// for every scaled value, the table's slot and the bisection between its bounds must find the
// symbol whose interval holds the value. update() fills the table in fixed runs that write
// past their slots; this holds it to the slot-by-slot fill too.
#include "io/laz/arithmetic_model.hpp"

#include <algorithm>
#include <gtest/gtest.h>
#include <random>
#include <vector>

namespace omicron::laz {
namespace {

// The table as LASzip fills it: slot by slot, each slot given the symbol before the first
// symbol whose interval starts in a later slot.
std::vector<std::uint32_t> slotBySlotTable(const SymbolModel& model) {
    std::vector<std::uint32_t> table(model.tableSize + 2);
    std::uint32_t filled = 0;
    for (std::uint32_t k = 0; k < model.symbols; ++k) {
        const std::uint32_t slot = model.distribution[k] >> model.tableShift;
        while (filled < slot) {
            table[++filled] = k - 1;
        }
    }
    table[0] = 0;
    while (filled <= model.tableSize) {
        table[++filled] = model.symbols - 1;
    }
    return table;
}

// The symbol holding `scaled` (a value in units of the interval's 2^-15), by the table and a
// bisection between its bounds, as ArithmeticDecoder::decodeSymbol searches.
std::uint32_t tableSymbol(const SymbolModel& model, std::uint32_t scaled) {
    const std::uint32_t slot = scaled >> model.tableShift;
    std::uint32_t symbol = model.decoderTable[slot];
    std::uint32_t end = model.decoderTable[slot + 1] + 1;
    while (end > symbol + 1) {
        const std::uint32_t middle = (symbol + end) >> 1;
        if (model.distribution[middle] > scaled) {
            end = middle;
        } else {
            symbol = middle;
        }
    }
    return symbol;
}

// The last symbol whose interval starts at or before `scaled`.
std::uint32_t trueSymbol(const SymbolModel& model, std::uint32_t scaled) {
    const auto begin = model.distribution.begin();
    return static_cast<std::uint32_t>(std::upper_bound(begin, begin + model.symbols, scaled) -
                                      begin - 1);
}

TEST(SymbolModel, DecoderTableFindsEverySymbolAfterEveryUpdate) {
    for (const std::uint32_t symbols : {17u, 33u, 128u, 256u, 1000u, 2048u}) {
        SCOPED_TRACE(symbols);
        SymbolModel model(symbols);
        ASSERT_GT(model.tableSize, 0u);
        std::mt19937 random(symbols);
        // Skewed counts (a few symbols most of the time, as corrector classes are), so some
        // symbols span many slots and others share one.
        std::geometric_distribution<std::uint32_t> skewed(0.3);
        std::uniform_int_distribution<std::uint32_t> any(0, symbols - 1);
        for (int update = 0; update < 30; ++update) {
            SCOPED_TRACE(update);
            while (model.symbolsUntilUpdate > 0) { // as decodeSymbol counts its symbols
                const std::uint32_t s = random() % 4 == 0 ? any(random) : skewed(random);
                ++model.symbolCount[s < symbols ? s : symbols - 1];
                --model.symbolsUntilUpdate;
            }
            model.update();
            const std::vector<std::uint32_t> reference = slotBySlotTable(model);
            ASSERT_TRUE(std::equal(reference.begin(), reference.end(), model.decoderTable.begin()));
            for (std::uint32_t scaled = 0; scaled < kSymbolMaxCount; scaled += 7) {
                ASSERT_EQ(tableSymbol(model, scaled), trueSymbol(model, scaled)) << scaled;
            }
        }
    }
}

} // namespace
} // namespace omicron::laz
