// The plan of one shade pass (SPEC 6), built once on the host and followed by
// every backend: the shaded grid (coarse at resolution f > 1), the shear-warp
// geometry, the per-slice attenuation and the order of the slices.
#pragma once

#include <cstdint>

#include "core/math/Shading.h"

namespace cb {

struct ShadeParams;
struct Extent3;

struct ShadePlan {
    int resolution = 1;               // f
    uint32_t cells[3] = {1, 1, 1};    // shaded grid: ceil(n / f) per axis
    ShearWarp geometry;               // axes u, v, w and the taps into the previous slice
    SliceAttenuation attenuation;     // for slices f h thick
    uint32_t nu = 1, nv = 1, nw = 1;  // cells along u, v, w

    // The w index of the m-th slice visited (m = 0 is nearest the sun, T = 1);
    // slice m > 0 reads slice SliceW(m - 1).
    uint32_t SliceW(uint32_t m) const { return geometry.sunAbove ? nw - 1 - m : m; }
};

// The plan for shading a grid of extent `grid` with `params`.
ShadePlan MakeShadePlan(const ShadeParams& params, const Extent3& grid);

}  // namespace cb
