// Scene loading: defaults, every field, and scene files. The refusals are in
// SceneErrorsTest.cpp, the --set overrides in SceneOverridesTest.cpp.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "SceneTestUtil.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"

namespace cb {
namespace {

using test::ErrorOf;
using test::HasLine;
using test::kMinimal;
using test::Parsed;
using test::Stages;

// ---- Accepted scenes -----------------------------------------------------------------------------------------

// Test that a scene with only grid.size gets every documented default.
TEST(SceneTest, MinimalSceneGetsDefaults) {
    Scene scene = Parsed(kMinimal);
    EXPECT_EQ(scene.name, "test");
    EXPECT_EQ(scene.grid.size, (Extent3{8, 4, 6}));
    EXPECT_EQ(scene.grid.voxelSize, 50.0);
    EXPECT_EQ(scene.grid.origin, (std::array<double, 3>{0, 0, 0}));
    EXPECT_EQ(scene.steps, 20u);
    EXPECT_EQ(scene.warmupSteps, 0u);
    EXPECT_EQ(scene.stages, Stages({Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density}));
    EXPECT_EQ(scene.ca.seed, 1u);
    EXPECT_EQ(scene.ca.hum0, 0.35);
    EXPECT_EQ(scene.ca.act0, 0.001);
    EXPECT_EQ(scene.ca.pExt, 0.1);
    EXPECT_EQ(scene.ca.pHum, 0.1);
    EXPECT_EQ(scene.ca.pAct, 0.001);
    EXPECT_TRUE(scene.ca.windShift.empty());
    EXPECT_EQ(scene.ellipsoids.seed, 1u);
    EXPECT_EQ(scene.ellipsoids.targetCount, 40u);
    EXPECT_EQ(scene.ellipsoids.densityAdaption, 2u);
    EXPECT_EQ(scene.ellipsoids.sizeMean, (std::array<double, 3>{16, 16, 8}));
    EXPECT_EQ(scene.ellipsoids.sizeVariance, (std::array<double, 3>{4, 4, 2}));
    EXPECT_EQ(scene.ellipsoids.lifetimeMean, 400.0);
    EXPECT_EQ(scene.ellipsoids.lifetimeVariance, 100.0);
    EXPECT_EQ(scene.ellipsoids.shrinkSteps, 40u);
    EXPECT_EQ(scene.ellipsoids.margin, 16.0);
    EXPECT_EQ(scene.ellipsoids.heightRange, (std::array<double, 2>{0.25, 0.5}));
    EXPECT_EQ(scene.ellipsoids.wind.vector, (std::array<double, 2>{0, 0}));
    EXPECT_EQ(scene.ellipsoids.wind.gridNx, 0u);
    EXPECT_EQ(scene.ellipsoids.jitter, 0.05);
    EXPECT_EQ(scene.smooth.radius, 1);
    EXPECT_EQ(scene.density.tile, 32u);
    EXPECT_EQ(scene.density.band, 4u);
}

// Test that the ellipsoid seed follows ca.seed when it is not given.
TEST(SceneTest, EllipsoidSeedDefaultsToCaSeed) {
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "ca": {"seed": 77}})").ellipsoids.seed, 77u);
    Scene own = Parsed(R"({"grid": {"size": [8, 4, 6]}, "ca": {"seed": 77}, "ellipsoids": {"seed": 5}})");
    EXPECT_EQ(own.ellipsoids.seed, 5u);
    EXPECT_EQ(own.ca.seed, 77u);
}

// Test that a scene giving every field lands in the right struct members, one wind_shift pair expanded to nz.
TEST(SceneTest, FullSceneParsesEveryField) {
    Scene scene = Parsed(R"({
        "name": "storm",
        "description": "every field",
        "grid": {"size": [10, 6, 4], "voxel_size": 25.5, "origin": [-100, 200.5, 3]},
        "steps": 300,
        "warmup_steps": 10,
        "stages": ["density", "smooth", "ca", "region", "shade"],
        "ca": {"seed": 4294967295, "hum0": 0.4, "act0": 0.002, "p_ext": 0.2, "p_hum": 0.3, "p_act": 0.004,
               "wind_shift": [[1, -2]]},
        "ellipsoids": {
            "seed": 9007199254740992, "target_count": 100, "density_adaption": 5,
            "size_mean": [20, 18, 9], "size_variance": [5, 6, 3], "lifetime_mean": 500,
            "lifetime_variance": 50, "shrink_steps": 30, "margin": 8.5, "height_range": [0.1, 0.9],
            "wind": {"grid": [3, 2], "vectors": [[1, 0], [2, 0], [3, 0], [0, 1], [0, 2], [0.5, -3]]},
            "jitter": 0.25
        },
        "smooth": {"radius": 2},
        "density": {"tile": 16, "band": 2}
    })");
    EXPECT_EQ(scene.name, "storm");
    EXPECT_EQ(scene.path, "");
    EXPECT_EQ(scene.grid.size, (Extent3{10, 6, 4}));
    EXPECT_EQ(scene.grid.voxelSize, 25.5);
    EXPECT_EQ(scene.grid.origin, (std::array<double, 3>{-100, 200.5, 3}));
    EXPECT_EQ(scene.steps, 300u);
    EXPECT_EQ(scene.warmupSteps, 10u);
    EXPECT_EQ(scene.stages, Stages({Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density, Stage::Shade}));
    EXPECT_EQ(scene.ca.seed, 4294967295u);
    EXPECT_EQ(scene.ca.hum0, 0.4);
    EXPECT_EQ(scene.ca.act0, 0.002);
    EXPECT_EQ(scene.ca.pExt, 0.2);
    EXPECT_EQ(scene.ca.pHum, 0.3);
    EXPECT_EQ(scene.ca.pAct, 0.004);
    ASSERT_EQ(scene.ca.windShift.size(), 4u);
    for (const SliceShift& s : scene.ca.windShift) {
        EXPECT_EQ(s.sx, 1);
        EXPECT_EQ(s.sy, -2);
    }
    EXPECT_TRUE(scene.ca.HasWind());
    const EllipsoidSettings& e = scene.ellipsoids;
    EXPECT_EQ(e.seed, uint64_t(1) << 53);
    EXPECT_EQ(e.targetCount, 100u);
    EXPECT_EQ(e.densityAdaption, 5u);
    EXPECT_EQ(e.sizeMean, (std::array<double, 3>{20, 18, 9}));
    EXPECT_EQ(e.sizeVariance, (std::array<double, 3>{5, 6, 3}));
    EXPECT_EQ(e.lifetimeMean, 500.0);
    EXPECT_EQ(e.lifetimeVariance, 50.0);
    EXPECT_EQ(e.shrinkSteps, 30u);
    EXPECT_EQ(e.margin, 8.5);
    EXPECT_EQ(e.heightRange, (std::array<double, 2>{0.1, 0.9}));
    EXPECT_EQ(e.wind.gridNx, 3u);
    EXPECT_EQ(e.wind.gridNy, 2u);
    ASSERT_EQ(e.wind.grid.size(), 6u);
    EXPECT_EQ(e.wind.grid[1], (std::array<double, 2>{2, 0}));
    EXPECT_EQ(e.wind.grid[5], (std::array<double, 2>{0.5, -3}));
    EXPECT_EQ(e.jitter, 0.25);
    EXPECT_EQ(scene.smooth.radius, 2);
    EXPECT_EQ(scene.density.tile, 16u);
    EXPECT_EQ(scene.density.band, 2u);
}

// Test that nz wind_shift pairs are kept slice by slice, and a single wind vector fills EllipsoidWind::vector.
TEST(SceneTest, PerSliceWindShiftAndWindVector) {
    Scene scene = Parsed(R"({"grid": {"size": [8, 4, 3]}, "ca": {"wind_shift": [[0, 0], [1, 2], [-3, 4]]},
                             "ellipsoids": {"wind": [1.5, -0.25]}})");
    ASSERT_EQ(scene.ca.windShift.size(), 3u);
    EXPECT_EQ(scene.ca.windShift[0].sx, 0);
    EXPECT_EQ(scene.ca.windShift[1].sy, 2);
    EXPECT_EQ(scene.ca.windShift[2].sx, -3);
    EXPECT_EQ(scene.ca.windShift[2].sy, 4);
    EXPECT_EQ(scene.ellipsoids.wind.vector, (std::array<double, 2>{1.5, -0.25}));
    EXPECT_EQ(scene.ellipsoids.wind.gridNx, 0u);
}

// Test that a whole-number float such as 1e3 is accepted for an integer field.
TEST(SceneTest, IntegralFloatIsAnInteger) {
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "steps": 1e3})").steps, 1000u);
}

// Test that the ray-march path's stages load when their inputs are written:
// noise alone, and render_march on noise's q with a camera (a renderer needs one).
TEST(SceneTest, OtherKnownStagesNeedTheirInputs) {
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "stages": ["noise"]})").stages, Stages({Stage::Noise}));
    const std::string camera = R"("render": {"cameras": [{"eye": [0, 0, 0], "target": [1, 0, 0]}]})";
    const std::string lightMarch = R"("march": {"light": "march"})";
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, )" + camera + ", " + lightMarch +
                     R"(, "stages": ["render_march", "noise"]})")
                  .stages,
              Stages({Stage::RenderMarch, Stage::Noise}));
    // The default light source reads T from the shade stage.
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, )" + camera + R"(, "stages": ["render_march", "noise"]})"),
                        R"(test.json: march.light: "shade" needs stage "shade" (add it to stages, or set march.light to "march"))"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["render_march", "noise"]})"),
                        R"(test.json: render.cameras: "render_march" needs at least one camera)"));
}

// Test that a scene with none of the lighting sections gets every documented default for them.
TEST(SceneTest, LightingSectionsDefaults) {
    Scene scene = Parsed(kMinimal);
    EXPECT_EQ(scene.sun.elevationDeg, 40.0);
    EXPECT_EQ(scene.sun.azimuthDeg, 30.0);
    EXPECT_EQ(scene.sun.color, (std::array<double, 3>{1, 0.96, 0.9}));
    EXPECT_EQ(scene.sun.intensity, 1.0);
    EXPECT_EQ(scene.lighting.ambient, (std::array<double, 3>{0.25, 0.3, 0.38}));
    EXPECT_EQ(scene.lighting.background, (std::array<double, 3>{0.45, 0.6, 0.85}));
    EXPECT_EQ(scene.phase.kind, PhaseKind::HenyeyGreenstein);
    EXPECT_EQ(scene.phase.g, 0.6f);
    EXPECT_EQ(scene.shade.attenuation, AttenuationKind::Beer);
    EXPECT_EQ(scene.shade.sigma, 0.02);
    EXPECT_EQ(scene.shade.thesisAr, 0.9);
    EXPECT_EQ(scene.shade.filter, SampleFilter::Bilinear);
    EXPECT_EQ(scene.shade.resolution, 1);
    EXPECT_EQ(scene.shade.storage, StorageFormat::Fp32);
    EXPECT_FALSE(scene.shade.scattering);
    EXPECT_EQ(scene.shade.albedo, 0.9);
    EXPECT_EQ(scene.shade.solidAngle, 0.05);
    EXPECT_EQ(scene.shadow.form, ShadowForm::Beer);
    EXPECT_EQ(scene.shadow.coverage, 1.0);
    EXPECT_EQ(scene.shadow.densityFactor, 1.0);
    EXPECT_EQ(scene.shadow.kappa, 0.25);
    EXPECT_EQ(scene.render.width, 320u);
    EXPECT_EQ(scene.render.height, 240u);
    EXPECT_EQ(scene.splat.qMin, 0.3);
    EXPECT_EQ(scene.splat.splatScale, 1.5);
    EXPECT_EQ(scene.splat.opacity, 0.6);
    EXPECT_EQ(scene.render.alpha, 0.5);
    EXPECT_TRUE(scene.splat.culling);
    EXPECT_TRUE(scene.splat.skipping);
    EXPECT_EQ(scene.render.everySteps, 0u);
    EXPECT_TRUE(scene.render.cameras.empty());
}

// Test that a camera giving only eye and target gets the name view<index> and the other camera defaults.
TEST(SceneTest, CameraDefaults) {
    Scene scene = Parsed(R"({"grid": {"size": [8, 4, 6]}, "render": {"cameras": [
        {"name": "first", "eye": [0, 0, 0], "target": [1, 0, 0]},
        {"eye": [-10, 5, 2.5], "target": [100, 200, 0]}]}})");
    ASSERT_EQ(scene.render.cameras.size(), 2u);
    const CameraSettings& c = scene.render.cameras[1];
    EXPECT_EQ(c.name, "view1");
    EXPECT_EQ(c.eye, (std::array<double, 3>{-10, 5, 2.5}));
    EXPECT_EQ(c.target, (std::array<double, 3>{100, 200, 0}));
    EXPECT_EQ(c.up, (std::array<double, 3>{0, 0, 1}));
    EXPECT_EQ(c.fovDeg, 60.0);
    EXPECT_EQ(c.nearPlane, 1.0);
    EXPECT_EQ(c.farPlane, 100000.0);
}

// Test that a scene giving every lighting, shading and render field (two cameras) lands in the right members.
TEST(SceneTest, FullSceneParsesEveryLightingField) {
    Scene scene = Parsed(R"({
        "grid": {"size": [8, 4, 6]},
        "stages": ["region", "ca", "smooth", "density", "shade", "shadow", "render_splat"],
        "sun": {"elevation_deg": -12.5, "azimuth_deg": 400, "color": [0.5, 0, 2], "intensity": 3},
        "lighting": {"ambient": [0, 0.1, 0.2], "background": [1, 2, 3]},
        "phase": {"function": "cornette-shanks", "g": -0.25},
        "shade": {"attenuation": "thesis", "sigma": 0.5, "thesis_ar": 0.75, "filter": "nearest",
                  "resolution": 4, "storage": "unorm8",
                  "scattering": {"enabled": true, "albedo": 0.8, "solid_angle": 12.5}},
        "shadow": {"form": "thesis", "kappa": 0},
        "render": {"width": 16384, "height": 1, "q_min": 0, "splat_scale": 0.25, "opacity": 1, "alpha": 0,
                   "culling": false, "skipping": false, "every_steps": 5,
                   "cameras": [
                       {"name": "top", "eye": [200, 100, 5000], "target": [200, 100, 0], "up": [0, 1, 0],
                        "fov_deg": 179.5, "near": 0.5, "far": 20000},
                       {"name": "side", "eye": [-500, 100, 150], "target": [200, 100, 150], "up": [0, 0, 2],
                        "fov_deg": 0.5, "near": 10, "far": 10.5}]}
    })");
    EXPECT_EQ(scene.stages, Stages({Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density, Stage::Shade,
                                    Stage::Shadow, Stage::RenderSplat}));
    EXPECT_EQ(scene.sun.elevationDeg, -12.5);
    EXPECT_EQ(scene.sun.azimuthDeg, 400.0);
    EXPECT_EQ(scene.sun.color, (std::array<double, 3>{0.5, 0, 2}));
    EXPECT_EQ(scene.sun.intensity, 3.0);
    EXPECT_EQ(scene.lighting.ambient, (std::array<double, 3>{0, 0.1, 0.2}));
    EXPECT_EQ(scene.lighting.background, (std::array<double, 3>{1, 2, 3}));
    EXPECT_EQ(scene.phase.kind, PhaseKind::CornetteShanks);
    EXPECT_EQ(scene.phase.g, -0.25f);
    EXPECT_EQ(scene.shade.attenuation, AttenuationKind::Thesis);
    EXPECT_EQ(scene.shade.sigma, 0.5);
    EXPECT_EQ(scene.shade.thesisAr, 0.75);
    EXPECT_EQ(scene.shade.filter, SampleFilter::Nearest);
    EXPECT_EQ(scene.shade.resolution, 4);
    EXPECT_EQ(scene.shade.storage, StorageFormat::Unorm8);
    EXPECT_TRUE(scene.shade.scattering);
    EXPECT_EQ(scene.shade.albedo, 0.8);
    EXPECT_EQ(scene.shade.solidAngle, 12.5);
    EXPECT_EQ(scene.shadow.form, ShadowForm::Thesis);
    EXPECT_EQ(scene.shadow.kappa, 0.0);
    EXPECT_EQ(scene.render.width, 16384u);
    EXPECT_EQ(scene.render.height, 1u);
    EXPECT_EQ(scene.splat.qMin, 0.0);
    EXPECT_EQ(scene.splat.splatScale, 0.25);
    EXPECT_EQ(scene.splat.opacity, 1.0);
    EXPECT_EQ(scene.render.alpha, 0.0);
    EXPECT_FALSE(scene.splat.culling);
    EXPECT_FALSE(scene.splat.skipping);
    EXPECT_EQ(scene.render.everySteps, 5u);
    ASSERT_EQ(scene.render.cameras.size(), 2u);
    const CameraSettings& top = scene.render.cameras[0];
    EXPECT_EQ(top.name, "top");
    EXPECT_EQ(top.eye, (std::array<double, 3>{200, 100, 5000}));
    EXPECT_EQ(top.target, (std::array<double, 3>{200, 100, 0}));
    EXPECT_EQ(top.up, (std::array<double, 3>{0, 1, 0}));
    EXPECT_EQ(top.fovDeg, 179.5);
    EXPECT_EQ(top.nearPlane, 0.5);
    EXPECT_EQ(top.farPlane, 20000.0);
    const CameraSettings& side = scene.render.cameras[1];
    EXPECT_EQ(side.name, "side");
    EXPECT_EQ(side.eye, (std::array<double, 3>{-500, 100, 150}));
    EXPECT_EQ(side.target, (std::array<double, 3>{200, 100, 150}));
    EXPECT_EQ(side.up, (std::array<double, 3>{0, 0, 2}));
    EXPECT_EQ(side.fovDeg, 0.5);
    EXPECT_EQ(side.nearPlane, 10.0);
    EXPECT_EQ(side.farPlane, 10.5);
}

// Test that each choice string maps to its enum value (the ones the full scene above does not use).
TEST(SceneTest, EveryChoiceString) {
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "phase": {"function": "none"}})").phase.kind, PhaseKind::None);
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "phase": {"function": "henyey-greenstein"}})").phase.kind,
              PhaseKind::HenyeyGreenstein);
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "shade": {"storage": "fp16"}})").shade.storage,
              StorageFormat::Fp16);
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "shade": {"storage": "fp32", "attenuation": "beer",
                        "filter": "bilinear", "resolution": 2}})").shade.resolution, 2);
}

// ---- Files ---------------------------------------------------------------------------------------------------

// Test that LoadScene names the scene after the file's stem and records the path.
TEST(SceneTest, LoadSceneFromFile) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("cloudbench-scenetest-" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "ci-small.json").string();
    std::ofstream(path) << kMinimal;

    Result<Scene> scene = LoadScene(path, {{"steps", "7"}});
    std::filesystem::remove_all(dir);
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_EQ(scene->name, "ci-small");
    EXPECT_EQ(scene->path, path);
    EXPECT_EQ(scene->steps, 7u);
}

// Test that a file that cannot be opened is reported with the system's reason.
TEST(SceneTest, LoadSceneMissingFile) {
    Result<Scene> scene = LoadScene("/nonexistent-cloudbench/none.json");
    ASSERT_FALSE(scene);
    EXPECT_EQ(scene.error().message,
              std::string("/nonexistent-cloudbench/none.json: cannot read the file: ") + std::strerror(ENOENT));
}

}  // namespace
}  // namespace cb
