// City glow (Wang, Ji and Zhang, eq. 20; lighting.city_glow): the term InScattered adds against its closed form
// worked by hand, its terms in voxel units from a scene, every renderer taking it on the CPU, and its settings'
// checks. The GLSL twin is GlslTwin.InScatteredMatchesTheCpp; the backends' agreement is Cli.ConformCityGlow.*.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/math/Light.h"
#include "core/pipeline/LightTerms.h"
#include "core/plan/SceneLoad.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// One blob at (10, 20) voxel units, sigma 4 voxels (k = 1 / 32), strength 3; fade 2 over nz = 16; no sun.
LightTerms OneBlob() {
    LightTerms L;
    L.sunRadiance = {0, 0, 0};
    L.ambient = {0.125f, 0.25f, 0.5f};
    L.glowOn = true;
    L.glowColor = {1.0f, 0.5f, 0.25f};
    L.glowFade = 2;
    L.glowInvThickness = 1.0f / 16.0f;
    L.glowBlobCount = 1;
    L.glowBlobs[0] = {10, 20, 1.0f / 32.0f, 3};
    return L;
}

Vec3 At(const LightTerms& L, float x, float y, float z) {
    return InScattered(L, LightSample{0, 1, {x, y, z}, {0, 0, 1}});
}

// Test the term against eq. 20 by hand: at the blob's centre and a quarter of the thickness up (fade 2: half gone)
// glow = 3 * 1 * (1 - 0.5) = 1.5; one sigma out in x, 1.5 exp(-1/2); from half the thickness up (fade 2) nothing,
// bit for bit the ambient; at the base the whole strength; two blobs add.
TEST(CityGlow, InScatteredIsEquationTwenty) {
    LightTerms L = OneBlob();
    Vec3 c = At(L, 10, 20, 4);
    EXPECT_EQ(c[0], 0.125f + 1.5f);
    EXPECT_EQ(c[1], 0.25f + 0.75f);
    EXPECT_EQ(c[2], 0.5f + 0.375f);
    c = At(L, 14, 20, 4);
    const double expected = 1.5 * std::exp(-0.5);
    EXPECT_NEAR(c[0], 0.125 + expected, 4e-7);
    EXPECT_NEAR(c[2], 0.5 + 0.25 * expected, 4e-7);
    for (float z : {8.0f, 9.5f, 40.0f}) {
        c = At(L, 10, 20, z);
        EXPECT_EQ(c, (Vec3{0.125f, 0.25f, 0.5f})) << "z " << z;
    }
    c = At(L, 10, 20, 0);
    EXPECT_EQ(c[0], 0.125f + 3.0f);
    // Below the base (a camera under the clouds sees no sample there, but the clamp holds): the whole strength.
    EXPECT_EQ(At(L, 10, 20, -3)[0], 0.125f + 3.0f);
    L.glowBlobCount = 2;
    L.glowBlobs[1] = {14, 20, 1.0f / 8.0f, 1};  // sigma 2 voxels, centred one sigma of the first blob out
    c = At(L, 14, 20, 0);
    EXPECT_NEAR(c[0], 0.125 + 3 * std::exp(-0.5) + 1, 1e-6);
    // Off: nothing added, bit for bit.
    L.glowOn = false;
    EXPECT_EQ(At(L, 10, 20, 0), (Vec3{0.125f, 0.25f, 0.5f}));
}

// Test MakeLightTerms' voxel units by hand: origin (-1000, 500, 200), h = 50, nz = 8; a blob at world (500, 1500),
// radius 100 m is (30, 20) voxel units with k = 50^2 / (2 100^2) = 0.125; 1 / nz = 0.125.
TEST(CityGlow, TermsInVoxelUnits) {
    const std::string glow =
        R"({"color": [2, 1, 0.5], "fade": 3, "blobs": [{"center": [500, 1500], "radius": 100, "strength": 4},
                                                     {"center": [-1000, 500]}]})";
    auto scene =
        LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
                  {{"grid.origin", "[-1000, 500, 200]"}, {"grid.size", "[64, 64, 8]"}, {"lighting.city_glow", glow}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const LightTerms L = MakeLightTerms(*scene, 0);
    EXPECT_TRUE(L.glowOn);
    EXPECT_EQ(L.glowColor, (Vec3{2, 1, 0.5f}));
    EXPECT_EQ(L.glowFade, 3.0f);
    EXPECT_EQ(L.glowInvThickness, 0.125f);
    ASSERT_EQ(L.glowBlobCount, 2u);
    EXPECT_EQ(L.glowBlobs[0], (std::array<float, 4>{30, 20, 0.125f, 4}));
    // The defaults: radius 1000 m (k = 50^2 / (2 1000^2) = 0.00125), strength 1.
    EXPECT_EQ(L.glowBlobs[1], (std::array<float, 4>{0, 0, 0.00125f, 1}));
    EXPECT_FALSE(MakeLightTerms(*LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json"), 0).glowOn);
}

// The sum of camera 0's image of `scene` on the CPU after `steps` steps, with `overrides`.
double ImageSum(const std::string& scene, Resource image, uint32_t steps, std::vector<SceneOverride> overrides) {
    overrides.push_back({"steps", std::to_string(steps)});
    overrides.push_back({"warmup_steps", "0"});
    auto loaded = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + scene + ".json", overrides);
    EXPECT_TRUE(loaded.has_value()) << loaded.error().message;
    if (!loaded) return 0;
    cpu::BackendCpu backend;
    auto sim = Simulation::Create(*loaded, backend, /*everyStepOutputs=*/true);
    EXPECT_TRUE(sim.has_value()) << sim.error().message;
    if (!sim) return 0;
    for (uint32_t t = 0; t < loaded->steps; ++t) {
        StepRecord r;
        Status s = (*sim)->Step(r);
        EXPECT_TRUE(s.has_value()) << s.error().message;
        if (!s) return 0;
    }
    const Buffer* buffer = (*sim)->Get(image);
    EXPECT_NE(buffer, nullptr) << scene;
    if (!buffer) return 0;
    double sum = 0;
    for (float v : test::Read<float>(backend, *buffer)) sum += v;
    return sum;
}

// Test that every renderer takes the glow through InScattered: a splat (ci-small), a march (noise-layer) and a
// layers (layers-small) image brighten with it, and are the same bit for bit when the fade leaves none of it at
// any sample (fade 1e6: gone a millionth of the thickness above the base).
TEST(CityGlow, EveryRendererTakesIt) {
    const std::pair<const char*, Resource> cases[] = {{"ci-small", Resource::SplatImage},
                                                      {"noise-layer", Resource::MarchImage},
                                                      {"layers-small", Resource::LayersImage}};
    const std::string blob = R"("blobs": [{"center": [1600, 1600], "radius": 1000, "strength": 2}])";
    for (const auto& [scene, image] : cases) {
        const double plain = ImageSum(scene, image, 6, {});
        const double lit = ImageSum(scene, image, 6, {{"lighting.city_glow", "{" + blob + "}"}});
        const double faded = ImageSum(scene, image, 6, {{"lighting.city_glow", R"({"fade": 1e6, )" + blob + "}"}});
        EXPECT_GT(lit, plain * (1 + 1e-4)) << scene << ": without " << plain << ", with the glow " << lit;
        EXPECT_EQ(faded, plain) << scene;
    }
}

// Test that each setting is checked, naming the field.
TEST(CityGlow, SettingsAreChecked) {
    const std::pair<const char*, const char*> cases[] = {
        {"{}", "lighting.city_glow.blobs: required field is missing"},
        {R"({"blobs": []})", "lighting.city_glow.blobs: expected an array of 1 to 4"},
        {R"({"blobs": [{"center": [0, 0]}, {"center": [0, 0]}, {"center": [0, 0]}, {"center": [0, 0]},
                      {"center": [0, 0]}]})",
         "lighting.city_glow.blobs: expected an array of 1 to 4"},
        {R"({"blobs": [{"radius": 5}]})", "lighting.city_glow.blobs[0].center: required field is missing"},
        {R"({"blobs": [{"center": [0, 0], "radius": 0}]})", "lighting.city_glow.blobs[0].radius"},
        {R"({"blobs": [{"center": [0, 0], "strength": -1}]})", "lighting.city_glow.blobs[0].strength"},
        {R"({"blobs": [{"center": [0, 0], "sigma": 3}]})", "lighting.city_glow.blobs[0].sigma: unknown field"},
        {R"({"color": [1, 2e6, 0], "blobs": [{"center": [0, 0]}]})", "lighting.city_glow.color[1]"},
        {R"({"fade": -0.5, "blobs": [{"center": [0, 0]}]})", "lighting.city_glow.fade"},
    };
    for (const auto& [value, message] : cases) {
        auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", {{"lighting.city_glow", value}});
        ASSERT_FALSE(scene.has_value()) << value;
        EXPECT_NE(scene.error().message.find(message), std::string::npos) << scene.error().message;
    }
}

}  // namespace
}  // namespace cb
