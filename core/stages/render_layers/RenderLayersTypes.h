// Stage `render_layers`'s types (SPEC 15, docs/contract.md): the layered renderer's settings
// (section `layers`), its parameters, inputs and counters. Fields, units and defaults in docs/scenes.md.
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <array>
#include <cstdint>
#include <iterator>

#include "core/base/Counter.h"
#include "core/math/Camera.h"
#include "core/math/Layers.h"
#include "core/math/NoiseSettings.h"

namespace cb {

class Buffer;  // core/pipeline/Backend.h

// Where a layer fragment's light comes from (SPEC 15): shade's T at the frame's sun, or Wang, Ji and Zhang's
// relighting: T shaded once for the first step's sun s0, scaled by max(0, s0 . s) for the frame's sun s.
enum class LayersRelight : uint8_t { Shade, Vector };

struct LayersSettings {
    uint32_t count = 0;     // N; 0: the grid's nz (one layer on each voxel-centre plane)
    double extent = 0;      // metres, the layers' horizontal radius around the eye; 0: each camera's far plane
    double fade = 0.5;      // the fraction of the extent over which the opacity falls to 0 (LayersFade); 0: a hard cut
    double maxLength = 0;   // l_max, voxel edges; 0: the grid's nz (a fragment stands for at most the slab seen
                            // straight through)
    // The wind (Wang, Ji and Zhang, eq. 18): the clouds drift by this many metres per step in x and y, at the
    // frame's time step - 1 + alpha (as q's interpolation).
    std::array<double, 2> wind{0, 0};
    // Enabled: the opacity is Wang, Ji and Zhang's eq. 16 (coverage C, density factor D_w) of q and a 2-D
    // modulation map m of the noise stage's weather-map form (frequency, octaves, gain); else beer's.
    NoiseCoverage wang;
    LayersRelight relight = LayersRelight::Shade;
    // The billboards near the eye (LOD0): r0, metres (0: none; the layers' annulus starts there), and the spacing
    // p_s of their square grid, metres (0: the grid's voxel size).
    double lod0Radius = 0;
    double billboardSpacing = 0;
    double exposure = 1.0;  // PNG: Reinhard(exposure C), sRGB encoded
    bool toneMap = true;    // PNG only; false: clamp(exposure C)
};

// An upper bound on one call's billboards: (2 r0 / p_s + 2)^2 grid points on each of the N layers (nz: the grid's,
// N's default), p_s the spacing or the voxel size h; 0 without LOD0.
inline double LayersBillboardBound(const LayersSettings& layers, double voxelSize, uint32_t nz) {
    if (!(layers.lod0Radius > 0)) return 0;
    const double side = 2 * layers.lod0Radius / (layers.billboardSpacing > 0 ? layers.billboardSpacing : voxelSize) + 2;
    return side * side * double(layers.count > 0 ? layers.count : nz);
}
// The most billboards a scene may ask for (LayersBillboardBound): each is 16 bytes, and every pixel of the CPU and
// Vulkan tests each one.
inline constexpr double kMaxLayersBillboards = double(1u << 20);

// Inputs of the layered renderer besides its buffers: the kernel's constants
// (core/math/Layers.h, voxel units) and what the backend needs to feed it.
struct LayersParams {
    CameraFrame camera;
    LayersSetup setup;
    std::array<float, 3> origin{0, 0, 0};  // world position of voxel corner (0, 0, 0)
    float alpha = 0.5f;                    // q_alpha = (1 - alpha) q_prev + alpha q_cur
};

struct LayersInputs {
    const Buffer* qPrev = nullptr;  // F32 volume
    const Buffer* qCur = nullptr;   // F32 volume
    const Buffer* T = nullptr;      // F32 volume: shade's T
    const Buffer* TSky = nullptr;   // F32 volume: the sky light's T_sky; read only with the sky light on
    uint64_t stamp = 0;             // StageHostInputs::inputsStamp: equal non-zero stamps, unchanged contents
};

struct LayersStats {
    uint64_t fragments = 0;  // layer crossings within range (near / far planes, extent, box without tiling)
    uint64_t drawn = 0;      // of them with q_alpha > 0: blended
};

// The layered renderer's counters (core/base/Counter.h).
inline constexpr Counter<LayersStats> kLayersCounters[] = {
    {"fragments", &LayersStats::fragments, CounterShown::ResultsAndReport},
    {"drawn", &LayersStats::drawn, CounterShown::Results},
};
static_assert(ReportedCounter(kLayersCounters).name == "fragments");
static_assert(sizeof(LayersStats) == std::size(kLayersCounters) * sizeof(uint64_t), "a LayersStats member is unlisted");

}  // namespace cb
