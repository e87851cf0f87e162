// The exact depth of the trilinear field of q_alpha along a ray (SPEC 11), shared by the exact reference renders
// (reference/MarchReference.h, reference/HazeReference.h): TrilinearDepthTracer's integral, with `tiling` (the field
// periodic in x and y, SPEC 15) walked period by period through the slab 0 <= z <= nz.
#pragma once

#include <utility>
#include <vector>

#include "core/math/Grid.h"
#include "reference/Trilinear.h"

namespace cb::ref {

// The exact integral of q_alpha (voxel edges) along o + t u, t in [0, tEnd] (tEnd may be +infinity: to the
// volume's edge). Without tiling the tracer covers the box. With tiling it covers one period grown by a wrapped
// column on each side (voxel (i, j, k) at (i + 1, j + 1, k)), where the trilinear field over [1, n + 1] in x and y
// is the periodic field over [0, n]: the ray is clipped to the slab 0 <= z <= nz, cut where it crosses a
// period's side, and each piece integrated in its own period. The walk stops once the depth reaches `stopDepth`
// (where exp(-sigma h depth) rounds to 0 in float), or after kMaxTilePieces pieces: a light within about 0.001
// degrees of the horizon, whose path through the slab crosses that many periods, is integrated that far.
class ExactDepth {
  public:
    static constexpr int kMaxTilePieces = 1 << 16;

    // `tracer` holds TracedField(grid, q, tiling).
    ExactDepth(const TrilinearDepthTracer& tracer, const Extent3& grid, bool tiling, double stopDepth)
        : mTracer(tracer),
          mTiling(tiling),
          mN{double(grid.nx), double(grid.ny), double(grid.nz)},
          mStopDepth(stopDepth) {}

    // The integral over t in [0, tEnd].
    double Along(const Point3d& o, const Point3d& u, double tEnd) const;
    // The integral over t in [t0, t1] (0 <= t0): the tracer's own clipping without tiling, else Along from o + t0 u.
    double Between(const Point3d& o, const Point3d& u, double t0, double t1) const;

  private:
    const TrilinearDepthTracer& mTracer;
    bool mTiling;
    double mN[3];
    double mStopDepth;
};

// The field the tracer holds: q itself, or with tiling one period grown by a wrapped column on each side in x and y.
std::pair<Extent3, std::vector<float>> TracedField(const Extent3& grid, std::vector<float> q, bool tiling);

}  // namespace cb::ref
