// Inner kernels of the CPU automaton, exposed so that tests can check the
// vector path against the scalar one it replaces.
#pragma once

#include <cstdint>

#include "core/math/Automaton.h"

namespace cb::cpu {

// For the 64 voxels v0 .. v0+63: bit b is set iff the region-scaled event fires,
// rand24(key, v0 + b) < ((r'*q + 127) / 255) with r' = invert ? 255 - r[b] : r[b].
// Reads r[0..63] (callers pad the region buffer).
uint64_t EventBitsScalar(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert);
uint64_t EventBitsVector(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert);

// Bit b set iff r[b] != 0, for 64 bytes.
uint64_t NonZeroMaskScalar(const uint8_t* r);
uint64_t NonZeroMaskVector(const uint8_t* r);

// True when the vector kernels run on this CPU (AVX-512BW); otherwise the
// *Vector functions fall back to the scalar ones.
bool HasVectorKernels();
const char* CaKernelName();

// SPEC 3 steps 1-3 for the 64 voxels v0 .. v0+63 of one word: the bit-parallel
// form of core/math/Automaton.h (CaGrowth on the word, then CaVoxelEvents for every
// bit at once), tested against the per-voxel twin. f: the growth neighbourhood;
// r: the 64 region bytes (padded); valid: the bits inside the grid.
inline CaBits<uint64_t> CaStepWord(CaBits<uint64_t> s, uint64_t f, const uint8_t* r, uint64_t valid, uint32_t v0,
                                   const CaEvents& e) {
    const CaBits<uint64_t> grown = CaGrowth(s, f);  // no bits past nx, as s has none
    // Where R = 0 no event can change the result (P_hum = P_act = 0 and cld is
    // cleared), so only voxels with R > 0 that an event could flip draw numbers.
    const uint64_t inRegion = NonZeroMaskVector(r) & valid;
    CaBits<uint64_t> next{grown.hum, grown.act, grown.cld & inRegion};
    if (next.cld && e.qExt) next.cld &= ~(EventBitsVector(e.keyExt, v0, r, e.qExt, /*invert=*/true) & next.cld);
    if (const uint64_t candidates = ~grown.hum & inRegion; candidates && e.qHum)
        next.hum |= EventBitsVector(e.keyHum, v0, r, e.qHum, false) & candidates;
    if (const uint64_t candidates = ~grown.act & inRegion; candidates && e.qAct)
        next.act |= EventBitsVector(e.keyAct, v0, r, e.qAct, false) & candidates;
    return next;
}

}  // namespace cb::cpu
