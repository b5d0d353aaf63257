#include "io/laz/arithmetic_model.hpp"

#include <cassert>

namespace omicron::laz {

SymbolModel::SymbolModel(std::uint32_t symbolCountIn)
    : symbols(symbolCountIn), lastSymbol(symbolCountIn - 1), distribution(symbolCountIn),
      symbolCount(symbolCountIn, 1), updateCycle(symbolCountIn) {
    assert(symbols >= 2 && symbols <= kMaxSymbols);
    if (symbols > 16) {
        // Four slots a symbol or more (2^bits >= 4 * symbols): most values find their symbol
        // in the slot itself, without a search. terrascan_fmt8.laz decoded 10 % slower with
        // four symbols a slot (LASzip's table), 2 % slower with one slot a symbol, and no
        // faster with eight or sixteen (the table is rebuilt at every model update).
        std::uint32_t tableBits = 2;
        while (symbols > (std::uint32_t{1} << (tableBits - 2))) {
            ++tableBits;
        }
        tableSize = std::uint32_t{1} << tableBits;
        tableShift = kSymbolLengthShift - tableBits;
        decoderTable.resize(tableSize + 2 + kTableFillRun);
    }
    // The first update turns the unit counts into a uniform distribution (total = symbols).
    update();
    symbolsUntilUpdate = updateCycle = (symbols + 6) >> 1;
}

void SymbolModel::update() {
    totalCount += updateCycle;
    if (totalCount > kSymbolMaxCount) {
        totalCount = 0;
        for (std::uint32_t& count : symbolCount) {
            count = (count + 1) >> 1;
            totalCount += count;
        }
    }
    // scale * sum <= 2^31 because sum <= totalCount; a symbol's width is at least 1 unit
    // because totalCount <= 2^15 here.
    const std::uint32_t scale = 0x80000000u / totalCount;
    std::uint32_t sum = 0;
    if (tableSize == 0) {
        for (std::uint32_t k = 0; k < symbols; ++k) {
            distribution[k] = (scale * sum) >> (31 - kSymbolLengthShift);
            sum += symbolCount[k];
        }
    } else {
        // Slots (filled, slot] go to symbol k - 1. A fixed run of kTableFillRun stores covers
        // them without a data-dependent loop (a symbol spans about four slots, so the loop's
        // exit was a mispredicted branch per symbol); the slots it writes past `slot` are
        // written again by the later symbol or the tail below that owns them.
        std::uint32_t* table = decoderTable.data();
        std::uint32_t filled = 0;
        for (std::uint32_t k = 0; k < symbols; ++k) {
            distribution[k] = (scale * sum) >> (31 - kSymbolLengthShift);
            sum += symbolCount[k];
            const std::uint32_t slot = distribution[k] >> tableShift;
            for (std::uint32_t i = 1; i <= kTableFillRun; ++i) {
                table[filled + i] = k - 1;
            }
            for (std::uint32_t i = filled + kTableFillRun + 1; i <= slot; ++i) {
                table[i] = k - 1;
            }
            filled = slot > filled ? slot : filled;
        }
        table[0] = 0;
        while (filled <= tableSize) {
            table[++filled] = symbols - 1;
        }
    }
    updateCycle = (5 * updateCycle) >> 2;
    const std::uint32_t maxCycle = (symbols + 6) << 3;
    if (updateCycle > maxCycle) {
        updateCycle = maxCycle;
    }
    symbolsUntilUpdate = updateCycle;
}

void BitModel::update() {
    bitCount += updateCycle;
    if (bitCount > kBitMaxCount) {
        bitCount = (bitCount + 1) >> 1;
        bit0Count = (bit0Count + 1) >> 1;
        if (bit0Count == bitCount) {
            ++bitCount; // a 1 always keeps a non-zero probability
        }
    }
    const std::uint32_t scale = 0x80000000u / bitCount;
    bit0Probability = (bit0Count * scale) >> (31 - kBitLengthShift);
    updateCycle = (5 * updateCycle) >> 2;
    if (updateCycle > 64) {
        updateCycle = 64;
    }
    bitsUntilUpdate = updateCycle;
}

} // namespace omicron::laz
