// The published inverse of lowbias32, and with it a seed that puts a chosen
// draw at a chosen step, stream and voxel (SPEC 1), so that a test can build
// the rare case where a draw lands exactly on an event's threshold.
#pragma once

#include <cstdint>

#include "core/math/Random.h"

namespace cb::test {

// The published inverse of lowbias32 (Wellons, hash-prospector README, `lowbias32_r`).
constexpr uint32_t LowBias32Inverse(uint32_t x) {
    x ^= x >> 16;
    x *= 0x43021123u;
    x ^= x >> 15 ^ x >> 30;
    x *= 0x1d69e2a5u;
    x ^= x >> 16;
    return x;
}

// A stream key under which rand24 at `voxel` is `draw` (0 .. 2^24-1): SPEC 1
// takes the top 24 bits of LB(voxel ^ key), so key = LB^-1(draw << 8 | low) ^ voxel,
// for any `low` in 0..255 (the 8 bits the shift drops).
constexpr uint32_t KeyForDraw(uint32_t draw, uint32_t voxel, uint32_t low = 0) {
    return LowBias32Inverse(draw << 8 | (low & 255u)) ^ voxel;
}

// A seed with rand24(seed, step, stream, voxel) == draw: SPEC 1's key is
// LB(seed ^ LB(step*4 + stream + 0x9E3779B9)), so seed = LB^-1(key) ^ that inner hash.
constexpr uint32_t SeedForDraw(uint32_t draw, uint32_t step, uint32_t stream, uint32_t voxel, uint32_t low = 0) {
    return LowBias32Inverse(KeyForDraw(draw, voxel, low)) ^ LowBias32(step * 4u + stream + 0x9E3779B9u);
}

}  // namespace cb::test
