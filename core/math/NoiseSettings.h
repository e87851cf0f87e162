// Settings of stage `noise` (SPEC 10a): the scene section `noise`, read by
// core/stages/noise/Noise.cpp and documented in docs/scenes.md ("noise"). The
// formulas that use them are in core/math/Noise.h.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/base/NamedValues.h"

namespace cb {

// The lattice noise an fBm sums.
enum class NoiseBasis : uint8_t {
    Perlin,   // improved Perlin (2002), signed, about [-1, 1]
    Simplex,  // Gustavson's 3-D simplex, signed, about [-1, 1]; its periods must be multiples of 3
    Worley,   // 1 - distance to the nearest feature point / sqrt(3), in [0, 1]
};

// The spellings of NoiseBasis in scene files.
inline constexpr std::array<NamedValue<NoiseBasis>, 3> kNoiseBasisNames{{
    {"perlin", NoiseBasis::Perlin},
    {"simplex", NoiseBasis::Simplex},
    {"worley", NoiseBasis::Worley},
}};

// fBm over one basis: sum_o gain^o noise(lacunarity^o p), o = 0 .. octaves-1.
struct FbmSettings {
    NoiseBasis basis = NoiseBasis::Perlin;
    uint32_t octaves = 5;
    double gain = 0.5;
    uint32_t lacunarity = 2;  // integral, so the period of octave o is frequency * lacunarity^o
    bool turbulence = false;  // sum |noise| instead of noise
    bool operator==(const FbmSettings&) const = default;
};

// A Gaussian tower (Olajos 2.3.2): amplitude * exp(-1/2 sum_a ((p_a - centre_a) / sigma_a)^2), in voxels.
struct NoiseTower {
    std::array<double, 3> center{0, 0, 0};  // voxel coordinates (voxel (i,j,k) has its centre at i+0.5, ...)
    std::array<double, 3> sigma{4, 4, 4};   // voxels, >= 0.001
    double amplitude = 0.5;
    bool operator==(const NoiseTower&) const = default;
};

// An optional small volume of detail noise, tiled across the grid (one detail
// voxel per grid voxel), that erodes the base shape (Schneider's remap).
struct NoiseDetail {
    bool enabled = false;
    uint32_t size = 32;      // edge of the cubic detail volume, voxels
    uint32_t frequency = 4;  // lattice cells across the detail volume per axis
    FbmSettings fbm{NoiseBasis::Worley, 3, 0.5, 2, false};
    double strength = 0.2;  // in [0, 0.99]: v <- (v - s d) / (1 - s d)
    bool operator==(const NoiseDetail&) const = default;
};

// Wang's coverage and density modulation (Wang, Ji and Zhang, eq. 15-16), in place of the
// threshold: q = D max(v - (m + 1 - C), 0), with a 2-D weather map
// m(x, y) = max(0, 2 f - 1), f a Perlin fBm over x and y in [0, 1], tiled: half
// the sky has m = 0 (only the coverage thins it), the rest is thinned up to m = 1.
struct NoiseCoverage {
    bool enabled = false;
    double coverage = 0.65;                   // C in [0, 1]; 1 - C acts as the threshold where m = 0
    double density = 1.0;                     // D >= 0
    std::array<uint32_t, 2> frequency{2, 2};  // lattice cells of the map across the grid in x and y
    uint32_t octaves = 3;
    double gain = 0.5;
    bool operator==(const NoiseCoverage&) const = default;
};

struct NoiseSettings {
    uint32_t seed = 1;
    std::array<uint32_t, 3> frequency{4, 4, 2};  // lattice cells of octave 0 across the grid per axis
    FbmSettings fbm;
    double heightA = 50, heightB = 4;  // HD(h) = (1 - e^{-a h}) e^{-b h}
    std::vector<NoiseTower> towers;
    double threshold = 0.35;  // c in [0, 0.99]: q = clamp((v - c) / (1 - c), 0, 1) (without coverage)
    NoiseDetail detail;
    NoiseCoverage coverage;
    // Time: the noise moves by this many voxels per step. Zero: the noise is
    // static and the stage runs once (docs/pipeline.md, "Noise").
    std::array<double, 3> drift{0, 0, 0};

    bool Animated() const { return drift[0] != 0 || drift[1] != 0 || drift[2] != 0; }
    bool operator==(const NoiseSettings&) const = default;
};

}  // namespace cb
