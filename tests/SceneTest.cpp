// Scene loading: defaults, every field, every kind of refusal and the --set overrides.
#include "core/Scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace cb {
namespace {

constexpr const char* kLabel = "test.json";

std::vector<std::string> SplitLines(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream stream(text);
    for (std::string line; std::getline(stream, line);) lines.push_back(line);
    return lines;
}

// The error message of a scene that must be refused ("" and a failure when it was accepted).
std::string ErrorOf(const std::string& text, const std::vector<SceneOverride>& overrides = {}) {
    Result<Scene> scene = ParseScene(text, kLabel, overrides);
    if (scene) {
        ADD_FAILURE() << "the scene was accepted:\n" << text;
        return "";
    }
    return scene.error().message;
}

// A scene that must be accepted (a default Scene and a failure when it was refused).
Scene Parsed(const std::string& text, const std::vector<SceneOverride>& overrides = {}) {
    Result<Scene> scene = ParseScene(text, kLabel, overrides);
    if (!scene) {
        ADD_FAILURE() << "the scene was refused:\n" << scene.error().message;
        return Scene{};
    }
    return *scene;
}

// True when one line of `message` equals `expected` exactly.
::testing::AssertionResult HasLine(const std::string& message, const std::string& expected) {
    for (const std::string& line : SplitLines(message))
        if (line == expected) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "no line\n  " << expected << "\nin\n" << message;
}

// True when one line of `message` starts with `prefix`.
::testing::AssertionResult HasLineStartingWith(const std::string& message, const std::string& prefix) {
    for (const std::string& line : SplitLines(message))
        if (line.starts_with(prefix)) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "no line starting with\n  " << prefix << "\nin\n" << message;
}

StageSet Stages(std::initializer_list<Stage> list) {
    StageSet set;
    for (Stage s : list) set.Add(s);
    return set;
}

constexpr const char* kMinimal = R"({"grid": {"size": [8, 4, 6]}})";

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

// Test that the stages without dependency rules (render_march, noise) are accepted on their own.
TEST(SceneTest, OtherKnownStagesNeedNothing) {
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "stages": ["render_march", "noise"]})").stages,
              Stages({Stage::RenderMarch, Stage::Noise}));
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
    EXPECT_EQ(scene.shadow.form, AttenuationKind::Beer);
    EXPECT_EQ(scene.shadow.kappa, 0.25);
    EXPECT_EQ(scene.render.width, 320u);
    EXPECT_EQ(scene.render.height, 240u);
    EXPECT_EQ(scene.render.qMin, 0.3);
    EXPECT_EQ(scene.render.splatScale, 1.5);
    EXPECT_EQ(scene.render.opacity, 0.6);
    EXPECT_EQ(scene.render.alpha, 0.5);
    EXPECT_TRUE(scene.render.culling);
    EXPECT_TRUE(scene.render.skipping);
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
    EXPECT_EQ(scene.shadow.form, AttenuationKind::Thesis);
    EXPECT_EQ(scene.shadow.kappa, 0.0);
    EXPECT_EQ(scene.render.width, 16384u);
    EXPECT_EQ(scene.render.height, 1u);
    EXPECT_EQ(scene.render.qMin, 0.0);
    EXPECT_EQ(scene.render.splatScale, 0.25);
    EXPECT_EQ(scene.render.opacity, 1.0);
    EXPECT_EQ(scene.render.alpha, 0.0);
    EXPECT_FALSE(scene.render.culling);
    EXPECT_FALSE(scene.render.skipping);
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

// ---- Refused scenes ------------------------------------------------------------------------------------------

// Test that an unknown top-level key is refused.
TEST(SceneTest, UnknownTopLevelKey) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "colour": "grey"})"),
                        "test.json: colour: unknown field"));
}

// Test that an unknown nested key is refused with the closest known key suggested.
TEST(SceneTest, UnknownNestedKeySuggestsClosest) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "ellipsoids": {"sise_mean": [1, 1, 1]}})"),
                        R"(test.json: ellipsoids.sise_mean: unknown field (did you mean "size_mean"?))"));
}

// Test that a string, a bool and an object where numbers belong are refused with the value shown.
TEST(SceneTest, WrongType) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6], "voxel_size": true}, "steps": "20",
                                      "smooth": [1]})");
    EXPECT_TRUE(HasLine(message, "test.json: grid.voxel_size: expected a number, got true"));
    EXPECT_TRUE(HasLine(message, R"(test.json: steps: expected an integer, got "20")"));
    EXPECT_TRUE(HasLine(message, "test.json: smooth: expected an object, got [1]"));
}

// Test that a fractional number for an integer field is refused.
TEST(SceneTest, FloatForInteger) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "ca": {"seed": 1.5}})"),
                        "test.json: ca.seed: expected an integer, got 1.5"));
}

// Test that a probability above 1 is refused with the range and the value.
TEST(SceneTest, ProbabilityOutOfRange) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "ca": {"p_ext": 1.5}})"),
                        "test.json: ca.p_ext: must be in [0, 1], got 1.5"));
}

// Test that a negative grid size is refused.
TEST(SceneTest, NegativeSize) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, -4, 6]}})"),
                        "test.json: grid.size[1]: must be in [1, 4294967295], got -4"));
}

// Test that a zero grid size and a zero voxel size are refused.
TEST(SceneTest, ZeroSize) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 0], "voxel_size": 0}})");
    EXPECT_TRUE(HasLine(message, "test.json: grid.size[2]: must be in [1, 4294967295], got 0"));
    EXPECT_TRUE(HasLine(message, "test.json: grid.voxel_size: must be > 0, got 0"));
}

// Test that grid.size is required, whether grid is missing or only size is.
TEST(SceneTest, MissingGridSize) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"steps": 5})"), "test.json: grid.size: required field is missing"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"voxel_size": 10}})"), "test.json: grid.size: required field is missing"));
}

// Test that warmup_steps must stay below steps.
TEST(SceneTest, WarmupNotBelowSteps) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "steps": 10, "warmup_steps": 10})"),
                        "test.json: warmup_steps: must be < steps (10), got 10"));
}

// Test that a stage listed twice is refused.
TEST(SceneTest, DuplicateStage) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["region", "ca", "region"]})"),
                        R"(test.json: stages[2]: duplicate stage "region")"));
}

// Test that an unknown stage is refused with a suggestion, and an empty list is refused.
TEST(SceneTest, UnknownStage) {
    EXPECT_TRUE(HasLineStartingWith(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["region", "smoth"]})"),
                                    R"(test.json: stages[1]: unknown stage "smoth" (did you mean "smooth"?))"));
    EXPECT_TRUE(HasLineStartingWith(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": []})"),
                                    "test.json: stages: must name at least one stage"));
}

// Test that a stage whose input no enabled stage writes is refused, naming the resource and its producers.
TEST(SceneTest, StageDependency) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["region", "ca", "density"]})"),
                        R"(test.json: stages: "density" needs "q", which no enabled stage writes (enable "smooth" or "noise"))"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["ca"]})"),
                        R"(test.json: stages: "ca" needs "region", which no enabled stage writes (enable "region"))"));
}

// Test that wind_shift must have one pair or nz pairs, each two integers.
TEST(SceneTest, WindShiftWrongLength) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "ca": {"wind_shift": [[1, 0], [2, 0]]}})");
    EXPECT_TRUE(HasLine(message, "test.json: ca.wind_shift: expected 1 pair (for every slice) or nz = 6 pairs, got 2"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 1]}, "ca": {"wind_shift": ["abc"]}})"),
                        R"(test.json: ca.wind_shift[0]: expected an array of 2 integers, got "abc")"));
}

// Test that a choice string not in its list is refused with the choices, and a near miss gets a suggestion.
TEST(SceneTest, BadChoiceString) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "shade": {"filter": "cubic", "storage": "fp-16"},
                                      "phase": {"function": "Henyey-Greenstein"}, "shadow": {"form": 1}})");
    EXPECT_TRUE(HasLine(message, R"(test.json: shade.filter: must be one of "bilinear", "nearest", got "cubic")"));
    EXPECT_TRUE(HasLine(message, R"(test.json: shade.storage: must be one of "fp32", "fp16", "unorm8", got "fp-16" )"
                                 R"((did you mean "fp16"?))"));
    EXPECT_TRUE(HasLine(message, R"(test.json: phase.function: must be one of "none", "henyey-greenstein", )"
                                 R"("cornette-shanks", got "Henyey-Greenstein" (did you mean "henyey-greenstein"?))"));
    EXPECT_TRUE(HasLine(message, R"(test.json: shadow.form: must be one of "beer", "thesis", got 1)"));
    EXPECT_EQ(SplitLines(message).size(), 4u) << message;
}

// Test that a shade resolution other than 1, 2 or 4 is refused, and a fractional one as not an integer.
TEST(SceneTest, ShadeResolutionThree) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "shade": {"resolution": 3}})"),
                        "test.json: shade.resolution: must be 1, 2 or 4, got 3"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "shade": {"resolution": 1e30}})"),
                        "test.json: shade.resolution: must be 1, 2 or 4, got 1e+30"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "shade": {"resolution": 1.5}})"),
                        "test.json: shade.resolution: expected an integer, got 1.5"));
}

// Test that the phase asymmetry g = 1 is refused (open interval), and so is a g that becomes 1 as a float.
TEST(SceneTest, PhaseGOne) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "phase": {"g": 1}})"),
                        "test.json: phase.g: must be in (-1, 1), got 1"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "phase": {"g": -0.99999999999}})"),
                        "test.json: phase.g: must be in (-1, 1) in single precision, got -0.99999999999"));
}

// Test that a sun elevation above 90 degrees is refused.
TEST(SceneTest, SunElevation91) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "sun": {"elevation_deg": 91}})"),
                        "test.json: sun.elevation_deg: must be in [-90, 90], got 91"));
}

// Test that a negative colour component is refused, in the sun and in the lighting colours.
TEST(SceneTest, NegativeColourComponent) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "sun": {"color": [1, -0.5, 1]},
                                      "lighting": {"background": [0.1, 0.2, -3]}})");
    EXPECT_TRUE(HasLine(message, "test.json: sun.color[1]: must be >= 0, got -0.5"));
    EXPECT_TRUE(HasLine(message, "test.json: lighting.background[2]: must be >= 0, got -3"));
}

// Test that a camera without eye is refused: eye is required.
TEST(SceneTest, CameraMissingEye) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"cameras": [{"target": [1, 2, 3]}]}})"),
                        "test.json: render.cameras[0].eye: required field is missing"));
}

// Test that a camera looking at its own eye position is refused.
TEST(SceneTest, CameraTargetEqualsEye) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"cameras": [
                                        {"eye": [1, 2, 3], "target": [1, 2, 4]},
                                        {"eye": [5, 5, 5], "target": [5, 5, 5.0]}]}})"),
                        "test.json: render.cameras[1].target: must differ from eye"));
}

// Test that an up vector of all zeros is refused.
TEST(SceneTest, CameraUpAllZero) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"cameras": [
                                        {"eye": [0, 0, 0], "target": [1, 0, 0], "up": [0, -0.0, 0]}]}})"),
                        "test.json: render.cameras[0].up: must not be all zero, got [0,-0.0,0]"));
}

// Test that a field of view of 180 degrees is refused (open interval).
TEST(SceneTest, CameraFov180) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"cameras": [
                                        {"eye": [0, 0, 0], "target": [1, 0, 0], "fov_deg": 180}]}})"),
                        "test.json: render.cameras[0].fov_deg: must be in (0, 180), got 180"));
}

// Test that far must exceed near, reported on far, or on near when only near was given.
TEST(SceneTest, CameraFarNotBeyondNear) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"cameras": [
                                      {"eye": [0, 0, 0], "target": [1, 0, 0], "near": 5, "far": 5},
                                      {"eye": [0, 0, 0], "target": [1, 0, 0], "near": 2e5}]}})");
    EXPECT_TRUE(HasLine(message, "test.json: render.cameras[0].far: must be > near (5), got 5"));
    EXPECT_TRUE(HasLine(message, "test.json: render.cameras[1].near: must be < far (100000), got 200000"));
}

// Test that two cameras with one name are refused, also when the second name is the default view<index>.
TEST(SceneTest, DuplicateCameraNames) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"cameras": [
                                      {"name": "a", "eye": [0, 0, 0], "target": [1, 0, 0]},
                                      {"name": "a", "eye": [0, 0, 0], "target": [0, 1, 0]},
                                      {"name": "view3", "eye": [0, 0, 0], "target": [0, 1, 0]},
                                      {"eye": [0, 0, 0], "target": [0, 0, 1]}]}})");
    EXPECT_TRUE(HasLine(message, R"(test.json: render.cameras[1].name: duplicate camera name "a")"));
    EXPECT_TRUE(HasLine(message,
                        R"(test.json: render.cameras[3].name: duplicate camera name "view3" (its default name))"));
    EXPECT_EQ(SplitLines(message).size(), 2u) << message;
}

// Test that render_splat without any camera is refused, whether cameras is missing or empty.
TEST(SceneTest, RenderSplatWithoutCameras) {
    const std::string stages = R"("stages": ["region", "ca", "smooth", "density", "shade", "render_splat"])";
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, )" + stages + "}"),
                        R"(test.json: render.cameras: "render_splat" needs at least one camera)"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"cameras": []}, )" + stages + "}"),
                        R"(test.json: render.cameras: "render_splat" needs at least one camera)"));
}

// Test each input of the lighting stages: shade needs q, shadow D, render_splat T and the occupancy.
TEST(SceneTest, LightingStageDependencies) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["shade"]})"),
                        R"(test.json: stages: "shade" needs "q", which no enabled stage writes (enable "smooth" or "noise"))"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["region", "ca", "smooth", "shadow"]})"),
                        R"(test.json: stages: "shadow" needs "D", which no enabled stage writes (enable "density"))"));
    const std::string camera = R"("render": {"cameras": [{"eye": [0, 0, 0], "target": [1, 0, 0]}]})";
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, )" + camera +
                                R"(, "stages": ["region", "ca", "smooth", "density", "render_splat"]})"),
                        R"(test.json: stages: "render_splat" needs "T", which no enabled stage writes (enable "shade"))"));
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, )" + camera +
                                  R"(, "stages": ["region", "ca", "smooth", "shade", "render_splat"]})");
    EXPECT_TRUE(HasLine(message, R"(test.json: stages: "render_splat" needs "tiles" and "bands", which no enabled stage writes (enable "density"))"));
    EXPECT_EQ(SplitLines(message).size(), 1u) << message;
}

// Test that a number or a string where a boolean belongs is refused.
TEST(SceneTest, WrongBooleanType) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"culling": 1},
                                      "shade": {"scattering": {"enabled": "true"}}})");
    EXPECT_TRUE(HasLine(message, "test.json: render.culling: expected true or false, got 1"));
    EXPECT_TRUE(HasLine(message, R"(test.json: shade.scattering.enabled: expected true or false, got "true")"));
}

// Test that the other new fields refuse out-of-range values with their ranges (a sample of each kind of bound).
TEST(SceneTest, LightingFieldRanges) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "sun": {"intensity": -1},
        "shade": {"sigma": -0.1, "scattering": {"solid_angle": 13, "albedo": 1.5}}, "shadow": {"kappa": -1},
        "render": {"width": 0, "height": 16385, "splat_scale": 0, "opacity": 2, "every_steps": -1,
                   "cameras": {"eye": [0, 0, 0]}}})");
    EXPECT_TRUE(HasLine(message, "test.json: sun.intensity: must be >= 0, got -1"));
    EXPECT_TRUE(HasLine(message, "test.json: shade.sigma: must be >= 0, got -0.1"));
    EXPECT_TRUE(
        HasLine(message, "test.json: shade.scattering.solid_angle: must be in (0, 12.566370614359172], got 13"));
    EXPECT_TRUE(HasLine(message, "test.json: shade.scattering.albedo: must be in [0, 1], got 1.5"));
    EXPECT_TRUE(HasLine(message, "test.json: shadow.kappa: must be >= 0, got -1"));
    EXPECT_TRUE(HasLine(message, "test.json: render.width: must be in [1, 16384], got 0"));
    EXPECT_TRUE(HasLine(message, "test.json: render.height: must be in [1, 16384], got 16385"));
    EXPECT_TRUE(HasLine(message, "test.json: render.splat_scale: must be > 0, got 0"));
    EXPECT_TRUE(HasLine(message, "test.json: render.opacity: must be in [0, 1], got 2"));
    EXPECT_TRUE(HasLine(message, "test.json: render.every_steps: must be in [0, 4294967295], got -1"));
    EXPECT_TRUE(HasLine(message,
                        R"(test.json: render.cameras: expected an array of camera objects, got {"eye":[0,0,0]})"));
    EXPECT_EQ(SplitLines(message).size(), 11u) << message;
}

// Test that unknown keys inside the new sections and a camera are refused, a shortened key suggesting the full one.
TEST(SceneTest, LightingUnknownKeys) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "sun": {"elevation": 10},
        "shade": {"scattering": {"enable": true}}, "render": {"cameras": [
        {"eye": [0, 0, 0], "target": [1, 0, 0], "fov": 50}]}})");
    EXPECT_TRUE(HasLine(message, R"(test.json: sun.elevation: unknown field (did you mean "elevation_deg"?))"));
    EXPECT_TRUE(HasLine(message, R"(test.json: shade.scattering.enable: unknown field (did you mean "enabled"?))"));
    EXPECT_TRUE(HasLine(message, R"(test.json: render.cameras[0].fov: unknown field (did you mean "fov_deg"?))"));
}

// Test that a wind grid must carry exactly gx*gy vectors.
TEST(SceneTest, WindGridVectorCountMismatch) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]},
                                    "ellipsoids": {"wind": {"grid": [2, 2], "vectors": [[1, 0], [1, 0], [1, 0]]}}})"),
                        "test.json: ellipsoids.wind.vectors: expected 4 pairs (grid 2 x 2), got 3"));
}

// Test that a size variance larger than its mean is refused, and so is a lifetime variance not below its mean.
TEST(SceneTest, VarianceAboveMean) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]},
                                      "ellipsoids": {"size_variance": [4, 4, 9], "lifetime_variance": 400}})");
    EXPECT_TRUE(HasLine(message, "test.json: ellipsoids.size_variance[2]: must be <= size_mean[2] (8), got 9"));
    EXPECT_TRUE(HasLine(message, "test.json: ellipsoids.lifetime_variance: must be < lifetime_mean (400), got 400"));
}

// Test that a grid of 2^32 voxels is refused: the linear voxel index is 32-bit.
TEST(SceneTest, VoxelCountTooLarge) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [65536, 65536, 1]}})"),
                        "test.json: grid.size: [65536, 65536, 1] is 4294967296 voxels; the voxel index is 32-bit, "
                        "so at most 4294967295"));
}

// The largest-footprint scene below 2^32 voxels: nx = 1 costs a 64-bit word per voxel in every bit field.
constexpr const char* kHugeScene = R"({"grid": {"size": [1, 65535, 65535]}, "ca": {"wind_shift": [[1, 0]]},
                                       "density": {"tile": 1, "band": 1}})";
// 85 bytes per voxel (4 staging + 1 region + 72 bit fields + 8 q) plus smoothing rings and density maps, about 348 GiB.
constexpr uint64_t kHugeSceneBytes = 373693349389ull;

// Test that a scene needing more memory than the machine has is refused before anything is allocated.
TEST(SceneTest, MemoryTooLarge) {
    const uint64_t physical = uint64_t(sysconf(_SC_PHYS_PAGES)) * uint64_t(sysconf(_SC_PAGE_SIZE));
    if (physical >= kHugeSceneBytes) GTEST_SKIP() << "this machine has more memory than the largest valid scene needs";
    std::string message = ErrorOf(kHugeScene);
    EXPECT_TRUE(HasLineStartingWith(message, "test.json: grid.size: the enabled stages need 348.0 GiB, more than "
                                             "this machine's "));
}

// Test the memory estimate on a small grid, term by term (lighting stages too), and on the largest scene.
TEST(SceneTest, EstimateSceneBytes) {
    Scene scene = Parsed(R"({"grid": {"size": [100, 4, 6]}})");
    const uint64_t v = 100 * 4 * 6;
    const uint64_t bitField = 2 * 4 * 6 * 8;  // ceil(100 / 64) words per row
    const uint64_t density = 2 * 4 * 100 * 4 + 4 * 1 * (2 + 1) * 2;  // D twice; 4 x 1 tiles, 2 bands + 1
    const uint64_t smooth = 8 * v + 640 * 100 * 4;  // q twice, and 64 threads' rings of five 16-bit slices
    EXPECT_EQ(EstimateSceneBytes(scene), 4 * v + (v + 64) + 6 * bitField + smooth + density);
    scene.ca.windShift.assign(6, SliceShift{1, 0});
    EXPECT_EQ(EstimateSceneBytes(scene), 4 * v + (v + 64) + 9 * bitField + smooth + density);
    scene.stages = Stages({Stage::Region});
    EXPECT_EQ(EstimateSceneBytes(scene), 4 * v + (v + 64));

    // The lighting stages: shade's T, shadow's G, render_splat's previous q and RGB float image.
    Scene lit = Parsed(R"({"grid": {"size": [100, 4, 6]},
        "stages": ["region", "ca", "smooth", "density", "shade", "shadow", "render_splat"],
        "render": {"width": 10, "height": 7, "cameras": [{"eye": [0, 0, 0], "target": [1, 0, 0]}]}})");
    const uint64_t simulation = 4 * v + (v + 64) + 6 * bitField + smooth + density;
    const uint64_t shade = 4 * v, shadow = 4 * 100 * 4, render = 4 * v + 3 * 4 * 10 * 7;
    EXPECT_EQ(EstimateSceneBytes(lit), simulation + shade + shadow + render);
    // Half resolution adds coarse q and T grids of ceil(100/2) x ceil(4/2) x ceil(6/2) floats.
    lit.shade.resolution = 2;
    EXPECT_EQ(EstimateSceneBytes(lit), simulation + shade + 2 * 4 * (50 * 2 * 3) + shadow + render);
    // Quarter resolution: ceil(100/4) x ceil(4/4) x ceil(6/4).
    lit.shade.resolution = 4;
    EXPECT_EQ(EstimateSceneBytes(lit), simulation + shade + 2 * 4 * (25 * 1 * 2) + shadow + render);
    lit.stages = Stages({Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density, Stage::Shadow});
    EXPECT_EQ(EstimateSceneBytes(lit), simulation + shadow);

    Scene huge;
    huge.grid.size = Extent3{1, 65535, 65535};
    huge.stages = Stages({Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density});
    huge.ca.windShift = {SliceShift{1, 0}};
    huge.density.tile = 1;
    huge.density.band = 1;
    EXPECT_EQ(EstimateSceneBytes(huge), kHugeSceneBytes);
}

// Test that malformed JSON is reported at the right line and column (hand-counted, 1-based).
TEST(SceneTest, MalformedJsonLineAndColumn) {
    // Line 3 is `  "steps": 20,,`: the second comma is column 15.
    std::string message = ErrorOf("{\n"
                                  "  \"grid\": {\"size\": [8, 4, 6]},\n"
                                  "  \"steps\": 20,,\n"
                                  "  \"ca\": {}\n"
                                  "}\n");
    EXPECT_TRUE(HasLineStartingWith(message, "test.json: line 3, column 15: malformed JSON: ")) << message;
    EXPECT_EQ(SplitLines(message).size(), 1u);
}

// Test that a number too large for a double is refused at its position, not read as infinity.
TEST(SceneTest, NumberOverflowInFile) {
    // `  "steps": 1e999`: the number starts at column 12 of line 2.
    EXPECT_TRUE(HasLine(ErrorOf("{\"grid\": {\"size\": [8, 4, 6]},\n  \"steps\": 1e999}"),
                        "test.json: line 2, column 12: the number 1e999 is out of range (not finite)"));
}

// Test that a key given twice in one object is refused rather than silently overwritten.
TEST(SceneTest, DuplicateKey) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "ca": {"seed": 1, "seed": 2}})"),
                        "test.json: ca.seed: duplicate field"));
}

// Test that a top level that is not an object is refused.
TEST(SceneTest, TopLevelNotAnObject) {
    EXPECT_TRUE(HasLine(ErrorOf("[1, 2]"), "test.json: expected a JSON object at the top level, got [1,2]"));
}

// Test that every problem of a file is reported, one line each, not just the first.
TEST(SceneTest, SeveralErrorsTogether) {
    std::string message = ErrorOf(R"({"grid": {"size": [0, 4, 6]}, "steps": 0, "ca": {"p_ext": -0.5},
                                      "smooth": {"radius": 3}})");
    EXPECT_TRUE(HasLine(message, "test.json: grid.size[0]: must be in [1, 4294967295], got 0"));
    EXPECT_TRUE(HasLine(message, "test.json: steps: must be in [1, 10000000], got 0"));
    EXPECT_TRUE(HasLine(message, "test.json: ca.p_ext: must be in [0, 1], got -0.5"));
    EXPECT_TRUE(HasLine(message, "test.json: smooth.radius: must be in [0, 2], got 3"));
    EXPECT_EQ(SplitLines(message).size(), 4u) << message;
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

// ---- Overrides -----------------------------------------------------------------------------------------------

// Test that --set ca.seed=42 changes the seed (and the ellipsoid seed that follows it).
TEST(SceneTest, OverrideSeed) {
    Scene scene = Parsed(kMinimal, {{"ca.seed", "42"}});
    EXPECT_EQ(scene.ca.seed, 42u);
    EXPECT_EQ(scene.ellipsoids.seed, 42u);
}

// Test that --set grid.size=[10,5,3] replaces the whole array.
TEST(SceneTest, OverrideGridSize) {
    EXPECT_EQ(Parsed(kMinimal, {{"grid.size", "[10,5,3]"}}).grid.size, (Extent3{10, 5, 3}));
}

// Test that a bare word is taken as a string, and missing objects along the path are created.
TEST(SceneTest, OverrideBareWordAndNewSection) {
    Scene scene = Parsed(kMinimal, {{"name", "storm"}, {"smooth.radius", "2"}});
    EXPECT_EQ(scene.name, "storm");
    EXPECT_EQ(scene.smooth.radius, 2);
}

// Test that a bad override value is refused and marked as coming from --set.
TEST(SceneTest, OverrideBadValue) {
    std::string message = ErrorOf(kMinimal, {{"ca.p_ext", "2"}, {"grid", R"({"size": [8, 0, 6]})"}});
    EXPECT_TRUE(HasLine(message, "test.json: ca.p_ext: must be in [0, 1], got 2 (set on the command line)"));
    EXPECT_TRUE(HasLine(message, "test.json: grid.size[1]: must be in [1, 4294967295], got 0 (set on the command line)"));
}

// Test that errors outside the overridden paths are not marked as coming from --set.
TEST(SceneTest, OverrideSuffixOnlyOnOverriddenFields) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "steps": 0})", {{"step", "3"}});
    EXPECT_TRUE(HasLine(message, "test.json: steps: must be in [1, 10000000], got 0"));
    EXPECT_TRUE(HasLine(message, R"(test.json: step: unknown field (did you mean "steps"?) (set on the command line))"));
}

// Test that an override of an unknown field is refused by the unknown-field check.
TEST(SceneTest, OverrideUnknownField) {
    EXPECT_TRUE(HasLine(ErrorOf(kMinimal, {{"ca.sed", "3"}}),
                        R"(test.json: ca.sed: unknown field (did you mean "seed"?) (set on the command line))"));
}

// Test that an override cannot descend into a value that is not an object.
TEST(SceneTest, OverrideThroughNonObject) {
    EXPECT_TRUE(HasLine(ErrorOf(kMinimal, {{"grid.size.x", "1"}}),
                        R"(test.json: --set grid.size.x: "grid.size" is not an object)"));
}

// Test that --set shade.storage=fp16 (a bare word) selects fp16, and --set render.culling=false a boolean.
TEST(SceneTest, OverrideShadeStorage) {
    Scene scene = Parsed(kMinimal, {{"shade.storage", "fp16"}, {"render.culling", "false"}});
    EXPECT_EQ(scene.shade.storage, StorageFormat::Fp16);
    EXPECT_FALSE(scene.render.culling);
}

// Test that --set shade.resolution=3 is refused and marked as coming from --set.
TEST(SceneTest, OverrideShadeResolutionRefused) {
    EXPECT_TRUE(HasLine(ErrorOf(kMinimal, {{"shade.resolution", "3"}}),
                        "test.json: shade.resolution: must be 1, 2 or 4, got 3 (set on the command line)"));
}

// Test that an override value that overflows to infinity is refused, not used.
TEST(SceneTest, OverrideNonFinite) {
    std::string message = ErrorOf(kMinimal, {{"grid.voxel_size", "1e999"}, {"grid.origin", "[0, -1e999, 0]"}});
    EXPECT_TRUE(HasLine(message,
                        "test.json: grid.voxel_size: the number 1e999 is out of range (not finite) (set on the command line)"));
    EXPECT_TRUE(HasLine(message,
                        "test.json: grid.origin: the number -1e999 is out of range (not finite) (set on the command line)"));
}

}  // namespace
}  // namespace cb
