// Stage `render_splat`'s types (SPEC 8, docs/contract.md): its settings (in section `render`),
// parameters, inputs and counters.
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <array>
#include <cstdint>
#include <iterator>

#include "core/base/Counter.h"
#include "core/math/Camera.h"
#include "core/math/Ground.h"
#include "core/math/Light.h"
#include "core/math/Shading.h"

namespace cb {

class Buffer;  // core/pipeline/Backend.h

// Stage `render_splat` (SPEC 8): the splat renderer's own settings. In scene
// files they sit in the `render` section beside the shared ones (docs/scenes.md).
struct SplatSettings {
    double qMin = 0.3;        // a voxel makes a splat iff q_alpha > q_min
    double splatScale = 1.5;  // splat diameter d = splatScale * voxel size
    double opacity = 0.6;
    bool culling = true;   // view-frustum culling of tile-band boxes
    bool skipping = true;  // empty-space skipping from the density map
};

// Inputs of the splat renderer (SPEC 8). The order is computed on the host
// (MakeSplatOrder) and shared by every backend.
struct SplatParams {
    CameraFrame camera;
    const SplatOrder* order = nullptr;
    Vec3 sun{0, 0, 1};  // toward the sun
    Vec3 background{0, 0, 0};
    // The light terms (core/math/Light.h; made by MakeLightTerms): the sun and the ambient light; the point
    // light stays off (no transmittance toward it here).
    LightTerms light;
    float qMin = 0.3f, splatDiameter = 75, opacity = 0.6f, alpha = 0.5f;
    std::array<float, 3> origin{0, 0, 0};
    float voxelSize = 50;
    bool culling = true, skipping = true;
    uint32_t tile = 32, band = 4;  // of the occupancy maps
    GroundParams ground;           // the ground plane under the clouds (core/math/Ground.h); on: SplatInputs::G
};

struct SplatInputs {
    const Buffer* qPrev = nullptr;  // F32 volume
    const Buffer* qCur = nullptr;   // F32 volume
    const Buffer* T = nullptr;      // F32 volume: full-resolution transmittance
    // Occupancy of both steps (density stage); read only when skipping.
    const Buffer* tilesPrev = nullptr;
    const Buffer* tilesCur = nullptr;
    const Buffer* bandsPrev = nullptr;
    const Buffer* bandsCur = nullptr;
    const Buffer* G = nullptr;  // F32 (nx, ny, 1): the ground shadow; read only with params.ground.on
    const Buffer* TSky = nullptr;  // F32 volume: the sky light's T_sky; read only with the sky light on
};

struct SplatStats {
    uint64_t splats = 0;         // splats drawn (q_alpha > q_min, in front of the near plane, not culled)
    uint64_t voxelsVisited = 0;  // voxels the renderer looked at after culling and skipping
    uint64_t fragments = 0;      // pixel blends: covered pixels summed over splats, clipped to the image
};

// The splat renderer's counters (core/base/Counter.h).
inline constexpr Counter<SplatStats> kSplatCounters[] = {
    {"splats", &SplatStats::splats, CounterShown::ResultsAndReport},
    {"voxels_visited", &SplatStats::voxelsVisited, CounterShown::Results},
    {"fragments", &SplatStats::fragments, CounterShown::ReadBack},
};
static_assert(ReportedCounter(kSplatCounters).name == "splats");
static_assert(sizeof(SplatStats) == std::size(kSplatCounters) * sizeof(uint64_t), "a SplatStats member is unlisted");

}  // namespace cb
