// The sky light (Wang, Ji and Zhang, section 3.3; lighting.sky and the stage shade_sky): the term InScattered adds
// worked by hand, its terms and settings from a scene, shade_sky as shade's sweep toward the sky (and between two
// shares of the sun's sweep, which it leaves alone), and on every
// backend and renderer two properties that owe nothing to the code under test: a sky light standing where the sun
// stood, with the sun's radiance and the sun dark, lights the clouds as the sun did; and light adds up (the image
// with both lights is the sun's image plus the sky's alone). The GLSL twins are GlslTwin.InScatteredMatchesTheCpp,
// GlslTwin.MakeSplatMatchesTheCpp and the march's and the layers' twins (their random setups light the sky).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/math/Light.h"
#include "core/pipeline/LightTerms.h"
#include "core/pipeline/ShadePlan.h"
#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
#include "core/stages/render_march/RenderMarch.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "reference/MarchReference.h"
#include "tests/BackendTestUtil.h"
#include "tests/MarchTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// Test the term by hand: with the sun dark, a sample's light is the ambient plus sky * skyGain, in dyadic numbers
// that every step keeps exact; off, the ambient bit for bit, whatever skyGain says.
TEST(SkyLight, InScatteredAddsSkyRadianceTimesItsGain) {
    LightTerms L;
    L.sunRadiance = {0, 0, 0};
    L.ambient = {0.125f, 0.25f, 0.5f};
    L.skyOn = true;
    L.skyRadiance = {1.0f, 0.5f, 0.25f};
    const LightSample s{0.75f, 0.5f, 1, {3, 4, 5}, {0, 0, 1}, 0.5f};
    EXPECT_EQ(InScattered(L, s), (Vec3{0.625f, 0.5f, 0.625f}));
    L.sunRadiance = {2, 2, 2};  // the sun's gain 0.75 adds 1.5 to each channel
    EXPECT_EQ(InScattered(L, s), (Vec3{2.125f, 2.0f, 2.125f}));
    L.skyOn = false;
    EXPECT_EQ(InScattered(L, s), (Vec3{1.625f, 1.75f, 2.0f}));
}

// Test SkyPhase against Henyey-Greenstein's closed form (1 - g^2) / (1 + g^2 - 2 g cos)^(3/2) at the sky's own
// direction, square to it and opposite it, and that it is 0 with the sky light off.
TEST(SkyLight, SkyPhaseIsThePhaseAtTheAngleToTheSkyLight) {
    LightTerms L;
    L.skyOn = true;
    L.skyDirection = {0.6f, 0.0f, 0.8f};
    L.phase = {PhaseKind::HenyeyGreenstein, 0.5f};
    auto hg = [](double c) { return 0.75 / std::pow(1.25 - c, 1.5); };
    EXPECT_NEAR(SkyPhase(L, {0.6f, 0.0f, 0.8f}), hg(1), 1e-5 * hg(1));  // 0.75 / 0.125 = 6
    EXPECT_NEAR(SkyPhase(L, {0.0f, 1.0f, 0.0f}), hg(0), 1e-6);          // 0.75 / 1.25^1.5
    EXPECT_NEAR(SkyPhase(L, {-0.6f, 0.0f, -0.8f}), hg(-1), 1e-6);       // 0.75 / 2.25^1.5 = 2/9
    L.phase = {PhaseKind::None, 0};
    EXPECT_EQ(SkyPhase(L, {0.0f, 1.0f, 0.0f}), 1.0f);
    L.skyOn = false;
    EXPECT_EQ(SkyPhase(L, {0.6f, 0.0f, 0.8f}), 0.0f);
}

Result<Scene> LoadCiScene(const std::string& name, const std::vector<SceneOverride>& overrides) {
    return LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + name + ".json", overrides);
}

// Test the terms a scene gives: colour times intensity, the direction of (elevation, azimuth) as the sun's, the
// defaults, and off without the section.
TEST(SkyLight, TermsFromTheScene) {
    const std::vector<SceneOverride> sky = {
        {"stages", R"(["noise", "shade", "shade_sky", "render_layers"])"},
        {"lighting.sky", R"({"elevation_deg": 12, "azimuth_deg": 250, "color": [1, 0.5, 0.25], "intensity": 4})"}};
    auto scene = LoadCiScene("layers-small", sky);
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const LightTerms L = MakeLightTerms(*scene, 0);
    EXPECT_TRUE(L.skyOn);
    EXPECT_EQ(L.skyRadiance, (Vec3{4, 2, 1}));
    SunSettings sun;
    sun.elevationDeg = 12;
    sun.azimuthDeg = 250;
    EXPECT_EQ(L.skyDirection, sun.Direction());
    auto defaults = LoadCiScene("layers-small", {sky[0], {"lighting.sky", "{}"}});
    ASSERT_TRUE(defaults.has_value()) << defaults.error().message;
    EXPECT_EQ(defaults->lighting.sky.elevationDeg, 20);
    EXPECT_EQ(defaults->lighting.sky.azimuthDeg, 0);
    EXPECT_FALSE(MakeLightTerms(*LoadCiScene("layers-small", {}), 0).skyOn);
}

// Test that each setting is checked, naming the field, and that the light and its stage come together.
TEST(SkyLight, SettingsAreChecked) {
    const SceneOverride stages{"stages", R"(["noise", "shade", "shade_sky", "render_layers"])"};
    const std::pair<const char*, const char*> cases[] = {
        {R"({"elevation_deg": 0})", "lighting.sky.elevation_deg: the sky light shines from above the horizon"},
        {R"({"elevation_deg": -5})", "lighting.sky.elevation_deg: the sky light shines from above the horizon"},
        {R"({"elevation_deg": 90.5})", "lighting.sky.elevation_deg: must be in (0, 90]"},
        {R"({"azimuth_deg": 400})", "lighting.sky.azimuth_deg: must be in [-360, 360]"},
        {R"({"color": [1, -1, 0]})", "lighting.sky.color[1]"},
        {R"({"color": [1e20, 1, 1], "intensity": 1e20})", "lighting.sky.intensity: color * intensity"},
        {R"({"elevation": 10})", "lighting.sky.elevation: unknown field"},
        {R"([10, 20])", "lighting.sky"},
    };
    for (const auto& [value, message] : cases) {
        auto scene = LoadCiScene("layers-small", {stages, {"lighting.sky", value}});
        ASSERT_FALSE(scene.has_value()) << value;
        EXPECT_NE(scene.error().message.find(message), std::string::npos) << scene.error().message;
    }
    auto noStage = LoadCiScene("layers-small", {{"lighting.sky", "{}"}});
    ASSERT_FALSE(noStage.has_value());
    EXPECT_NE(noStage.error().message.find("lighting.sky: needs the stage \"shade_sky\""), std::string::npos)
        << noStage.error().message;
    auto noLight = LoadCiScene("layers-small", {stages});
    ASSERT_FALSE(noLight.has_value());
    EXPECT_NE(noLight.error().message.find("stages: \"shade_sky\" shades toward the sky light, and the scene has none"),
              std::string::npos)
        << noLight.error().message;
}

// A scene's buffers after its last step on a backend (nullopt when the backend cannot start here).
struct SceneRun {
    std::unique_ptr<Backend> backend;
    std::unique_ptr<Simulation> sim;
    std::vector<float> Read(Resource r, size_t camera = 0) const {
        const Buffer* b = sim->Get(r, camera);
        EXPECT_NE(b, nullptr) << ResourceName(r);
        return b ? test::Read<float>(*backend, *b) : std::vector<float>{};
    }
};
std::optional<SceneRun> RunScene(const std::string& backendName, const std::string& name,
                                 std::vector<SceneOverride> overrides) {
    overrides.push_back({"warmup_steps", "0"});
    auto scene = LoadCiScene(name, overrides);
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    if (!scene) return std::nullopt;
    auto backend = test::MakeTestBackend(backendName);
    if (!backend) return std::nullopt;
    SceneRun run{std::move(*backend), nullptr};
    auto sim = Simulation::Create(*scene, *run.backend, /*everyStepOutputs=*/true);
    EXPECT_TRUE(sim.has_value()) << sim.error().message;
    if (!sim) return std::nullopt;
    run.sim = std::move(*sim);
    for (uint32_t t = 0; t < scene->steps; ++t) {
        StepRecord r;
        Status s = run.sim->Step(r);
        EXPECT_TRUE(s.has_value()) << s.error().message;
        if (!s) return std::nullopt;
    }
    test::ExpectNoValidationMessages(run.backend.get());
    return run;
}

// Test shade_sky as shade's sweep toward the sky light: its T_sky is, bit for bit, the T that shade makes with the
// sun where the sky light stands, at every resolution; and it differs from the sun's own T.
TEST(SkyLight, ShadeSkyIsShadeTowardTheSkyLight) {
    for (const char* resolution : {"1", "2"}) {
        const std::vector<SceneOverride> withSky = {{"stages", R"(["noise", "shade", "shade_sky"])"},
                                                    {"shade.resolution", resolution},
                                                    {"lighting.sky", R"({"elevation_deg": 15, "azimuth_deg": 200})"}};
        auto lit = RunScene("cpu", "layers-small", withSky);
        auto moved = RunScene("cpu", "layers-small",
                              {{"stages", R"(["noise", "shade"])"},
                               {"shade.resolution", resolution},
                               {"sun", R"({"elevation_deg": 15, "azimuth_deg": 200})"}});
        ASSERT_TRUE(lit && moved);
        const std::vector<float> skyT = lit->Read(Resource::TSky);
        EXPECT_EQ(skyT, moved->Read(Resource::T)) << "resolution " << resolution;
        EXPECT_NE(skyT, lit->Read(Resource::T)) << "resolution " << resolution;
    }
}

// The image of camera 0 of `name` on a backend, as the scene stands after `overrides` (empty when the backend
// cannot start here).
std::vector<float> CameraImage(const std::string& backend, const std::string& name, Resource image,
                               const std::vector<SceneOverride>& overrides) {
    auto run = RunScene(backend, name, overrides);
    return run ? run->Read(image) : std::vector<float>{};
}

// The renderers, each on a small scene it runs: the splats on the automaton's ci-small (six steps), the march and
// the layers on layers-small's tiled noise.
struct RendererCase {
    const char* stage;
    const char* scene;
    Resource image;
    std::vector<SceneOverride> base;
};
std::vector<RendererCase> RendererCases() {
    return {{"render_splat",
             "ci-small",
             Resource::SplatImage,
             {{"steps", "6"},
              {"stages", R"(["region", "ca", "smooth", "density", "shade", "shade_sky", "render_splat"])"}}},
            {"render_march",
             "layers-small",
             Resource::MarchImage,
             {{"stages", R"(["noise", "shade", "shade_sky", "render_march"])"}}},
            {"render_layers",
             "layers-small",
             Resource::LayersImage,
             {{"stages", R"(["noise", "shade", "shade_sky", "render_layers"])"}}}};
}

float WorstDifference(const std::vector<float>& a, const std::vector<float>& b) {
    float worst = 0;
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) worst = std::max(worst, std::fabs(a[i] - b[i]));
    return worst;
}

// Test, on every backend and renderer, that a sky light standing where the sun stands, with the sun's colour and
// intensity, lights as the sun does once the sun is dark (and turned elsewhere): the two scenes' samples differ
// only in which term carries the same product, and float addition commutes, so the march and the layers agree bit
// for bit; the splats form the sky's angle from the unit direction and the sun's from the offset, a rounding
// apart. The sky's T_sky is then shade's T at the sun (SkyLight.ShadeSkyIsShadeTowardTheSkyLight).
TEST(SkyLight, ASkyLightWhereTheSunStandsLightsAsTheSun) {
    const std::string place = R"("elevation_deg": 28, "azimuth_deg": 75, "color": [1, 0.8, 0.6], "intensity": 1.5)";
    for (const std::string& backend : test::TestBackends())
        for (RendererCase c : RendererCases()) {
            std::vector<SceneOverride> sunLit = c.base, skyLit = c.base;
            sunLit.push_back({"sun", "{" + place + "}"});
            // The sun needs a sky light to run shade_sky: one with no light at all.
            sunLit.push_back({"lighting.sky", R"({"intensity": 0})"});
            skyLit.push_back({"sun", R"({"elevation_deg": 60, "azimuth_deg": 300, "intensity": 0})"});
            skyLit.push_back({"lighting.sky", "{" + place + "}"});
            const std::vector<float> a = CameraImage(backend, c.scene, c.image, sunLit);
            if (a.empty()) continue;  // the backend cannot start here
            const std::vector<float> b = CameraImage(backend, c.scene, c.image, skyLit);
            ASSERT_EQ(a.size(), b.size()) << backend << " " << c.stage;
            const bool exact = std::string(c.stage) != "render_splat";
            if (exact && backend == "cpu")
                EXPECT_EQ(a, b) << backend << " " << c.stage;
            else
                EXPECT_LE(WorstDifference(a, b), 1e-5f) << backend << " " << c.stage;
            // And the dark sun of skyLit alone gives only the ambient light: not the same image.
            std::vector<SceneOverride> dark = c.base;
            dark.push_back({"sun", R"({"intensity": 0})"});
            dark.push_back({"lighting.sky", R"({"intensity": 0})"});
            EXPECT_GT(WorstDifference(a, CameraImage(backend, c.scene, c.image, dark)), 0.01f)
                << backend << " " << c.stage;
        }
}

// Test that light adds up on every backend and renderer: every renderer's pixel is a sum of weights (independent
// of the light) times each sample's light, so the image with the sun and the sky light is the image with the sun
// alone plus the image with the sky light alone, no ambient light and a black background, to float rounding.
TEST(SkyLight, LightAddsUp) {
    const std::string sky = R"("elevation_deg": 8, "azimuth_deg": 210, "color": [1, 0.45, 0.2], "intensity": 2)";
    for (const std::string& backend : test::TestBackends())
        for (RendererCase c : RendererCases()) {
            std::vector<SceneOverride> both = c.base, sunOnly = c.base, skyOnly = c.base;
            both.push_back({"lighting.sky", "{" + sky + "}"});
            sunOnly.push_back({"lighting.sky", R"({"intensity": 0})"});
            skyOnly.push_back({"lighting.sky", "{" + sky + "}"});
            skyOnly.push_back({"sun", R"({"intensity": 0})"});
            skyOnly.push_back({"lighting.ambient", "[0, 0, 0]"});
            skyOnly.push_back({"lighting.background", "[0, 0, 0]"});
            const std::vector<float> sum = CameraImage(backend, c.scene, c.image, both);
            if (sum.empty()) continue;
            const std::vector<float> a = CameraImage(backend, c.scene, c.image, sunOnly);
            const std::vector<float> b = CameraImage(backend, c.scene, c.image, skyOnly);
            ASSERT_EQ(sum.size(), a.size());
            ASSERT_EQ(sum.size(), b.size());
            double worst = 0, skyTotal = 0;
            for (size_t i = 0; i < sum.size(); ++i) {
                worst = std::max(worst, std::fabs(double(sum[i]) - (double(a[i]) + b[i])) / (1 + std::fabs(sum[i])));
                skyTotal += b[i];
            }
            EXPECT_LE(worst, 1e-5) << backend << " " << c.stage;
            EXPECT_GT(skyTotal, 1e-3 * double(sum.size())) << backend << " " << c.stage << ": the sky lit nothing";
        }
}

// Test the exact reference render alike: its sky light where the sun stood, the sun dark, renders the sun's image
// bit for bit (the exact depth toward either is the same integral).
TEST(SkyLight, ReferenceSkyLightWhereTheSunStandsLightsAsTheSun) {
    auto scene = LoadCiScene("layers-small", {{"stages", R"(["noise", "shade", "shade_sky", "render_march"])"},
                                              {"render.width", "32"},
                                              {"render.height", "24"},
                                              {"lighting.sky", "{}"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const Extent3 e = scene->grid.size;
    std::vector<float> q(e.Count());
    for (size_t v = 0; v < q.size(); ++v) q[v] = float((v * 2654435761u) % 1000) / 1000.0f * float(v % 3 == 0);
    MarchParams sunLit = MakeMarchParams(*scene, scene->render.cameras[0], 0);
    sunLit.setup.light.skyOn = false;
    MarchParams skyLit = sunLit;
    skyLit.setup.light.skyOn = true;
    skyLit.setup.light.skyDirection = sunLit.setup.sun;
    skyLit.setup.light.skyRadiance = sunLit.setup.light.sunRadiance;
    skyLit.setup.light.sunRadiance = {0, 0, 0};
    skyLit.setup.sun = {0, 0, 1};
    ref::MarchReferenceOptions o;
    o.stepVoxels = 0.5f;
    o.threads = 2;
    auto a = ref::RenderMarchReference(sunLit, e, q, q, o);
    auto b = ref::RenderMarchReference(skyLit, e, q, q, o);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->image, b->image);
    EXPECT_EQ(b->light.rays, 2 * a->light.rays);  // the sun's exact light is traced still, then the sky's
}

// Test on every backend that shade's sweep in shares of 3 slices with a whole shade_sky between each two gives the
// sun's T of the whole call, at every resolution (at 2 and 4 a share hands the next its coarse grids), and each T_sky
// the sky light's whole call: shade_sky sweeps on a stage object of its own. (ShadeBlockVk's test adds Vulkan's
// batches and sweep forms.)
TEST(SkyLight, ShadeSkyBetweenSharesLeavesTheSunsSweep) {
    const Extent3 e{29, 23, 17};
    for (const std::string& name : test::TestBackends()) {
        auto made = test::MakeTestBackend(name);
        if (!made) continue;  // the backend cannot start here
        Backend& backend = **made;
        auto q = test::MakeFilled(backend, BufferFormat::F32, e,
                                  test::GaussianBlobField(e, {{9, 8, 6, 4}, {20, 15, 11, 5}, {14, 4, 9, 3}}));
        for (int resolution : {1, 2, 4}) {
            const std::string what = name + " resolution " + std::to_string(resolution);
            ShadeParams sun;
            sun.sun = {0.36f, -0.48f, 0.8f};
            sun.resolution = resolution;
            ShadeParams sky = sun;
            sky.sun = {-0.6f, 0.0f, 0.8f};
            auto whole = test::MakeBuffer(backend, BufferFormat::F32, e);
            auto skyWhole = test::MakeBuffer(backend, BufferFormat::F32, e);
            ASSERT_TRUE(backend.Shade(sun, *q, *whole)) << what;
            ASSERT_TRUE(backend.Shade(sky, *q, *skyWhole)) << what;
            const auto wholeT = test::Read<float>(backend, *whole), skyT = test::Read<float>(backend, *skyWhole);
            ASSERT_NE(wholeT, skyT) << "the two lights must shade differently for the test to see a mix-up";
            auto shared = test::MakeBuffer(backend, BufferFormat::F32, e);
            auto skyShared = test::MakeBuffer(backend, BufferFormat::F32, e);
            const uint32_t nw = MakeShadePlan(sun, e).nw;
            for (uint32_t m = 0; m < nw; m += 3) {
                ShadeParams share = sun;
                share.slices = {m, m + 3};
                ASSERT_TRUE(backend.Shade(share, *q, *shared)) << what;
                ASSERT_TRUE(backend.ShadeSky(sky, *q, *skyShared)) << what;
                EXPECT_EQ(test::Read<float>(backend, *skyShared), skyT) << what << ", share at " << m;
            }
            EXPECT_EQ(test::Read<float>(backend, *shared), wholeT) << what;
        }
        test::ExpectNoValidationMessages(&backend);
    }
}

}  // namespace
}  // namespace cb
