// The exact reference render of the ray marcher (SPEC 11):
// render_march's own per-ray kernel MarchRay (core/math/March.h) with a light
// functor that returns the EXACT transmittance toward the sun and toward the
// point light at each sample (TrilinearDepthTracer: the same trilinear field
// of q_alpha the marcher samples), a fine fixed step, epsilon = 0 (no early
// termination), no jitter (the sample at each segment's midpoint) and no
// brick skipping (every sample is taken). Everything else (camera, sun,
// ambient, background, phase, powder, point light) is the scene's, as
// MakeMarchParams gives it. docs/accuracy.md, "Images".
#pragma once

#include <span>
#include <vector>

#include "core/base/Error.h"
#include "core/pipeline/Backend.h"
#include "reference/Reference.h"

namespace cb::ref {

struct MarchReferenceOptions {
    float stepVoxels = 0.125f;  // the fixed step Delta, voxel edges (default 1/8)
    int threads = 0;            // 0 = every hardware thread
};

struct MarchReferenceResult {
    std::vector<float> image;  // (3, width, height), linear HDR, as RenderMarch writes it
    TraceStats light;          // exact light rays (sun and point light) and the time of the whole render
    uint64_t samples = 0;      // density samples of the main march
    double buildSeconds = 0;   // the tracer's Embree build
    size_t primitives = 0;
};

// `params` as MakeMarchParams gives it; its light source, step, adaptive
// step, epsilon, jitter and skipping are overridden as above. q_alpha =
// (1 - alpha) qPrev + alpha qCur (canonical, grid.Count() each).
Result<MarchReferenceResult> RenderMarchReference(const MarchParams& params, const Extent3& grid,
                                                  std::span<const float> qPrev, std::span<const float> qCur,
                                                  const MarchReferenceOptions& options = {});

}  // namespace cb::ref
