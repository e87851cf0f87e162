// The data block of stage `noise` on the GPU backends (core/math/noise.glsl):
// everything of a scene's noise that does not change per step, as 32-bit
// words, made once per scene on the host and uploaded as one storage buffer.
// The step's offsets travel separately (push constants / uniforms).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/math/Noise.h"
#include "core/math/noise_words.glsl"

namespace cb::noise {

// The header's word indices, kGpu<Name>: core/math/noise_words.glsl's list, from which noise.glsl makes its
// kNoise<Name> constants too; then the header's length.
enum GpuWord : uint32_t {
#define CB_NOISE_GPU_WORD(name, index) kGpu##name = index,
    CB_NOISE_WORDS(CB_NOISE_GPU_WORD)
#undef CB_NOISE_GPU_WORD
    kGpuHeaderWords = 64
};
static_assert(kGpuDetail < kGpuHeaderWords, "the header's words fit in the header");

// Header (64 words), then: the base permutation (256 words, one entry each),
// the weather map's permutation (256), HD per slice (nz floats, the CPU's own
// values: exp is not bit-exact across devices), the towers (7 floats each:
// centre, 1 / sigma^2, amplitude) and the detail volume (size^3 floats, made
// by NoiseForm on the host).
std::vector<uint32_t> GpuData(const NoiseForm& form);

// GpuData's size in bytes, without making it (the memory plan's ScratchBytes).
uint64_t GpuDataBytes(const NoiseSettings& settings, const Extent3& grid);

// The step's offsets as noise.glsl's `offsets`: base[3], detail[3], map[2].
std::array<float, 8> GpuOffsets(const StepOffsets& o);

}  // namespace cb::noise
