// The exact attenuation reference (SPEC 11). Density is piecewise constant:
// voxel (i,j,k) fills [i,i+1]x[j,j+1]x[k,k+1] (voxel units) with q(i,j,k). The
// optical depth along a ray is then exactly sigma h sum_v q_v l_v, with l_v the
// ray's length inside voxel v in voxel units. OpticalDepthTracer computes that
// sum with Embree 3: each run of occupied voxels along x is one user-geometry
// box; its intersect callback clips the ray to the run and to each voxel of it,
// adds q l to the ray's own accumulator and never reports a hit, so traversal
// visits every run the ray crosses, each once (docs/accuracy.md says why).
//
// From it: T_ref at voxel centres toward the sun and G_ref at ground cells.
// These are accuracy references for the fast stages, not pass/fail gates.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/base/Error.h"
#include "core/math/Grid.h"
#include "core/math/Shading.h"

namespace cb::ref {

// Where a voxel's reference ray starts to count optical depth (docs/accuracy.md).
enum class RayStart : uint8_t {
    // Where the ray from the centre leaves the voxel: the light that reaches
    // the voxel before its own extinction. This is what shade's T means (its
    // slice m is lit by slices m' < m only), so it is the default.
    VoxelExit,
    // At the voxel centre: includes half of the voxel's own path.
    VoxelCentre,
};

const char* RayStartName(RayStart start);

struct ReferenceParams {
    Vec3 sun{0, 0, 1};      // unit vector toward the sun (the float s every stage uses)
    double sigma = 0.02;    // extinction at q = 1, 1/m
    double voxelSize = 50;  // h, metres
    RayStart start = RayStart::VoxelExit;
};

// Rays traced and the wall time they took (for rays per second).
struct TraceStats {
    uint64_t rays = 0;
    double seconds = 0;
    double RaysPerSecond() const { return seconds > 0 ? double(rays) / seconds : 0.0; }
};

class OpticalDepthTracer {
  public:
    // Builds the Embree scene over the voxels of `q` (canonical float32, SPEC 0
    // order, extent.Count() values) with q > 0. `threads`: 0 = every hardware
    // thread; the build and every query batch run in a TBB arena of that size.
    static Result<std::unique_ptr<OpticalDepthTracer>> Create(const Extent3& extent, std::span<const float> q,
                                                              int threads = 0);
    ~OpticalDepthTracer();
    OpticalDepthTracer(const OpticalDepthTracer&) = delete;
    OpticalDepthTracer& operator=(const OpticalDepthTracer&) = delete;

    // sum_v q_v l_v along origin + t dir for t > tStart (origin in voxel units,
    // dir a unit vector, so l is in voxel edges). Thread-safe.
    double Integrate(const std::array<double, 3>& origin, const Vec3& dir, double tStart) const;

    // T_ref(v) = exp(-sigma h tau(v)) for every voxel, tau along the ray from
    // the voxel centre toward the sun to the edge of the volume, counted from
    // params.start. Canonical order, float32. Multithreaded.
    std::vector<float> Transmittance(const ReferenceParams& params, TraceStats* stats = nullptr) const;

    // G_ref(g) for the nx x ny ground cells at z = 0 (the volume's bottom):
    // exp(-sigma h tau) through the whole volume toward the sun; 1 where
    // s_z <= 0 (no sun above the horizon: no shadow, as SPEC 7 does).
    std::vector<float> GroundShadow(const ReferenceParams& params, TraceStats* stats = nullptr) const;

    const Extent3& Extent() const { return mExtent; }
    // Boxes in the Embree scene (runs of occupied voxels along x).
    size_t Primitives() const;
    double BuildSeconds() const { return mBuildSeconds; }

  private:
    struct Impl;
    explicit OpticalDepthTracer(const Extent3& extent);

    Extent3 mExtent;
    std::unique_ptr<Impl> mImpl;
    double mBuildSeconds = 0;
};

// The parameter t at which a ray from a voxel centre along `dir` leaves the
// voxel: 0.5 / max |dir_a| (voxel units).
double VoxelExitDistance(const Vec3& dir);

}  // namespace cb::ref
