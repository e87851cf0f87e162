// The scenes shipped in scenes/ load, and have the sizes the docs promise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/math/Noise.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "harness/report/Report.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"

namespace cb {
namespace {

// Test that every shipped scene passes validation.
TEST(ScenesShipped, AllLoad) {
    size_t count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(CLOUDBENCH_SCENES_DIR)) {
        if (entry.path().extension() != ".json") continue;
        auto scene = LoadScene(entry.path().string());
        EXPECT_TRUE(scene.has_value()) << scene.error().message;
        ++count;
    }
    EXPECT_GE(count, 8u);
}

// Test that ci-small-wind is ci-small in every field but its description and the
// ellipsoids' wind: a 3x2 grid of distinct vectors, none equal to another's (or
// its own) mirror (wx, wy) -> (wy, wx); and that the grid is read x fastest: far
// outside the region the lookup clamps to a corner cell, (2, 0) = [0.8, 0.05] and
// (0, 1) = [-0.2, 0.4], where a transposed lookup (index y + 2x) reads [0.1, 0.6]
// and [0.5, -0.2].
TEST(ScenesShipped, CiSmallWindIsCiSmallWithAWindGrid) {
    auto read = [](const char* name) {
        std::ifstream in(std::string(CLOUDBENCH_SCENES_DIR) + "/" + name);
        return nlohmann::json::parse(in);
    };
    nlohmann::json wind = read("ci-small-wind.json"), small = read("ci-small.json");
    EXPECT_EQ(wind["ellipsoids"]["wind"]["grid"], nlohmann::json({3, 2}));
    for (nlohmann::json* doc : {&wind, &small}) {
        doc->erase("description");
        (*doc)["ellipsoids"].erase("wind");
    }
    EXPECT_EQ(wind, small);
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small-wind.json");
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const EllipsoidWind& w = scene->ellipsoids.wind;
    ASSERT_EQ(w.gridNx, 3u);
    ASSERT_EQ(w.gridNy, 2u);
    ASSERT_EQ(w.grid.size(), 6u);
    for (size_t i = 0; i < 6; ++i)
        for (size_t j = 0; j < 6; ++j) {
            if (i != j) {
                EXPECT_NE(w.grid[i], w.grid[j]) << i << " " << j;
            }
            EXPECT_NE(w.grid[i], (std::array<double, 2>{w.grid[j][1], w.grid[j][0]})) << i << " " << j;
        }
    const EllipsoidList list(scene->ellipsoids, scene->grid.size);
    EXPECT_EQ(list.WindAt(1e4, -1e4), (std::array<double, 2>{0.8, 0.05}));
    EXPECT_EQ(list.WindAt(-1e4, 1e4), (std::array<double, 2>{-0.2, 0.4}));
    EXPECT_EQ(list.WindAt(1e4, 1e4), (std::array<double, 2>{0.4, -0.5}));
}

// Test that the thesis scenes use the thesis's 256x32x256 volume (32 slices high, so
// nx = ny = 256, nz = 32 with z up) and ci-small stays small.
TEST(ScenesShipped, Sizes) {
    for (const char* name : {"thesis-low", "thesis-medium", "thesis-high"}) {
        auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + name + ".json");
        ASSERT_TRUE(scene.has_value()) << scene.error().message;
        EXPECT_EQ(scene->grid.size, (Extent3{256, 256, 32})) << name;
        EXPECT_EQ(scene->name, name);
    }
    auto small = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json");
    ASSERT_TRUE(small.has_value()) << small.error().message;
    EXPECT_LE(small->grid.size.Count(), 100000u);
}

// Test that the thesis scenes reach the thesis's cover bands (Fizimayer's thesis, section
// 8.1: low 15-20 %, medium about 40 %, high over 70 %), as the median cover of
// the steps after warm-up, with the scenes' own seeds and step counts.
TEST(ScenesShipped, ThesisCoverInBands) {
    struct Band {
        const char* name;
        double lo, hi;
    };
    for (Band band :
         {Band{"thesis-low", 0.15, 0.20}, Band{"thesis-medium", 0.35, 0.45}, Band{"thesis-high", 0.70, 1.0}}) {
        // Cover needs only the simulation stages; lighting and rendering are left out.
        auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + band.name + ".json",
                               {{"stages", R"(["region", "ca", "smooth", "density"])"}});
        ASSERT_TRUE(scene.has_value()) << scene.error().message;
        cpu::BackendCpu backend;
        auto sim = Simulation::Create(*scene, backend);
        ASSERT_TRUE(sim.has_value()) << sim.error().message;
        std::vector<double> cover;
        for (uint32_t t = 0; t < scene->steps; ++t) {
            StepRecord record;
            ASSERT_TRUE((*sim)->Step(record).has_value());
            ASSERT_TRUE(record.coveredColumns.has_value());
            if (t >= scene->warmupSteps)
                cover.push_back(double(*record.coveredColumns) / (scene->grid.size.nx * scene->grid.size.ny));
        }
        const double median = Summarize(cover).median;
        EXPECT_GE(median, band.lo) << band.name;
        EXPECT_LE(median, band.hi) << band.name;
    }
}

Scene LoadShipped(const char* name) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + name + ".json");
    EXPECT_TRUE(scene.has_value()) << name << ": " << scene.error().message;
    return scene.has_value() ? *scene : Scene{};
}

// Test that the noise-formed layer is a 128^3 volume formed by
// `noise` with a 32^3 detail volume, shaded and ray-marched at 1280x720, one camera; and that the
// track and the lightning scene use the same clouds.
TEST(ScenesShipped, NoiseLayerSizes) {
    const Scene layer = LoadShipped("noise-layer");
    EXPECT_EQ(layer.grid.size, (Extent3{128, 128, 128}));
    EXPECT_TRUE(layer.noise.detail.enabled);
    EXPECT_EQ(layer.noise.detail.size, 32u);
    for (Stage s : {Stage::Noise, Stage::Shade, Stage::RenderMarch}) EXPECT_TRUE(layer.stages.Has(s));
    EXPECT_EQ(layer.render.width, 1280u);
    EXPECT_EQ(layer.render.height, 720u);
    EXPECT_EQ(layer.render.cameras.size(), 1u);
    for (const char* name : {"noise-track", "lightning"}) {
        const Scene other = LoadShipped(name);
        EXPECT_EQ(other.grid.size, layer.grid.size) << name;
        EXPECT_TRUE(other.noise == layer.noise) << name;
    }
    const Scene track = LoadShipped("noise-track");
    EXPECT_EQ(track.render.width, 1280u);
    EXPECT_EQ(track.render.height, 720u);
}

// Test that the noise track passes below, inside and above the clouds (Olajos's test track): by
// brute force over the formed q, some camera's eye lies below every cloudy voxel, some eye sits in
// a voxel with q > 0, and some eye lies above every cloudy voxel.
TEST(ScenesShipped, NoiseTrackBelowInsideAbove) {
    const Scene track = LoadShipped("noise-track");
    ASSERT_GE(track.render.cameras.size(), 6u);
    const Extent3 n = track.grid.size;
    const double h = track.grid.voxelSize;
    noise::NoiseForm form(track.noise, n);
    const noise::StepOffsets offsets = form.Offsets(0);
    auto sliceHasCloud = [&](uint32_t k) {
        for (uint32_t j = 0; j < n.ny; ++j)
            for (uint32_t i = 0; i < n.nx; ++i)
                if (form.Q(offsets, i, j, k) > 0.0f) return true;
        return false;
    };
    auto slice = [&](double z) { return int64_t(std::floor(z / h)); };
    bool below = false, inside = false, above = false;
    for (const CameraSettings& cam : track.render.cameras) {
        const int64_t k = slice(cam.eye[2]);
        const int64_t i = int64_t(std::floor(cam.eye[0] / h)), j = int64_t(std::floor(cam.eye[1] / h));
        if (k >= 0 && k < int64_t(n.nz) && i >= 0 && i < int64_t(n.nx) && j >= 0 && j < int64_t(n.ny) &&
            form.Q(offsets, uint32_t(i), uint32_t(j), uint32_t(k)) > 0.0f)
            inside = true;
        if (!below && k >= 0 && k < int64_t(n.nz) / 4) {  // a low eye: no cloud in its slice or under it
            bool clear = true;
            for (int64_t kk = 0; kk <= k && clear; ++kk) clear = !sliceHasCloud(uint32_t(kk));
            below = clear;
        }
        if (!above && k >= int64_t(n.nz) / 4 && k < int64_t(n.nz)) {  // a high eye: no cloud in its slice or over it
            bool clear = true;
            for (int64_t kk = k; kk < int64_t(n.nz) && clear; ++kk) clear = !sliceHasCloud(uint32_t(kk));
            above = clear;
        }
    }
    EXPECT_TRUE(below);
    EXPECT_TRUE(inside);
    EXPECT_TRUE(above);
}

// Test that the lightning scene flashes inside its run, after warm-up and before the last step,
// and renders every step, so frames before, during and after the flash exist.
TEST(ScenesShipped, LightningFlashInsideRun) {
    const Scene scene = LoadShipped("lightning");
    const LightningSettings& l = scene.lightning;
    EXPECT_TRUE(l.enabled);
    EXPECT_TRUE(scene.stages.Has(Stage::RenderMarch));
    EXPECT_GT(l.flashStart, scene.warmupSteps);
    EXPECT_LT(uint64_t(l.flashStart) + l.flashSteps, uint64_t(scene.steps));
    EXPECT_EQ(scene.render.everySteps, 1u);
    EXPECT_FALSE(l.OnAt(l.flashStart - 1));
    EXPECT_TRUE(l.OnAt(l.flashStart));
    EXPECT_FALSE(l.OnAt(scene.steps - 1));
}

// Test that thesis-medium-both is thesis-medium plus the ray marcher: the same grid, automaton,
// steps and cameras, and the stages of thesis-medium with render_march added.
TEST(ScenesShipped, ThesisMediumBothIsThesisMediumPlusMarch) {
    const Scene medium = LoadShipped("thesis-medium");
    const Scene both = LoadShipped("thesis-medium-both");
    EXPECT_EQ(both.grid.size, medium.grid.size);
    EXPECT_EQ(both.steps, medium.steps);
    EXPECT_EQ(both.warmupSteps, medium.warmupSteps);
    EXPECT_EQ(both.ca.seed, medium.ca.seed);
    EXPECT_EQ(both.render.width, medium.render.width);
    EXPECT_EQ(both.render.height, medium.render.height);
    ASSERT_EQ(both.render.cameras.size(), medium.render.cameras.size());
    for (size_t c = 0; c < both.render.cameras.size(); ++c)
        EXPECT_EQ(both.render.cameras[c].eye, medium.render.cameras[c].eye);
    EXPECT_FALSE(medium.stages.Has(Stage::RenderMarch));
    EXPECT_TRUE(both.stages.Has(Stage::RenderMarch));
    EXPECT_TRUE(both.stages.Has(Stage::RenderSplat));
}

}  // namespace
}  // namespace cb
