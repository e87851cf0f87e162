// The data block of stage `noise` on the GPU backends (core/math/noise.glsl):
// everything of a scene's noise that does not change per step, as 32-bit
// words, made once per scene on the host and uploaded as one storage buffer.
// The step's offsets travel separately (push constants / uniforms).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/math/Noise.h"

namespace cb::noise {

// The header's word indices; noise.glsl's kNoise* constants must match.
enum GpuWord : uint32_t {
    kGpuNx = 0,
    kGpuNy = 1,
    kGpuNz = 2,
    kGpuBasis = 3,
    kGpuOctaves = 4,
    kGpuGain = 5,
    kGpuLacunarity = 6,
    kGpuTurbulence = 7,
    kGpuScale = 8,
    kGpuPeriod = 11,
    kGpuDetailOn = 14,
    kGpuDetailSize = 15,
    kGpuStrength = 16,
    kGpuCoverageOn = 17,
    kGpuCoverage = 18,
    kGpuDensity = 19,
    kGpuThreshold = 20,
    kGpuMapOctaves = 21,
    kGpuMapGain = 22,
    kGpuMapPeriod = 23,
    kGpuMapScale = 25,
    kGpuTowerCount = 27,
    kGpuSeed = 28,
    kGpuBasePerm = 29,
    kGpuMapPerm = 30,
    kGpuHeights = 31,
    kGpuTowers = 32,
    kGpuDetail = 33,
    kGpuHeaderWords = 64
};

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
