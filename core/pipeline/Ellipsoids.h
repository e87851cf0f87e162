// The host-side ellipsoid list (SPEC 2, docs/contract.md; Fizimayer's thesis, section 4.3.3.5).
// It is updated once per step on the host, identically for every backend; the
// backends only rasterise its RasterEllipsoid form.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/math/Random.h"
#include "core/math/Rules.h"
#include "core/scene/Scene.h"

namespace cb {

struct Ellipsoid {
    double center[3];    // voxel units
    double semiAxes[3];  // full-size semi-axes, voxels
    double yaw;          // radians about z
    uint32_t age;        // steps lived
    uint32_t lifetime;   // steps; removed when age reaches it

    // Linear shrink over the last `shrinkSteps` of life: 1 before, -> 0 at death.
    double ShrinkFactor(uint32_t shrinkSteps) const;
};

class EllipsoidList {
  public:
    // Starts at the steady state: targetCount ellipsoids with ages spread
    // uniformly over their lifetimes, so that they do not all die together.
    EllipsoidList(const EllipsoidSettings& settings, const Extent3& grid);

    // One simulation step: move by wind + jitter, age, remove the dead and the
    // departed, then add (or remove) at most densityAdaption towards the target.
    void Update();

    const std::vector<Ellipsoid>& Items() const { return mItems; }
    // The generator of births, removals and jitter; with Items(), the list's whole state.
    const Pcg32& Rng() const { return mRng; }
    // Puts back a state that Items() and Rng() gave (a saved run, harness/run/SimulationState.h).
    void Restore(std::vector<Ellipsoid> items, const Pcg32& rng) {
        mItems = std::move(items);
        mRng = rng;
    }

    // What the backends rasterise: shrunk semi-axes, cos/sin of the yaw.
    std::vector<RasterEllipsoid> Raster() const;

    // Wind at a horizontal position (voxel units), bilinear in the wind grid.
    std::array<double, 2> WindAt(double x, double y) const;

  private:
    Ellipsoid Spawn(bool randomAge);
    bool InsideBounds(const Ellipsoid& e) const;

    EllipsoidSettings mSettings;
    Extent3 mGrid;
    Pcg32 mRng;
    std::vector<Ellipsoid> mItems;
};

}  // namespace cb
