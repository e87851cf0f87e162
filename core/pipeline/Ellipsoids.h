// The host-side ellipsoid list (SPEC 2, docs/contract.md; Fizimayer's thesis, section 4.3.3.5),
// with the scene's placed ellipsoids beside it (SPEC 17).
// It is updated once per step on the host, identically for every backend; the
// backends only rasterise its RasterEllipsoid form.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
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

// A placed ellipsoid's centre at list step `step`: linear between its keyframes, held before the
// first and after the last; its `center` when it has none.
std::array<double, 3> PlacedCenterAt(const PlacedEllipsoid& placed, uint32_t step);

// A placed ellipsoid as the list holds it at list step `step` (centre from its keyframes, yaw in
// radians, age step - start), or nothing when it is not alive then.
std::optional<Ellipsoid> PlacedAt(const PlacedEllipsoid& placed, uint32_t step);

class EllipsoidList {
  public:
    // Starts at the steady state: targetCount ellipsoids with ages spread
    // uniformly over their lifetimes, so that they do not all die together.
    EllipsoidList(const EllipsoidSettings& settings, const Extent3& grid);

    // One simulation step: move by wind + jitter, age, remove the dead and the
    // departed, then add (or remove) at most densityAdaption towards the target;
    // the list step advances by one (the placed ellipsoids follow it).
    void Update();

    // The random ellipsoids (the placed ones are the scene's, at ListStep()).
    const std::vector<Ellipsoid>& Items() const { return mItems; }
    // The generator of births, removals and jitter.
    const Pcg32& Rng() const { return mRng; }
    // Updates so far: the step the placed ellipsoids are at. With Items() and Rng(), the list's whole state.
    uint32_t ListStep() const { return mListStep; }
    // Puts back a state that Items(), Rng() and ListStep() gave (a saved run, harness/run/SimulationState.h).
    void Restore(std::vector<Ellipsoid> items, const Pcg32& rng, uint32_t listStep = 0) {
        mItems = std::move(items);
        mRng = rng;
        mListStep = listStep;
    }

    // What the backends rasterise: the random ellipsoids, then the placed ones alive at ListStep(), with
    // shrunk semi-axes and cos/sin of the yaw.
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
    uint32_t mListStep = 0;
};

}  // namespace cb
