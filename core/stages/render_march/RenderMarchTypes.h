// Stage `render_march`'s types (SPEC 10, docs/contract.md): the ray marcher's settings (section `march`), the
// lightning point light's (Wang, Ji and Zhang, section 6.3; section `lightning`), its parameters,
// inputs and counters. Fields, units and defaults in docs/scenes.md.
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <array>
#include <cstdint>
#include <iterator>

#include "core/base/Counter.h"
#include "core/math/Camera.h"
#include "core/math/Ground.h"
#include "core/math/March.h"
#include "core/math/Reprojection.h"

namespace cb {

class Buffer;  // core/pipeline/Backend.h

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
    // Temporal reprojection (SPEC 19, core/math/Reprojection.h): one pixel of each block x block traced a frame, the
    // rest reprojected from the previous frame; 1 traces every pixel.
    uint32_t reprojectionBlock = 1;
};

// Inputs of the ray marcher (SPEC 10) besides its buffers: the kernel's
// constants (core/math/March.h, voxel units) and how the backend feeds it.
struct MarchParams {
    CameraFrame camera;
    MarchSetup setup;
    std::array<float, 3> origin{0, 0, 0};  // world position of voxel corner (0, 0, 0)
    float alpha = 0.5f;                    // q_alpha = (1 - alpha) q_prev + alpha q_cur
    MarchLightSource light = MarchLightSource::Shade;
    uint32_t lightSteps = 8;  // n_l of the light march (sun with `march`, and the point light)
    bool jitter = false;
    uint32_t seed = 1, frame = 0;  // xi = rand24(seed, frame, 3, x + W y) / 2^24 with jitter
    bool skipping = true;
    uint32_t brick = 8;
    GroundParams ground;  // the ground plane under the clouds (core/math/Ground.h); on: MarchInputs::G
    // Which pixels this frame traces. Not full: the image holds the previous frame (drawn with reprojection.previous)
    // on entry, and its untraced pixels are reprojected from it.
    ReprojectionSetup reprojection;
};

struct MarchInputs {
    const Buffer* qPrev = nullptr;  // F32 volume
    const Buffer* qCur = nullptr;   // F32 volume
    const Buffer* T = nullptr;      // F32 volume; required with MarchLightSource::Shade, else unread
    const Buffer* G = nullptr;      // F32 (nx, ny, 1): the ground shadow; read only with params.ground.on
    const Buffer* TSky = nullptr;   // F32 volume: the sky light's T_sky; read only with the sky light on
};

struct MarchStats {
    uint64_t rays = 0;                     // rays that met the box between the near and far planes
    uint64_t samples = 0;                  // density samples
    uint64_t lightSamples = 0;             // light functor calls (samples with q_alpha > 0)
    uint64_t bricksSkipped = 0;            // empty bricks jumped over, summed over rays
    uint64_t emptyBricks = 0, bricks = 0;  // of the skip structure (0 without skipping)
    // Rays in SIMD lanes (the CPU, impl_cpu/MarchLanesCpu-inl.h): lane-steps that sampled or skipped, of the packet
    // steps times the lane count; their ratio is the lanes' utilisation. 0 where rays run one at a time.
    uint64_t laneSteps = 0, laneSlots = 0;
};

// The ray marcher's counters (core/base/Counter.h).
inline constexpr Counter<MarchStats> kMarchCounters[] = {
    {"rays", &MarchStats::rays, CounterShown::ReadBack},
    {"samples", &MarchStats::samples, CounterShown::ResultsAndReport},
    {"light_samples", &MarchStats::lightSamples, CounterShown::Results},
    {"bricks_skipped", &MarchStats::bricksSkipped, CounterShown::Results},
    {"empty_bricks", &MarchStats::emptyBricks, CounterShown::ReadBack},
    {"bricks", &MarchStats::bricks, CounterShown::ReadBack},
    {"lane_steps", &MarchStats::laneSteps, CounterShown::Results},
    {"lane_slots", &MarchStats::laneSlots, CounterShown::Results},
};
static_assert(ReportedCounter(kMarchCounters).name == "samples");
static_assert(sizeof(MarchStats) == std::size(kMarchCounters) * sizeof(uint64_t), "a MarchStats member is unlisted");

}  // namespace cb
