#include "core/pipeline/Ellipsoids.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/math/Keyframes.h"

namespace cb {

double Ellipsoid::ShrinkFactor(uint32_t shrinkSteps) const {
    // In 64 bits: shrink_steps may be up to 2^32 - 1, and age + shrinkSteps must not wrap.
    if (shrinkSteps == 0 || uint64_t(age) + shrinkSteps <= lifetime) return 1.0;
    uint32_t left = lifetime > age ? lifetime - age : 0;
    return double(left) / double(shrinkSteps);
}

std::array<double, 3> PlacedCenterAt(const PlacedEllipsoid& placed, uint32_t step) {
    if (placed.keyframes.empty()) return placed.center;
    return KeyframesAt(placed.keyframes, step, [](const PlacedKeyframe& k) { return k.center; });
}

std::optional<Ellipsoid> PlacedAt(const PlacedEllipsoid& placed, uint32_t step) {
    if (step < placed.start) return std::nullopt;
    const uint32_t age = step - placed.start;
    if (placed.lifetime && age >= *placed.lifetime) return std::nullopt;
    Ellipsoid e{};
    const std::array<double, 3> center = PlacedCenterAt(placed, step);
    for (int axis = 0; axis < 3; ++axis) {
        e.center[axis] = center[axis];
        e.semiAxes[axis] = placed.semiAxes[axis];
    }
    e.yaw = placed.yawDeg * (std::numbers::pi / 180.0);
    e.age = age;
    // Persistent: the largest lifetime; Raster() never shrinks it.
    e.lifetime = placed.lifetime.value_or(UINT32_MAX);
    return e;
}

EllipsoidList::EllipsoidList(const EllipsoidSettings& settings, const Extent3& grid)
    : mSettings(settings), mGrid(grid), mRng(settings.seed) {
    mItems.reserve(settings.targetCount + settings.densityAdaption);
    for (uint32_t n = 0; n < settings.targetCount; ++n) mItems.push_back(Spawn(/*randomAge=*/true));
}

Ellipsoid EllipsoidList::Spawn(bool randomAge) {
    const EllipsoidSettings& s = mSettings;
    const double m = s.margin;
    Ellipsoid e{};
    e.center[0] = mRng.Uniform(-m, mGrid.nx + m);
    e.center[1] = mRng.Uniform(-m, mGrid.ny + m);
    e.center[2] = mRng.Uniform(s.heightRange[0], s.heightRange[1]) * mGrid.nz;
    for (int axis = 0; axis < 3; ++axis) {
        double size = mRng.Uniform(s.sizeMean[axis] - s.sizeVariance[axis], s.sizeMean[axis] + s.sizeVariance[axis]);
        e.semiAxes[axis] = std::max(size, 0.5);
    }
    e.yaw = mRng.Uniform(0.0, 2.0 * std::numbers::pi);
    double life = mRng.Uniform(s.lifetimeMean - s.lifetimeVariance, s.lifetimeMean + s.lifetimeVariance);
    // Clamped before the cast: lifetime_mean has no upper bound, and a double beyond uint32 is undefined to convert.
    e.lifetime = static_cast<uint32_t>(std::clamp(std::round(life), 1.0, double(UINT32_MAX)));
    e.age = randomAge ? mRng.Below(e.lifetime) : 0;
    return e;
}

bool EllipsoidList::InsideBounds(const Ellipsoid& e) const {
    const double m = mSettings.margin;
    return e.center[0] >= -m && e.center[0] <= mGrid.nx + m && e.center[1] >= -m && e.center[1] <= mGrid.ny + m;
}

std::array<double, 2> EllipsoidList::WindAt(double x, double y) const {
    const EllipsoidWind& w = mSettings.wind;
    if (w.gridNx == 0) return w.vector;
    // The grid's cell centres span the region bounds [-m, n+m] evenly.
    const double m = mSettings.margin;
    auto cell = [](double pos, double lo, double hi, uint32_t cells) {
        double t = (pos - lo) / (hi - lo) * cells - 0.5;
        return std::clamp(t, 0.0, double(cells - 1));
    };
    double gx = cell(x, -m, mGrid.nx + m, w.gridNx);
    double gy = cell(y, -m, mGrid.ny + m, w.gridNy);
    uint32_t x0 = static_cast<uint32_t>(gx), y0 = static_cast<uint32_t>(gy);
    uint32_t x1 = std::min(x0 + 1, w.gridNx - 1), y1 = std::min(y0 + 1, w.gridNy - 1);
    double fx = gx - x0, fy = gy - y0;
    std::array<double, 2> out{};
    for (int c = 0; c < 2; ++c) {
        double a = w.grid[x0 + w.gridNx * y0][c] * (1 - fx) + w.grid[x1 + w.gridNx * y0][c] * fx;
        double b = w.grid[x0 + w.gridNx * y1][c] * (1 - fx) + w.grid[x1 + w.gridNx * y1][c] * fx;
        out[c] = a * (1 - fy) + b * fy;
    }
    return out;
}

void EllipsoidList::Update() {
    const EllipsoidSettings& s = mSettings;
    if (mListStep < UINT32_MAX) ++mListStep;
    for (Ellipsoid& e : mItems) {
        std::array<double, 2> wind = WindAt(e.center[0], e.center[1]);
        e.center[0] += wind[0] + mRng.Uniform(-s.jitter, s.jitter);
        e.center[1] += wind[1] + mRng.Uniform(-s.jitter, s.jitter);
        e.age += 1;
    }
    std::erase_if(mItems, [&](const Ellipsoid& e) { return e.age >= e.lifetime || !InsideBounds(e); });

    uint32_t count = static_cast<uint32_t>(mItems.size());
    if (count < s.targetCount) {
        uint32_t add = std::min(s.densityAdaption, s.targetCount - count);
        for (uint32_t n = 0; n < add; ++n) mItems.push_back(Spawn(/*randomAge=*/false));
    } else if (count > s.targetCount) {
        uint32_t remove = std::min(s.densityAdaption, count - s.targetCount);
        for (uint32_t n = 0; n < remove; ++n) {
            mItems.erase(mItems.begin() + mRng.Below(static_cast<uint32_t>(mItems.size())));
        }
    }
}

std::vector<RasterEllipsoid> EllipsoidList::Raster() const {
    std::vector<RasterEllipsoid> out;
    out.reserve(mItems.size() + mSettings.placed.size());
    auto add = [&](const Ellipsoid& e, double shrink) {
        if (shrink <= 0.0) return;
        RasterEllipsoid r{};
        for (int axis = 0; axis < 3; ++axis) {
            r.center[axis] = static_cast<float>(e.center[axis]);
            r.semiAxes[axis] = static_cast<float>(std::max(e.semiAxes[axis] * shrink, 1e-3));
        }
        r.cosYaw = static_cast<float>(std::cos(e.yaw));
        r.sinYaw = static_cast<float>(std::sin(e.yaw));
        out.push_back(r);
    };
    for (const Ellipsoid& e : mItems) add(e, e.ShrinkFactor(mSettings.shrinkSteps));
    for (const PlacedEllipsoid& placed : mSettings.placed) {
        const std::optional<Ellipsoid> e = PlacedAt(placed, mListStep);
        if (!e) continue;
        add(*e, placed.lifetime ? e->ShrinkFactor(mSettings.shrinkSteps) : 1.0);
    }
    return out;
}

}  // namespace cb
