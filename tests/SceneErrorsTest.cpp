// Scene loading: every kind of refusal and its message (the memory estimate: MemoryPlanTest.cpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <string>

#include "SceneTestUtil.h"
#include "core/scene/Scene.h"

namespace cb {
namespace {

using test::ErrorOf;
using test::HasLine;
using test::HasLineStartingWith;
using test::Parsed;
using test::SplitLines;

// ---- Refused scenes ------------------------------------------------------------------------------------------

// Test that an unknown top-level key is refused.
TEST(SceneTest, UnknownTopLevelKey) {
    EXPECT_TRUE(
        HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "colour": "grey"})"), "test.json: colour: unknown field"));
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
    EXPECT_TRUE(HasLine(message, "test.json: grid.voxel_size: must be in (0, 1e+30], got 0"));
}

// Test that grid.size is required, whether grid is missing or only size is.
TEST(SceneTest, MissingGridSize) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"steps": 5})"), "test.json: grid.size: required field is missing"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"voxel_size": 10}})"), "test.json: grid.size: required field is missing"));
}

// Test that warmup_steps must stay below steps.
TEST(SceneTest, WarmupNotBelowSteps) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "steps": 10, "warmup_steps": 10})"),
                        "test.json: warmup_steps: must be < steps (10), got 10 (more steps, or fewer warm-up "
                        "steps: --set warmup_steps=N)"));
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
    EXPECT_TRUE(HasLine(
        ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["region", "ca", "density"]})"),
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
                                 R"("cornette-shanks", "mie", "dual-lobe", got "Henyey-Greenstein" )"
                                 R"((did you mean "henyey-greenstein"?))"));
    EXPECT_TRUE(HasLine(message, R"(test.json: shadow.form: must be one of "beer", "thesis", "wang", got 1)"));
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
    EXPECT_TRUE(HasLine(message, "test.json: sun.color[1]: must be in [0, 1e+30], got -0.5"));
    EXPECT_TRUE(HasLine(message, "test.json: lighting.background[2]: must be in [0, 1e+30], got -3"));
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
    EXPECT_TRUE(
        HasLine(message, R"(test.json: render.cameras[3].name: duplicate camera name "view3" (its default name))"));
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
    EXPECT_TRUE(
        HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["shade"]})"),
                R"(test.json: stages: "shade" needs "q", which no enabled stage writes (enable "smooth" or "noise"))"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["region", "ca", "smooth", "shadow"]})"),
                        R"(test.json: stages: "shadow" needs "D", which no enabled stage writes (enable "density"))"));
    const std::string camera = R"("render": {"cameras": [{"eye": [0, 0, 0], "target": [1, 0, 0]}]})";
    EXPECT_TRUE(
        HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, )" + camera +
                        R"(, "stages": ["region", "ca", "smooth", "density", "render_splat"]})"),
                R"(test.json: stages: "render_splat" needs "T", which no enabled stage writes (enable "shade"))"));
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, )" + camera +
                                  R"(, "stages": ["region", "ca", "smooth", "shade", "render_splat"]})");
    EXPECT_TRUE(HasLine(
        message,
        R"(test.json: stages: "render_splat" needs "tiles" and "bands", which no enabled stage writes (enable "density"))"));
    EXPECT_EQ(SplitLines(message).size(), 1u) << message;
}

// Test that the ground is refused without the shadow stage that computes its G, and its albedo out of [0, 1];
// with the shadow stage, the same ground is accepted.
TEST(SceneTest, GroundNeedsShadow) {
    const std::string render =
        R"("render": {"ground": {"albedo": [0.3, 0.3, 0.3]}, "cameras": [{"eye": [0, 0, 9], "target": [1, 0, 0]}]})";
    const std::string stages = R"("stages": ["region", "ca", "smooth", "density", "shade", "render_march"])";
    const std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, )" + render + ", " + stages + "}");
    EXPECT_TRUE(HasLine(message, R"(test.json: render.ground: needs the stage "shadow", which computes the ground )"
                                 R"(shadow G it is lit through; enable it or remove render.ground)"));
    EXPECT_EQ(SplitLines(message).size(), 1u) << message;
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"ground": {"albedo": [0.3, 1.5, 0]}}})"),
                        "test.json: render.ground.albedo[1]: must be in [0, 1], got 1.5"));
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "render": {"ground": {"albedos": [0.3, 0.3, 0.3]}}})"),
                        R"(test.json: render.ground.albedos: unknown field (did you mean "albedo"?))"));
    const std::string shadowed = R"("stages": ["region", "ca", "smooth", "density", "shade", "shadow", "render_march"])";
    const Scene scene = test::Parsed(R"({"grid": {"size": [8, 4, 6]}, )" + render + ", " + shadowed + "}");
    EXPECT_TRUE(scene.render.ground.on);
    EXPECT_EQ(scene.render.ground.albedo, (std::array<double, 3>{0.3, 0.3, 0.3}));
    EXPECT_FALSE(test::Parsed(R"({"grid": {"size": [8, 4, 6]}, )" + shadowed + R"(, "render": {"cameras": [)"
                        R"({"eye": [0, 0, 9], "target": [1, 0, 0]}]}})")
                     .render.ground.on);
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
        "shade": {"sigma": -0.1, "scattering": {"solid_angle": 13, "albedo": 1.5}},
        "shadow": {"kappa": -1, "coverage": 1.5, "density_factor": -0.5},
        "render": {"width": 0, "height": 16385, "splat_scale": 0, "opacity": 2, "every_steps": -1,
                   "cameras": {"eye": [0, 0, 0]}}})");
    EXPECT_TRUE(HasLine(message, "test.json: sun.intensity: must be in [0, 1e+30], got -1"));
    EXPECT_TRUE(HasLine(message, "test.json: shade.sigma: must be in [0, 1e+30], got -0.1"));
    EXPECT_TRUE(
        HasLine(message, "test.json: shade.scattering.solid_angle: must be in (0, 12.566370614359172], got 13"));
    EXPECT_TRUE(HasLine(message, "test.json: shade.scattering.albedo: must be in [0, 1], got 1.5"));
    EXPECT_TRUE(HasLine(message, "test.json: shadow.kappa: must be in [0, 1e+30], got -1"));
    EXPECT_TRUE(HasLine(message, "test.json: shadow.coverage: must be in [0, 1], got 1.5"));
    EXPECT_TRUE(HasLine(message, "test.json: shadow.density_factor: must be in [0, 1], got -0.5"));
    EXPECT_TRUE(HasLine(message, "test.json: render.width: must be in [1, 16384], got 0"));
    EXPECT_TRUE(HasLine(message, "test.json: render.height: must be in [1, 16384], got 16385"));
    EXPECT_TRUE(HasLine(message, "test.json: render.splat_scale: must be > 0, got 0"));
    EXPECT_TRUE(HasLine(message, "test.json: render.opacity: must be in [0, 1], got 2"));
    EXPECT_TRUE(HasLine(message, "test.json: render.every_steps: must be in [0, 4294967295], got -1"));
    EXPECT_TRUE(
        HasLine(message, R"(test.json: render.cameras: expected an array of camera objects, got {"eye":[0,0,0]})"));
    EXPECT_EQ(SplitLines(message).size(), 13u) << message;
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
constexpr const char* kHugeScene = R"({"grid": {"size": [1, 65535, 65535]}, "density": {"tile": 1, "band": 1}})";
// 58 bytes per voxel (4 staging + 1 region + 48 bit fields + 4 q + 1 bands) and the column maps, about 232 GiB
// (tests/MemoryPlanTest.cpp prices it buffer by buffer).
constexpr uint64_t kHugeSceneBytes = 249100828917ull;

// Test that a scene needing more memory than the machine has is refused before anything is allocated.
TEST(SceneTest, MemoryTooLarge) {
    const uint64_t physical = uint64_t(sysconf(_SC_PHYS_PAGES)) * uint64_t(sysconf(_SC_PAGE_SIZE));
    if (physical >= kHugeSceneBytes) GTEST_SKIP() << "this machine has more memory than the largest valid scene needs";
    std::string message = ErrorOf(kHugeScene);
    EXPECT_TRUE(HasLineStartingWith(message,
                                    "test.json: grid.size: the enabled stages need 232.0 GiB, more than "
                                    "this machine's "));
}

// Test that malformed JSON is reported at the right line and column (hand-counted, 1-based).
TEST(SceneTest, MalformedJsonLineAndColumn) {
    // Line 3 is `  "steps": 20,,`: the second comma is column 15.
    std::string message = ErrorOf(
        "{\n"
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

// Test that a lattice frequency past its bound is reported with the real lacunarity^(octaves - 1): the power was
// capped at the first past 4096, so the coverage map said "1 x 8192" for 14, 15 and 16 octaves alike.
TEST(SceneTest, NoiseFrequencyMessageHasTheRealPower) {
    auto coverage = [](int octaves) {
        return ErrorOf(R"({"grid": {"size": [8, 8, 8]}, "stages": ["noise"],
                           "noise": {"coverage": {"frequency": [1, 1], "octaves": )" +
                       std::to_string(octaves) + "}}}");
    };
    const std::string reason = "times lacunarity^(octaves - 1) must be at most 4096 lattice cells, got ";
    EXPECT_TRUE(HasLine(coverage(14), "test.json: noise.coverage.frequency[0]: " + reason + "1 x 8192"));  // 2^13
    EXPECT_TRUE(HasLine(coverage(15), "test.json: noise.coverage.frequency[0]: " + reason + "1 x 16384"));
    EXPECT_TRUE(HasLine(coverage(16), "test.json: noise.coverage.frequency[0]: " + reason + "1 x 32768"));
    // 8^15 = 2^45 = 35184372088832, far past the old cap of 8^5 = 32768.
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 8, 8]}, "stages": ["noise"],
                                    "noise": {"frequency": [1, 2, 3], "lacunarity": 8, "octaves": 16}})"),
                        "test.json: noise.frequency[0]: " + reason + "1 x 35184372088832"));
    // 4096 x 2^0 is at the bound and accepted.
    Parsed(R"({"grid": {"size": [8, 8, 8]}, "stages": ["noise"],
               "noise": {"coverage": {"frequency": [4096, 1], "octaves": 1}}})");
}

}  // namespace
}  // namespace cb
