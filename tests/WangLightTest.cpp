// Wang, Ji and Zhang's light terms: city glow (eq. 20; lighting.city_glow) and eye scattering (eq. 17;
// lighting.eye_scattering). For each, the term InScattered adds against its closed form worked by hand, its terms
// from a scene, every renderer taking it on the CPU, and its settings' checks. The GLSL twin is
// GlslTwin.InScatteredMatchesTheCpp; the backends' agreement is Cli.ConformWangLight.*.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "core/math/Light.h"
#include "core/pipeline/LightTerms.h"
#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
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
    L.invThickness = 1.0f / 16.0f;
    L.glowBlobCount = 1;
    L.glowBlobs[0] = {10, 20, 1.0f / 32.0f, 3};
    return L;
}

Vec3 At(const LightTerms& L, float x, float y, float z) {
    return InScattered(L, LightSample{0, 0, 1, {x, y, z}, {0, 0, 1}});
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
    EXPECT_EQ(L.invThickness, 0.125f);
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

// Eye scattering, by hand: the sun (2, 1, 0.5) straight up, a 60-degree cone (cos 0.5), I_e0 = 3, f_e = 1, nz = 16,
// the sun's transmittance 0.5 and no sun gain or ambient, so that c is the term alone.
LightTerms EyeOnly() {
    LightTerms L;
    L.sunRadiance = {2, 1, 0.5f};
    L.ambient = {0, 0, 0};
    L.invThickness = 1.0f / 16.0f;
    L.eyeOn = true;
    L.sunDirection = {0, 0, 1};
    L.eyeIntensity = 3;
    L.eyeCosCone = 0.5f;
    L.eyeInvOneMinusCos = 2;
    L.eyeHeightGain = 1;
    return L;
}

Vec3 Eye(const LightTerms& L, float sunT, float z, Vec3 dir) {
    return InScattered(L, LightSample{0, sunT, 1, {5, 5, z}, dir});
}

// Test the term against eq. 17 by hand: looking at the sun, a quarter of the thickness up,
// I_e = 3 * 1 * (1 * 0.25 + 1) = 3.75 and c = sun * 0.5 * 3.75; half the cone's cosine away ((1 - 0.5) / 2 = 0.25
// of the way from its edge: cos 0.75) a quarter of it; at the cone's edge and beyond, none; at the top twice and
// below the base once the intensity; with no sunlight reaching the sample (T = 0), none.
TEST(EyeScattering, InScatteredIsEquationSeventeen) {
    const LightTerms L = EyeOnly();
    EXPECT_EQ(Eye(L, 0.5f, 4, {0, 0, 1}), (Vec3{3.75f, 1.875f, 0.9375f}));
    const float s = std::sqrt(1.0f - 0.75f * 0.75f);
    const Vec3 c = Eye(L, 0.5f, 4, {s, 0, 0.75f});  // cone (0.75 - 0.5) * 2 = 0.5
    EXPECT_EQ(c, (Vec3{1.875f, 0.9375f, 0.46875f}));
    EXPECT_EQ(Eye(L, 0.5f, 4, {std::sqrt(0.75f), 0, 0.5f}), (Vec3{0, 0, 0}));
    EXPECT_EQ(Eye(L, 0.5f, 4, {1, 0, 0}), (Vec3{0, 0, 0}));
    EXPECT_EQ(Eye(L, 0.5f, 4, {0, 0, -1}), (Vec3{0, 0, 0}));
    EXPECT_EQ(Eye(L, 0.5f, 16, {0, 0, 1}), (Vec3{6, 3, 1.5f}));
    EXPECT_EQ(Eye(L, 0.5f, 40, {0, 0, 1}), (Vec3{6, 3, 1.5f}));
    EXPECT_EQ(Eye(L, 0.5f, -2, {0, 0, 1}), (Vec3{3, 1.5f, 0.75f}));
    EXPECT_EQ(Eye(L, 0, 4, {0, 0, 1}), (Vec3{0, 0, 0}));
    LightTerms off = L;
    off.eyeOn = false;
    EXPECT_EQ(Eye(off, 0.5f, 4, {0, 0, 1}), (Vec3{0, 0, 0}));
}

// Test the terms a scene gives: the sun's direction at the step, cos and 1 / (1 - cos) of the cone, I_e0 and f_e.
TEST(EyeScattering, TermsFromTheScene) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
                           {{"lighting.eye_scattering", R"({"intensity": 2, "cone_deg": 60, "height_gain": 0.5})"},
                            {"sun.elevation_deg", "30"},
                            {"sun.azimuth_deg", "90"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const LightTerms L = MakeLightTerms(*scene, 3);
    EXPECT_TRUE(L.eyeOn);
    EXPECT_EQ(L.sunDirection, scene->sun.DirectionAt(3));
    EXPECT_NEAR(L.sunDirection[1], std::cos(std::numbers::pi / 6), 1e-6);  // azimuth 90: toward +y, elevation 30
    EXPECT_NEAR(L.sunDirection[2], 0.5, 1e-6);
    EXPECT_FLOAT_EQ(L.eyeCosCone, 0.5f);
    EXPECT_FLOAT_EQ(L.eyeInvOneMinusCos, 2.0f);
    EXPECT_EQ(L.eyeIntensity, 2.0f);
    EXPECT_EQ(L.eyeHeightGain, 0.5f);
    EXPECT_EQ(L.phase.kind, scene->phase.kind);  // the scene's phase function: replaces_phase is off
    // The defaults: I_e0 1, a 10-degree cone, f_e 0.
    auto plain = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", {{"lighting.eye_scattering", "{}"}});
    ASSERT_TRUE(plain.has_value()) << plain.error().message;
    const LightTerms D = MakeLightTerms(*plain, 0);
    EXPECT_EQ(D.eyeIntensity, 1.0f);
    EXPECT_FLOAT_EQ(D.eyeCosCone, float(std::cos(10 * std::numbers::pi / 180)));
    EXPECT_EQ(D.eyeHeightGain, 0.0f);
}

// Test Wang's model: with replaces_phase the renderers' light has no phase function, while the exact reference keeps
// the scene's (Cornette-Shanks here) and leaves eye scattering out, which is what its error measures.
TEST(EyeScattering, ReplacesPhaseInTheRenderersNotTheReference) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/noise-layer.json",
                           {{"phase.function", "cornette-shanks"},
                            {"lighting.eye_scattering", R"({"cone_deg": 20, "replaces_phase": true})"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const LightTerms L = MakeLightTerms(*scene, 0);
    EXPECT_TRUE(L.eyeOn);
    EXPECT_EQ(L.phase.kind, PhaseKind::None);
    const RendererDescriptor& march = *Describe(Stage::RenderMarch).renderer;
    ASSERT_TRUE(march.referenceParams);
    const MarchParams reference = march.referenceParams(*scene, scene->render.cameras[0], 0);
    EXPECT_FALSE(reference.setup.light.eyeOn);
    EXPECT_EQ(reference.setup.light.phase.kind, PhaseKind::CornetteShanks);
    EXPECT_TRUE(FieldsListed(march.referenceIgnores, "lighting.eye_scattering.cone_deg"));
}

// Test that every renderer takes eye scattering through InScattered: with a cone of 180 degrees every lit sample
// not facing straight away from the sun gains light, so each image brightens; with I_e0 = 0 the images are the
// same bit for bit.
TEST(EyeScattering, EveryRendererTakesIt) {
    const std::pair<const char*, Resource> cases[] = {{"ci-small", Resource::SplatImage},
                                                      {"noise-layer", Resource::MarchImage},
                                                      {"layers-small", Resource::LayersImage}};
    for (const auto& [scene, image] : cases) {
        const double plain = ImageSum(scene, image, 6, {});
        const double lit = ImageSum(scene, image, 6, {{"lighting.eye_scattering", R"({"cone_deg": 180})"}});
        const double none = ImageSum(scene, image, 6, {{"lighting.eye_scattering", R"({"intensity": 0})"}});
        EXPECT_GT(lit, plain * (1 + 1e-4)) << scene << ": without " << plain << ", with eye scattering " << lit;
        EXPECT_EQ(none, plain) << scene;
    }
}

// Test that each setting is checked, naming the field.
TEST(EyeScattering, SettingsAreChecked) {
    const std::pair<const char*, const char*> cases[] = {
        {R"({"cone_deg": 0})", "lighting.eye_scattering.cone_deg"},
        {R"({"cone_deg": 181})", "lighting.eye_scattering.cone_deg"},
        {R"({"intensity": 2000})", "lighting.eye_scattering.intensity"},
        {R"({"height_gain": -1})", "lighting.eye_scattering.height_gain"},
        {R"({"phi": 5})", "lighting.eye_scattering.phi: unknown field"},
        {"[]", "lighting.eye_scattering: expected an object"},
    };
    for (const auto& [value, message] : cases) {
        auto scene =
            LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", {{"lighting.eye_scattering", value}});
        ASSERT_FALSE(scene.has_value()) << value;
        EXPECT_NE(scene.error().message.find(message), std::string::npos) << scene.error().message;
    }
}

}  // namespace
}  // namespace cb
