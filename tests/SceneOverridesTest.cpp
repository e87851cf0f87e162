// Scene loading: the --set overrides.
#include <gtest/gtest.h>

#include <string>

#include "SceneTestUtil.h"
#include "core/scene/Scene.h"

namespace cb {
namespace {

using test::ErrorOf;
using test::HasLine;
using test::kMinimal;
using test::Parsed;

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
    EXPECT_TRUE(
        HasLine(message, "test.json: grid.size[1]: must be in [1, 4294967295], got 0 (set on the command line)"));
}

// Test that errors outside the overridden paths are not marked as coming from --set.
TEST(SceneTest, OverrideSuffixOnlyOnOverriddenFields) {
    std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "steps": 0})", {{"step", "3"}});
    EXPECT_TRUE(HasLine(message, "test.json: steps: must be in [1, 10000000], got 0"));
    EXPECT_TRUE(
        HasLine(message, R"(test.json: step: unknown field (did you mean "steps"?) (set on the command line))"));
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
    EXPECT_FALSE(scene.splat.culling);
}

// Test that --set shade.resolution=3 is refused and marked as coming from --set.
TEST(SceneTest, OverrideShadeResolutionRefused) {
    EXPECT_TRUE(HasLine(ErrorOf(kMinimal, {{"shade.resolution", "3"}}),
                        "test.json: shade.resolution: must be 1, 2 or 4, got 3 (set on the command line)"));
}

// Test that an override value that overflows to infinity is refused, not used.
TEST(SceneTest, OverrideNonFinite) {
    std::string message = ErrorOf(kMinimal, {{"grid.voxel_size", "1e999"}, {"grid.origin", "[0, -1e999, 0]"}});
    EXPECT_TRUE(
        HasLine(message,
                "test.json: grid.voxel_size: the number 1e999 is out of range (not finite) (set on the command line)"));
    EXPECT_TRUE(HasLine(
        message, "test.json: grid.origin: the number -1e999 is out of range (not finite) (set on the command line)"));
}

}  // namespace
}  // namespace cb
