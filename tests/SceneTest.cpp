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

// Test that known stages outside the default four are accepted without dependency rules.
TEST(SceneTest, OtherKnownStagesNeedNothing) {
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "stages": ["shade", "noise"]})").stages,
              Stages({Stage::Shade, Stage::Noise}));
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

// Test that a stage without the stage it reads is refused.
TEST(SceneTest, StageDependency) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["region", "ca", "density"]})"),
                        R"(test.json: stages: "density" needs "smooth")"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["ca"]})"),
                        R"(test.json: stages: "ca" needs "region")"));
}

// Test that wind_shift must have one pair or nz pairs, each two integers.
TEST(SceneTest, WindShiftWrongLength) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "ca": {"wind_shift": [[1, 0], [2, 0]]}})");
    EXPECT_TRUE(HasLine(message, "test.json: ca.wind_shift: expected 1 pair (for every slice) or nz = 6 pairs, got 2"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 1]}, "ca": {"wind_shift": ["abc"]}})"),
                        R"(test.json: ca.wind_shift[0]: expected an array of 2 integers, got "abc")"));
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

// Test the memory estimate on a small grid, term by term, and on the largest scene.
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
    EXPECT_TRUE(HasLine(message, "test.json: ca.p_ext: must be in [0, 1], got 2 (set with --set)"));
    EXPECT_TRUE(HasLine(message, "test.json: grid.size[1]: must be in [1, 4294967295], got 0 (set with --set)"));
}

// Test that errors outside the overridden paths are not marked as coming from --set.
TEST(SceneTest, OverrideSuffixOnlyOnOverriddenFields) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "steps": 0})", {{"step", "3"}});
    EXPECT_TRUE(HasLine(message, "test.json: steps: must be in [1, 10000000], got 0"));
    EXPECT_TRUE(HasLine(message, R"(test.json: step: unknown field (did you mean "steps"?) (set with --set))"));
}

// Test that an override of an unknown field is refused by the unknown-field check.
TEST(SceneTest, OverrideUnknownField) {
    EXPECT_TRUE(HasLine(ErrorOf(kMinimal, {{"ca.sed", "3"}}),
                        R"(test.json: ca.sed: unknown field (did you mean "seed"?) (set with --set))"));
}

// Test that an override cannot descend into a value that is not an object.
TEST(SceneTest, OverrideThroughNonObject) {
    EXPECT_TRUE(HasLine(ErrorOf(kMinimal, {{"grid.size.x", "1"}}),
                        R"(test.json: --set grid.size.x: "grid.size" is not an object)"));
}

// Test that an override value that overflows to infinity is refused, not used.
TEST(SceneTest, OverrideNonFinite) {
    std::string message = ErrorOf(kMinimal, {{"grid.voxel_size", "1e999"}, {"grid.origin", "[0, -1e999, 0]"}});
    EXPECT_TRUE(HasLine(message,
                        "test.json: grid.voxel_size: the number 1e999 is out of range (not finite) (set with --set)"));
    EXPECT_TRUE(HasLine(message,
                        "test.json: grid.origin: the number -1e999 is out of range (not finite) (set with --set)"));
}

}  // namespace
}  // namespace cb
