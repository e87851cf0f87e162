// Dobashi's bit-field layout for the CPU backend: each x-row of the grid is
// packed into ceil(nx/64) uint64 words, bit b of word w holding voxel
// i = 64*w + b. Invariant: the bits past nx in a row's last word are always 0,
// so reading them behaves as "outside the grid is 0" (SPEC 0).
#pragma once

#include <cstdint>
#include <vector>

#include "core/math/Grid.h"

namespace cb::cpu {

class BitField {
  public:
    BitField() = default;
    explicit BitField(Extent3 extent)
        : mExtent(extent), mWordsPerRow(CeilDiv(extent.nx, 64)),
          mWords(size_t(mWordsPerRow) * extent.ny * extent.nz, 0) {}

    const Extent3& Extent() const { return mExtent; }
    uint32_t WordsPerRow() const { return mWordsPerRow; }
    // Mask of valid bits in a row's last word.
    uint64_t LastWordMask() const {
        uint32_t rem = mExtent.nx % 64;
        return rem == 0 ? ~0ull : (1ull << rem) - 1;
    }

    uint64_t* Row(uint32_t j, uint32_t k) { return mWords.data() + size_t(mWordsPerRow) * (j + size_t(mExtent.ny) * k); }
    const uint64_t* Row(uint32_t j, uint32_t k) const {
        return mWords.data() + size_t(mWordsPerRow) * (j + size_t(mExtent.ny) * k);
    }
    // Row at a possibly out-of-grid (j, k); nullptr outside.
    const uint64_t* RowOrNull(int64_t j, int64_t k) const {
        if (j < 0 || k < 0 || j >= mExtent.ny || k >= mExtent.nz) return nullptr;
        return Row(uint32_t(j), uint32_t(k));
    }

    bool Get(uint32_t i, uint32_t j, uint32_t k) const { return (Row(j, k)[i >> 6] >> (i & 63)) & 1; }
    void Set(uint32_t i, uint32_t j, uint32_t k, bool value) {
        uint64_t bit = 1ull << (i & 63);
        uint64_t& word = Row(j, k)[i >> 6];
        word = value ? (word | bit) : (word & ~bit);
    }

    std::vector<uint64_t>& Words() { return mWords; }
    const std::vector<uint64_t>& Words() const { return mWords; }

  private:
    Extent3 mExtent;
    uint32_t mWordsPerRow = 0;
    std::vector<uint64_t> mWords;
};

}  // namespace cb::cpu
