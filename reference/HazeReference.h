// The exact single-scattering reference of the haze below the clouds ("shafts of light"): what the shell-based
// crepuscular rays are measured against.
//
// Units are voxel units (core/math/March.h): a world point w is at (w - origin) / h, the grid's box is
// [0,nx]x[0,ny]x[0,nz], the clouds are the trilinear field of q_alpha (reference/Trilinear.h), periodic in x and y
// with `tiling`. The haze is a homogeneous medium filling the slab 0 <= z <= nz/2 (infinite in x and y), extinction
// sigma = extinction * h per voxel edge, Henyey-Greenstein phase P^ = 4 pi p (core/math/Shading.h).
//
// Pixel (x, y) casts PixelRayDirection(camera, x, y) (unit d, cosForward) from o = (eye - origin) / h over the view
// depths [near, far], t in [near, far] / (h cosForward); its haze segment [a, b] is that range inside the slab. With
// s the unit vector toward the sun and sc = cloudSigma * h,
//   L = sunRadiance P^(d.s) int_a^b sigma V(p(t)) Tview(t) exp(-sigma t) dt,
//   V(p) = exp(-sc * depth of the field from p along s to the edge of the cloud volume),
//   Tview(t) = exp(-sc * int_0^t q(o + u d) du)  (the clouds between the eye and the point).
// The sun's own path through the haze is not attenuated. A sun with s_z <= 0 gives 0 everywhere.
//
// Quadrature. V and Tview are exact (ExactDepth: TrilinearDepthTracer's closed-form integral of the field). The t
// integral is split in pieces:
// - Where neither the view ray nor the sun ray from p(t) can meet the clouds, V = 1 and Tview is constant, and the
//   integral is closed: Tview (exp(-sigma t0) - exp(-sigma t1)). Without tiling that is where the view ray's xy
//   lies outside the rectangle R: the xy bounds of the field's support (the dual cells with a nonzero corner,
//   within the box's footprint), swept back along the sun, -s_xy u for u in [0, zTop / s_z] with zTop the support's
//   top (a sun ray from a haze point leaves the clouds' heights within that length). R lies within the box's
//   footprint grown by |s_xy| nz / s_z. The view ray's xy is a line, so it meets R in one interval: at most one
//   piece of quadrature between two closed pieces. Without clouds (cloudSigma = 0 or q all 0) the whole segment
//   is closed.
// - Elsewhere (with tiling: the whole segment) a composite product-midpoint rule: n = ceil(length / stepVoxels)
//   equal sub-intervals [t_i, t_i+1], each weighted by the exact integral of sigma exp(-sigma t) over it,
//   exp(-sigma t_i) - exp(-sigma t_i+1), times V Tview at its midpoint (exact for V Tview constant; error
//   O(step^2) times the curvature of V Tview). Tview is advanced exactly, midpoint to midpoint.
// - The walk stops early once the most the rest can add, Tview(t_i) exp(-sigma t_i) (V, Tview <= 1), is below 1e-10
//   of the sum so far, or below 1e-46 / (max sunRadiance P^) (it would round to 0 in float).
// Everything is in double; the image is rounded to float once.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/base/Error.h"
#include "core/math/Camera.h"
#include "core/math/Grid.h"

namespace cb::ref {

struct HazeReferenceParams {
    CameraFrame camera;                    // core/math/Camera.h (MakeCameraFrame)
    std::array<float, 3> origin{0, 0, 0};  // grid origin, metres
    float voxelSize = 1;                   // h, metres
    Vec3 sun{0, 0, 1};                     // toward the sun (normalised here)
    Vec3 sunRadiance{1, 1, 1};             // colour * intensity
    double extinction = 1e-4;              // sigma_air, per metre
    double g = 0.7;                        // the haze's Henyey-Greenstein eccentricity, |g| < 1
    double cloudSigma = 0;                 // the clouds' extinction per metre at q = 1 (shade.sigma)
    bool tiling = false;                   // the cloud field periodic in x and y (grid.tiling)
    double stepVoxels = 0.25;              // the composite rule's step, voxel edges
    int threads = 0;                       // 0 = every hardware thread
};

struct HazeReferenceResult {
    std::vector<float> image;  // (3, width, height): index c + 3 * (x + width * y), row 0 at the top
    uint64_t samples = 0;      // nodes of the composite rule
    uint64_t lightRays = 0;    // exact sun rays (one per node)
    double seconds = 0;        // the whole render, the tracer's build included
};

// qAlpha: canonical (SPEC 0 order), grid.Count() values.
Result<HazeReferenceResult> RenderHazeReference(const HazeReferenceParams& params, const Extent3& grid,
                                                std::span<const float> qAlpha);

}  // namespace cb::ref
