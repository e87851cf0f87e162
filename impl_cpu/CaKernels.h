// Inner kernels of the CPU automaton, exposed so that tests can check the
// vector path against the scalar one it replaces.
#pragma once

#include <cstdint>

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

}  // namespace cb::cpu
