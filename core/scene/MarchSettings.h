// Scene settings of the ray marcher (SPEC 10, section `march`) and of the
// lightning point light (Wang, Ji and Zhang, section 6.3, section `lightning`). Read by
// core/scene/SceneMarchReader.cpp; fields, units and defaults in docs/scenes.md.
#pragma once

#include <array>
#include <cstdint>

namespace cb {

// Where the light toward the sun at a sample comes from (SPEC 10).
enum class MarchLightSource : uint8_t {
    Shade,  // trilinear T of the shade stage at the sample (taps outside read 1)
    March,  // a secondary march of n_l steps toward the sun (Olajos's light march)
};

struct MarchSettings {
    double step = 0.5;  // Delta_0, voxel edges
    bool adaptive = false;
    double kappa = 0.05;        // Delta(t) = Delta_0 + kappa max(0, t - t_a)
    double adaptiveStart = 64;  // t_a, voxel edges from the eye
    bool jitter = false;        // xi from rand24(seed, step, 3, pixel) instead of 0.5
    MarchLightSource light = MarchLightSource::Shade;
    uint32_t lightSteps = 8;  // n_l
    bool powder = false;
    double powderC = 2.0;   // powder = 1 - exp(-c tau_light) = 1 - T_light^c
    double epsilon = 0.01;  // stop when T_view < epsilon
    bool skipping = true;   // brick skip structure
    uint32_t brick = 8;     // brick edge in voxels
    double exposure = 1.0;  // PNG: Reinhard(exposure C), sRGB encoded
    bool toneMap = true;    // PNG only; false: clamp(exposure C)
};

// A point light (Wang, Ji and Zhang, eq. 21) that flashes over a window of steps.
struct LightningSettings {
    bool enabled = false;
    std::array<double, 3> position{0, 0, 0};  // world, metres
    std::array<double, 3> color{0.8, 0.85, 1.0};
    double intensity = 1e6;                   // radiance * metres^2
    double radius = 50;                       // r0, metres: the 1/D^2 law is capped at 1/r0^2
    uint32_t flashStart = 0, flashSteps = 1;  // on for steps [start, start + steps)

    bool OnAt(uint32_t step) const {
        return enabled && step >= flashStart && uint64_t(step) < uint64_t(flashStart) + flashSteps;
    }
};

}  // namespace cb
