// The adaptive probability models of LAZ's arithmetic coder (LASzip's, after Amir Said's
// FastAC). A decoder must adapt its models exactly as the encoder did, symbol for symbol, so
// every constant and every rounding below is part of the LAZ format, not a tuning choice.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace omicron::laz {

// A symbol model's probabilities are 15-bit fractions of the interval length.
inline constexpr std::uint32_t kSymbolLengthShift = 15;
inline constexpr std::uint32_t kSymbolMaxCount = std::uint32_t{1} << kSymbolLengthShift;
// A bit model's probability of a 0 is a 13-bit fraction.
inline constexpr std::uint32_t kBitLengthShift = 13;
inline constexpr std::uint32_t kBitMaxCount = std::uint32_t{1} << kBitLengthShift;

inline constexpr std::uint32_t kMaxSymbols = 2048;

// SymbolModel::update fills the decoder table in runs of this many slots (see there).
inline constexpr std::uint32_t kTableFillRun = 8;

// An adaptive model over `symbols` symbols (2 to kMaxSymbols). The decoder reads the public
// fields directly: they are the model's whole state.
struct SymbolModel {
    // Every symbol starts with a count of 1. Asserts 2 <= symbols <= kMaxSymbols (callers pass
    // constants of the format).
    explicit SymbolModel(std::uint32_t symbols);

    // Recomputes the cumulative distribution (and the decoder's lookup table) from the counts,
    // halving the counts when their total passes kSymbolMaxCount; called every
    // `symbolsUntilUpdate` decoded symbols, at an interval that grows to (symbols + 6) * 8.
    void update();

    std::uint32_t symbols;
    std::uint32_t lastSymbol;
    std::vector<std::uint32_t> distribution; // cumulative, in units of 2^-15
    std::vector<std::uint32_t> symbolCount;
    // Only for more than 16 symbols: decoderTable[t] is the first symbol whose interval may
    // hold a value whose top bits are t, so a decode starts its search near the answer.
    std::vector<std::uint32_t> decoderTable;
    std::uint32_t tableSize = 0;
    std::uint32_t tableShift = 0;
    std::uint32_t totalCount = 0;
    std::uint32_t updateCycle;
    std::uint32_t symbolsUntilUpdate;
};

// Models chosen by a small previous value, made on first use in a chunk (LASzip makes them
// lazily too: a fresh model is the encoder's starting state either way).
template <std::size_t N>
SymbolModel& lazyModel(std::array<std::unique_ptr<SymbolModel>, N>& models, std::size_t index,
                       std::uint32_t symbols) {
    std::unique_ptr<SymbolModel>& model = models[index];
    if (!model) {
        model = std::make_unique<SymbolModel>(symbols);
    }
    return *model;
}

// An adaptive model of one binary decision.
struct BitModel {
    void update();

    std::uint32_t bit0Count = 1;
    std::uint32_t bitCount = 2;
    std::uint32_t bit0Probability = std::uint32_t{1} << (kBitLengthShift - 1);
    std::uint32_t updateCycle = 4; // frequent updates at first
    std::uint32_t bitsUntilUpdate = 4;
};

} // namespace omicron::laz
