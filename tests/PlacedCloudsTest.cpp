// Placed clouds in a run (SPEC 17): scenes/placed-shapes.json's shapes fill with cloud while they live and
// clear when they die, the simulation's region combines random and placed ellipsoids by the maximum (SPEC 2),
// and the scene file's placed section reads back as written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "core/math/Rules.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/plan/SceneLoad.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/RegionReference.h"

namespace cb {
namespace {

// Steps after its start by which a shape of placed-shapes must be full (docs/scenes.md, "placed-shapes").
constexpr uint32_t kPcBuildSteps = 8;

Scene PcLoadPlacedShapes() {
    // Only the automaton: the test reads the cloud field and the region.
    auto scene =
        LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/placed-shapes.json", {{"stages", R"(["region", "ca"])"}});
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    return scene ? *scene : Scene{};
}

// rho of a voxel centre against a placed ellipsoid at its full size, in double (independent of the raster's floats).
double PcRho(const Ellipsoid& e, uint32_t i, uint32_t j, uint32_t k) {
    const double ox = i + 0.5 - e.center[0], oy = j + 0.5 - e.center[1], dz = k + 0.5 - e.center[2];
    const double c = std::cos(e.yaw), s = std::sin(e.yaw);
    const double dx = c * ox + s * oy, dy = -s * ox + c * oy;
    return std::sqrt((dx / e.semiAxes[0]) * (dx / e.semiAxes[0]) + (dy / e.semiAxes[1]) * (dy / e.semiAxes[1]) +
                     (dz / e.semiAxes[2]) * (dz / e.semiAxes[2]));
}

// Test the scene's placed section as the file writes it: names, keyframes, yaw, start, lifetime or persistent.
TEST(PlacedClouds, SceneReadsItsShapes) {
    const Scene scene = PcLoadPlacedShapes();
    const std::vector<PlacedEllipsoid>& placed = scene.ellipsoids.placed;
    ASSERT_EQ(placed.size(), 3u);
    EXPECT_EQ(placed[0].name, "tower");
    EXPECT_FALSE(placed[0].lifetime.has_value());
    ASSERT_EQ(placed[0].keyframes.size(), 2u);
    EXPECT_EQ(placed[0].keyframes[1].step, 60u);
    EXPECT_EQ(placed[0].keyframes[1].center, (std::array<double, 3>{58, 38, 11}));
    EXPECT_EQ(placed[1].name, "ridge");
    EXPECT_EQ(placed[1].yawDeg, 30.0);
    EXPECT_EQ(placed[1].start, 5u);
    EXPECT_EQ(placed[1].lifetime, std::optional<uint32_t>(55));
    EXPECT_TRUE(placed[1].keyframes.empty());
    EXPECT_EQ(placed[2].name, "puff");
    EXPECT_EQ(placed[2].start, 25u);
    EXPECT_EQ(placed[2].lifetime, std::optional<uint32_t>(40));
}

// Cover of one shape at one step: the cloudy share of its core (rho <= 1/2 at its full size, where no random
// ellipsoid reaches) and of every voxel outside all the placed ellipsoids alive then.
struct PcCover {
    double core = 0, outside = 0;
    size_t coreVoxels = 0;
};

PcCover PcCoverOf(const Scene& scene, const std::vector<uint8_t>& cld, const Ellipsoid& shape, uint32_t listStep,
                  const std::vector<RasterEllipsoid>& random) {
    const Extent3 n = scene.grid.size;
    std::vector<Ellipsoid> alive;
    for (const PlacedEllipsoid& p : scene.ellipsoids.placed)
        if (auto e = PlacedAt(p, listStep)) alive.push_back(*e);
    size_t core = 0, coreCloud = 0, outside = 0, outsideCloud = 0;
    for (uint32_t k = 0; k < n.nz; ++k)
        for (uint32_t j = 0; j < n.ny; ++j)
            for (uint32_t i = 0; i < n.nx; ++i) {
                const bool cloud = cld[VoxelIndex(n, i, j, k)] != 0;
                if (PcRho(shape, i, j, k) <= 0.5) {
                    const bool randomReaches = std::any_of(random.begin(), random.end(), [&](const RasterEllipsoid& r) {
                        return EllipsoidWeight(r, i + 0.5f, j + 0.5f, k + 0.5f) > 0.0f;
                    });
                    if (!randomReaches) {
                        ++core;
                        coreCloud += cloud;
                    }
                }
                const bool inAny = std::any_of(alive.begin(), alive.end(),
                                               [&](const Ellipsoid& e) { return PcRho(e, i, j, k) <= 1.0; });
                if (!inAny) {
                    ++outside;
                    outsideCloud += cloud;
                }
            }
    PcCover c;
    c.coreVoxels = core;
    c.core = core ? double(coreCloud) / double(core) : 0;
    c.outside = outside ? double(outsideCloud) / double(outside) : 0;
    return c;
}

// Test that each shape of placed-shapes fills with cloud and clears again (SPEC 17): from kPcBuildSteps after its
// start until its shrink begins, at least 70 % of its core is cloud and its core's cover is at least four times the
// cover outside every placed ellipsoid; at its start its core holds at most 20 %; at the first step it no longer
// lives (no region is left there, SPEC 3's cld AND R > 0) none. Step t's cloud field is the automaton's output
// from R_t, which list step t's ellipsoids made (docs/pipeline.md).
TEST(PlacedClouds, EachShapeFillsWhileItLivesAndClearsAfter) {
    const Scene scene = PcLoadPlacedShapes();
    cpu::BackendCpu backend;
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    EllipsoidSettings randomOnly = scene.ellipsoids;
    randomOnly.placed.clear();
    EllipsoidList random(randomOnly, scene.grid.size);
    std::vector<size_t> fullSteps(scene.ellipsoids.placed.size(), 0);
    // Per shape over its full-size steps: the least core cover and the most cover outside (printed for the docs).
    std::vector<double> leastCore(fullSteps.size(), 1.0), mostOutside(fullSteps.size(), 0.0);
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord record;
        ASSERT_TRUE((*sim)->Step(record).has_value());
        const std::vector<RasterEllipsoid> randomRaster = random.Raster();
        random.Update();
        std::vector<uint8_t> cld((*sim)->Cld()->CanonicalBytes());
        ASSERT_TRUE(backend.Download(*(*sim)->Cld(), std::as_writable_bytes(std::span(cld))).has_value());
        for (size_t n = 0; n < scene.ellipsoids.placed.size(); ++n) {
            const PlacedEllipsoid& p = scene.ellipsoids.placed[n];
            const uint32_t death = p.lifetime ? p.start + *p.lifetime : UINT32_MAX;
            const uint32_t shrinkFrom = p.lifetime ? death - scene.ellipsoids.shrinkSteps : UINT32_MAX;
            // Where the shape is (or, once dead, was last).
            const std::optional<Ellipsoid> shape = PlacedAt(p, std::min(t, death - 1));
            if (!shape || t < p.start) continue;
            const PcCover c = PcCoverOf(scene, cld, *shape, t, randomRaster);
            SCOPED_TRACE(p.name + " at step " + std::to_string(t) + ": core " + std::to_string(c.core) + " of " +
                         std::to_string(c.coreVoxels) + " voxels, outside " + std::to_string(c.outside));
            ASSERT_GT(c.coreVoxels, 50u);
            if (t == p.start) EXPECT_LE(c.core, 0.2);
            if (t >= p.start + kPcBuildSteps && t < shrinkFrom) {
                EXPECT_GE(c.core, 0.7);
                EXPECT_GE(c.core, 4 * c.outside);
                ++fullSteps[n];
                leastCore[n] = std::min(leastCore[n], c.core);
                mostOutside[n] = std::max(mostOutside[n], c.outside);
            }
            if (t == death) EXPECT_EQ(c.core, 0.0);
        }
    }
    for (size_t n = 0; n < fullSteps.size(); ++n) {
        EXPECT_GE(fullSteps[n], 10u) << scene.ellipsoids.placed[n].name << ": the test needs steps at full size";
        std::printf("%s: %zu full-size steps, core cover at least %.3f, outside at most %.3f\n",
                    scene.ellipsoids.placed[n].name.c_str(), fullSteps[n], leastCore[n], mostOutside[n]);
    }
}

// Test SPEC 2's combination in the run: the simulation's region at each step is, voxel by voxel, the larger of the
// brute-force regions of the random ellipsoids and of the placed ones it was made from.
TEST(PlacedClouds, RunRegionIsTheMaximumOverRandomAndPlaced) {
    const Scene scene = PcLoadPlacedShapes();
    const Extent3 n = scene.grid.size;
    cpu::BackendCpu backend;
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    EllipsoidSettings randomOnly = scene.ellipsoids, placedOnly = scene.ellipsoids;
    randomOnly.placed.clear();
    placedOnly.targetCount = 0;
    EllipsoidList random(randomOnly, n), placed(placedOnly, n);
    for (uint32_t t = 0; t < 30; ++t) {
        StepRecord record;
        ASSERT_TRUE((*sim)->Step(record).has_value());
        if (t % 5 == 0) {
            std::vector<uint8_t> region((*sim)->Region()->CanonicalBytes());
            ASSERT_TRUE(backend.Download(*(*sim)->Region(), std::as_writable_bytes(std::span(region))).has_value());
            const std::vector<uint8_t> r = test::BruteForceRegion(n, random.Raster());
            const std::vector<uint8_t> p = test::BruteForceRegion(n, placed.Raster());
            for (size_t v = 0; v < region.size(); ++v)
                ASSERT_EQ(region[v], std::max(r[v], p[v])) << "step " << t << ", voxel " << v;
            EXPECT_GT(std::count_if(p.begin(), p.end(), [](uint8_t x) { return x > 0; }), 1000) << "step " << t;
        }
        random.Update();
        placed.Update();
    }
}

}  // namespace
}  // namespace cb
