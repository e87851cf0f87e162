// Inner kernels of the CPU automaton, compiled once per SIMD target
// (impl_cpu/CpuIsa.h) and exposed so that tests can check every target's
// vector path against the scalar one it replaces.
#pragma once

#include <cstdint>

#include "core/math/Automaton.h"
#include "impl_cpu/BitField.h"

namespace cb::cpu {

// For the 64 voxels v0 .. v0+63: bit b is set iff the region-scaled event fires,
// rand24(key, v0 + b) < ((r'*q + 127) / 255) with r' = invert ? 255 - r[b] : r[b].
// Reads r[0..63] (callers pad the region buffer).
uint64_t EventBitsScalar(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert);
// The same on the active target's vectors.
uint64_t EventBitsVector(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert);

// Bit b set iff r[b] != 0, for 64 bytes.
uint64_t NonZeroMaskScalar(const uint8_t* r);
uint64_t NonZeroMaskVector(const uint8_t* r);

// SPEC 3 steps 1-3 for the 64 voxels v0 .. v0+63 of one word: the bit-parallel
// form of core/math/Automaton.h (CaGrowth on the word, then CaVoxelEvents for every
// bit at once), tested against the per-voxel twin. f: the growth neighbourhood;
// r: the 64 region bytes (padded); valid: the bits inside the grid.
CaBits<uint64_t> CaStepWord(CaBits<uint64_t> s, uint64_t f, const uint8_t* r, uint64_t valid, uint32_t v0,
                            const CaEvents& e);

// One automaton step's rows: state in, region bytes (padded), state out.
struct CaStepRowsJob {
    const BitField *hum, *act, *cld;
    const uint8_t* region;
    BitField *humOut, *actOut, *cldOut;
    CaEvents events;
};

// SPEC 3 steps 1-3 for the rows r0 .. r1 - 1 (row r = j + ny k) of the job's
// fields, CaStepWord on each word.
void CaStepRows(const CaStepRowsJob& job, uint32_t r0, uint32_t r1);

}  // namespace cb::cpu
