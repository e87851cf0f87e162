// The exact optical depth of the TRILINEAR density field that the ray marcher
// samples (SPEC 10 and 11), the basis of exact reference renders.
//
// The field, x in voxel units: q(x) is the trilinear interpolation of the
// voxel-centre values q(i,j,k) at (i+1/2, j+1/2, k+1/2), taps outside the grid
// reading 0 (SPEC 0), restricted to the volume's box [0,nx]x[0,ny]x[0,nz] (zero
// outside it, which is where the marcher clips its rays). Inside one DUAL cell
// (the cube between 8 neighbouring voxel centres) the field is a product of
// three linear functions along any ray, a cubic in t, so 2-point Gauss-Legendre
// on each dual-cell segment integrates it exactly (docs/accuracy.md, "Exact
// light for ray-march references").
//
// TrilinearDepthTracer does this with Embree 3 user geometry, like
// OpticalDepthTracer (reference/Reference.h) does for piecewise-constant
// density: one box per maximal run along x of dual cells with a nonzero corner
// (clipped to the volume's box); the intersect callback clips the ray to the
// run and to each dual cell of it, integrates the cubic in double, adds it to
// the ray's own accumulator and never reports a hit, so every run is visited
// once.
#pragma once

#include <array>
#include <memory>
#include <span>
#include <vector>

#include "core/base/Error.h"
#include "core/math/Grid.h"
#include "reference/Reference.h"

namespace cb::ref {

using Point3d = std::array<double, 3>;

class TrilinearDepthTracer {
  public:
    // Builds the Embree scene over the dual cells of `q` (canonical float32,
    // SPEC 0 order, extent.Count() values) that have a nonzero corner.
    // `threads`: 0 = every hardware thread; the build and every batch run in a
    // TBB arena of that size.
    static Result<std::unique_ptr<TrilinearDepthTracer>> Create(const Extent3& extent, std::span<const float> q,
                                                                int threads = 0);
    ~TrilinearDepthTracer();
    TrilinearDepthTracer(const TrilinearDepthTracer&) = delete;
    TrilinearDepthTracer& operator=(const TrilinearDepthTracer&) = delete;

    // The integral over t in [tMin, tMax] of q(origin + t dir) dt (origin in
    // voxel units; dir a unit vector, so t is a length in voxel edges; tMax may
    // be +infinity: to the edge of the box). Computed in double. Thread-safe.
    double Integrate(const Point3d& origin, const Point3d& dir, double tMin, double tMax) const;

    // The integral of q along the segment from a to b (0 if a == b).
    double IntegrateSegment(const Point3d& a, const Point3d& b) const;

    // Batches, multithreaded. Depths are integrals of q in voxel edges (the
    // optical depth is sigma h times that); transmittances are
    // exp(-sigmaH depth) with sigmaH = sigma h (extinction at q = 1 times the
    // voxel size), rounded to float once.
    //
    // From every point along `dir` (normalised here) to the edge of the box:
    // the sun.
    std::vector<double> DepthsToward(std::span<const Point3d> points, const Point3d& dir,
                                     TraceStats* stats = nullptr) const;
    std::vector<float> TransmittanceToward(std::span<const Point3d> points, const Point3d& dir, double sigmaH,
                                           TraceStats* stats = nullptr) const;
    // From every point to `target`, stopping there: a point light.
    std::vector<double> DepthsToPoint(std::span<const Point3d> points, const Point3d& target,
                                      TraceStats* stats = nullptr) const;
    std::vector<float> TransmittanceToPoint(std::span<const Point3d> points, const Point3d& target, double sigmaH,
                                            TraceStats* stats = nullptr) const;

    // Batches trace packets of 16 rays (rtcIntersect16, the default) or
    // single rays (rtcIntersect1); the depths agree to rounding (the order in
    // which a ray's runs are summed may differ). Not to be called while a
    // batch runs.
    void UsePackets(bool on);

    const Extent3& Extent() const { return mExtent; }
    // Boxes in the Embree scene (runs of dual cells along x).
    size_t Primitives() const;
    double BuildSeconds() const { return mBuildSeconds; }

  private:
    struct Impl;
    explicit TrilinearDepthTracer(const Extent3& extent);

    Extent3 mExtent;
    std::unique_ptr<Impl> mImpl;
    double mBuildSeconds = 0;
};

}  // namespace cb::ref
