// Finite outputs at the load-time bounds (SPEC 12's "no stage may return NaN or Inf for any valid input";
// docs/pipeline.md, "Finite outputs"): the phase function's peak, the sun's, the sky light's and the lightning's
// radiance (at the guard radius too), the lightning's distance in voxel edges, ambient and background, the sun's
// azimuth (fixed, on a path, at a speed) and the optical depth with forward scattering. Each extreme runs just inside
// its bound on every backend with every output on every step, and every array it writes (T, G, the images of every
// camera, ...) must be finite and in range; just past each bound the scene is refused with file, field, bound and
// value.
#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/math/Shading.h"
#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
#include "core/scene/SceneNames.h"
#include "harness/run/Simulation.h"
#include "tests/BackendTestUtil.h"
#include "tests/SceneTestUtil.h"
#include "tests/Spec12Checks.h"
#include "tests/Spec12Outputs.h"
#include "tests/TestUtil.h"

namespace cb::spec12_test {
namespace {

// The bounds as docs/scenes.md states them.
constexpr float kPeakBound = 262144.0f;    // phase: P^max <= 2^18
constexpr double kRadianceBound = 1e30;    // sun and lightning radiance, at the guard radius too
constexpr double kLightEdgesBound = 1e18;  // |lightning.position - grid.origin| / grid.voxel_size
constexpr double kAzimuthBound = 1e9;      // |azimuth| in degrees
// What docs/pipeline.md derives from them: every P^ a stage evaluates is at most 2^19.5, a sample's light at most
// 1.5e36, a pixel at most 6 times that plus the background (or the ground, 2e30).
constexpr double kPixelBound = 6 * 1.5e36 + 2e30;

// The largest float g in (0, 1) whose peak, as the stages evaluate it, is within the bound (the peak is not
// monotone in g near 1, so this scans down from the float below 1).
float LargestAcceptedG(PhaseKind kind) {
    float g = std::nextafter(1.0f, 0.0f);
    while (!(PhasePeak({kind, g}) <= kPeakBound)) g = std::nextafter(g, 0.0f);
    return g;
}

// s toward the sun of elevation 25, azimuth 60 (ci-small's sun), in double.
struct D3 {
    double x, y, z;
};
const D3 kSun{std::cos(25 * kDeg) * std::cos(60 * kDeg), std::cos(25 * kDeg) * std::sin(60 * kDeg),
              std::sin(25 * kDeg)};
// The volume: 32 x 32 x 8 voxels of 1 m from the origin; the target is the centre of voxel (16, 16, 4).
const D3 kTarget{16.5, 16.5, 4.5};

std::string Vec(const D3& v) { return "[" + Num(v.x) + ", " + Num(v.y) + ", " + Num(v.z) + "]"; }
D3 Along(const D3& p, const D3& d, double t) { return {p.x + d.x * t, p.y + d.y * t, p.z + d.z * t}; }

// Cameras: "sunward" looks from 20 m on the night side straight toward the sun through the target (its centre
// pixel's ray and the target's splat see cos theta ~ 1, the phase peak), "antisunward" the other way (cos ~ -1),
// "above" at the ground and the cloud from above. Odd image sizes put a pixel centre on each axis.
std::string Cameras() {
    const D3 sunwardEye = Along(kTarget, kSun, -20), antiEye = Along(kTarget, kSun, 20);
    return "[{\"name\": \"sunward\", \"eye\": " + Vec(sunwardEye) + ", \"target\": " + Vec(kTarget) +
           ", \"near\": 0.5, \"far\": 1000}, {\"name\": \"antisunward\", \"eye\": " + Vec(antiEye) +
           ", \"target\": " + Vec(kTarget) +
           ", \"near\": 0.5, \"far\": 1000}, {\"name\": \"above\", \"eye\": [16, -20, 40], " +
           "\"target\": [16, 12, 0], \"near\": 0.5, \"far\": 1000}]";
}

// A full volume (Spec12Checks FullVolume) of thin cloud lit by the brightest sun, ambient and background the bounds
// allow, the ground white, forward scattering at its largest, both renderers.
std::vector<SceneOverride> LitFullVolume(bool splat = true) {
    const std::string stages = std::string("[\"region\", \"ca\", \"smooth\", \"density\", \"shade\", \"shadow\", ") +
                               (splat ? "\"render_splat\", " : "") + "\"render_march\"]";
    return Plus(FullVolume(),
                {{"steps", std::to_string(kSteps)},
                 {"warmup_steps", "0"},
                 {"grid", R"({"size": [32, 32, 8], "voxel_size": 1})"},
                 {"stages", stages},
                 {"sun", R"({"elevation_deg": 25, "azimuth_deg": 60, "color": [1e30, 1e30, 1e30], "intensity": 1})"},
                 {"lighting", R"({"ambient": [1e30, 1e30, 1e30], "background": [1e30, 1e30, 1e30]})"},
                 {"shade.sigma", "0.01"},
                 {"shade.scattering", R"({"enabled": true, "albedo": 1, "solid_angle": 12.566370614359172})"},
                 {"render.width", "49"},
                 {"render.height", "37"},
                 {"render.ground", R"({"albedo": [1, 1, 1]})"},
                 {"render.cameras", Cameras()}});
}

// The shortest text that reads back as g's double, as the scene reader's messages show numbers.
std::string G(float g) {
    char text[40];
    const auto [end, ec] = std::to_chars(text, text + sizeof text, double(g));
    return std::string(text, ec == std::errc() ? end : text);
}

struct BoundItem {
    std::string name;
    std::vector<SceneOverride> overrides;
    // The brightest pixel must reach this: the item evaluates its extreme (near the phase peak), so a removed
    // bound shows as inf or NaN in it.
    double brightestAtLeast = 0;
};

std::vector<BoundItem> BoundItems() {
    const float hg = LargestAcceptedG(PhaseKind::HenyeyGreenstein), cs = LargestAcceptedG(PhaseKind::CornetteShanks);
    const std::vector<SceneOverride> peak = {{"phase", R"({"function": "henyey-greenstein", "g": )" + G(hg) + "}"}};
    // The lightning on the sunward camera's axis, 3 m before the target: samples every 0.5 m pass within r0 = 1 m
    // with the light straight ahead (cos theta_l ~ 1), where it shines at its guard radiance 1e30.
    const std::string light =
        R"({"position": )" + Vec(Along(kTarget, kSun, -3)) +
        R"(, "color": [1, 1, 1], "intensity": 1e30, "radius": 1, "flash": {"start": 0, "steps": 10}})";
    std::vector<BoundItem> items;
    // 1e30 * 2^18 * (1 - exp(-0.01 * ~19 voxels)) ~ 5e34 at the sunward centre pixel of the march.
    items.push_back({"PhasePeakHenyeyGreenstein", Plus(LitFullVolume(), peak), 1e34});
    items.push_back({"PhasePeakCornetteShanks",
                     Plus(LitFullVolume(), {{"phase", R"({"function": "cornette-shanks", "g": )" + G(cs) + "}"}}),
                     1e34});
    items.push_back({"PhasePeakBackward",
                     Plus(LitFullVolume(), {{"phase", R"({"function": "henyey-greenstein", "g": )" + G(-hg) + "}"}}),
                     1e34});
    // gl and vk have no Mie splats (docs/scenes.md): the march alone. Its peak is ~7400.
    items.push_back({"PhasePeakMie", Plus(LitFullVolume(false), {{"phase.function", "mie"}}), 1e32});
    items.push_back({"LightningAtGuardRadius", Plus(LitFullVolume(), Plus(peak, {{"lightning", light}})), 1e34});
    // The light 1e18 voxel edges away on each axis: |x_l - p|^2 ~ 3e36, still finite.
    const std::string farLight = R"({"position": [1e18, 1e18, -1e18], "color": [1, 1, 1], "intensity": 1e30,
                                     "radius": 1, "flash": {"start": 0, "steps": 10}})";
    items.push_back({"LightningFarAtEdgeBound", Plus(LitFullVolume(), Plus(peak, {{"lightning", farLight}})), 1e34});
    // The sky light at its bound where the sun stands (its phase peak too), beside the sun and the lightning at theirs:
    // a sample's light is then three terms of up to 1e30 * 2^19.5 each.
    const std::vector<SceneOverride> sky = {
        {"stages", R"(["region", "ca", "smooth", "density", "shade", "shade_sky", "shadow", "render_splat",
                      "render_march"])"},
        {"lighting.sky", R"({"elevation_deg": 25, "azimuth_deg": 60, "color": [1e30, 1e30, 1e30], "intensity": 1})"},
        {"lightning", light}};
    items.push_back({"SkyLightAtBound", Plus(LitFullVolume(), Plus(peak, sky)), 1e34});
    // A path from -1e9 to 1e9 degrees over 2^32 - 1 steps: 0.47 degrees a step.
    const std::string path = R"({"color": [1e30, 1e30, 1e30], "intensity": 1, "path": [
        {"step": 0, "elevation_deg": 25, "azimuth_deg": -1e9},
        {"step": 4294967295, "elevation_deg": 30, "azimuth_deg": 1e9}]})";
    items.push_back({"SunPathAzimuthAtBound", Plus(LitFullVolume(), Plus(peak, {{"sun", path}})), 0});
    // At 359 degrees a step the last step's azimuth is exactly 1e9.
    items.push_back({"SunSpeedAzimuthAtBound",
                     Plus(LitFullVolume(), Plus(peak, {{"sun.azimuth_deg", Num(kAzimuthBound - 359.0 * (kSteps - 1))},
                                                       {"sun.speed", R"({"azimuth_deg": 359})"}})),
                     0});
    // The optical depth at its bound, the ground shadow's sigma h / sin(25 deg) = 4.2e29 / 0.4226 = 0.994e30 (the
    // tighter of the two here), with the largest scattering gain, 2^18 tau, in fp32 and fp16.
    items.push_back(
        {"ScatteringAtOpticalDepthBound", Plus(LitFullVolume(), Plus(peak, {{"shade.sigma", "4.2e29"}})), 0});
    items.push_back({"ScatteringAtOpticalDepthBoundFp16",
                     Plus(LitFullVolume(), Plus(peak, {{"shade.sigma", "4.2e29"}, {"shade.storage", "fp16"}})), 0});
    return items;
}

// Every array of every enabled stage, downloaded after the step: finite; T, G in [0, 1]; each image channel in
// [0, kPixelBound]. Returns the brightest image value.
double CheckFinite(const Simulation& sim, uint32_t step, size_t& arrays) {
    const Scene& scene = sim.GetScene();
    double brightest = 0;
    auto check = [&](Resource r, const Buffer& buffer, const std::string& what) {
        const std::vector<float> v = DownloadAsFloat(sim.GetBackend(), buffer);
        const bool image = r == Resource::SplatImage || r == Resource::MarchImage;
        const double hi = image                                         ? kPixelBound
                          : (r == Resource::T || r == Resource::Shadow) ? 1.0
                                                                        : std::numeric_limits<double>::max();
        size_t bad = 0, first = 0;
        for (size_t n = 0; n < v.size(); ++n) {
            if (!(std::isfinite(v[n]) && v[n] >= 0 && v[n] <= hi)) first = bad++ ? first : n;
            if (image && std::isfinite(v[n])) brightest = std::max(brightest, double(v[n]));
        }
        EXPECT_EQ(bad, 0u) << what << " at step " << step << ": " << bad << " of " << v.size()
                           << " values not finite in [0, " << hi << "]; first [" << first << "] = " << v[first];
        ++arrays;
    };
    std::vector<Resource> seen;
    for (Stage stage : sim.Schedule())
        for (Resource r : Describe(stage).writes) {
            if (std::find(seen.begin(), seen.end(), r) != seen.end()) continue;
            seen.push_back(r);
            const size_t buffers = IsPerCamera(r) ? scene.render.cameras.size() : 1;
            for (size_t n = 0; n < buffers; ++n) {
                const Buffer* buffer = sim.Get(r, n);
                if (!buffer) {
                    ADD_FAILURE() << ResourceName(r) << " has no buffer " << n;
                    continue;
                }
                check(r, *buffer, std::string(ResourceName(r)) + "[" + std::to_string(n) + "]");
            }
            if (const Buffer* previous = sim.Previous(r))
                check(r, *previous, "previous " + std::string(ResourceName(r)));
        }
    return brightest;
}

void RunBoundItem(Backend& backend, const BoundItem& item) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", item.overrides);
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    auto sim = Simulation::Create(*scene, backend, /*everyStepOutputs=*/true);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    size_t arrays = 0;
    double brightest = 0;
    for (uint32_t t = 0; t < scene->steps; ++t) {
        StepRecord record;
        const Status status = (*sim)->Step(record, [&](const Simulation& s) -> Status {
            brightest = std::max(brightest, CheckFinite(s, t, arrays));
            return {};
        });
        ASSERT_TRUE(status.has_value()) << "step " << t << ": " << status.error().message;
    }
    EXPECT_GE(brightest, item.brightestAtLeast) << "the extreme was not reached";
    EXPECT_GT(arrays, 0u);
    std::printf("%s %s: %zu arrays, brightest pixel %.3g\n", backend.Name().c_str(), item.name.c_str(), arrays,
                brightest);
}

class FiniteBounds : public ::testing::TestWithParam<std::string> {};

// Test every extreme just inside its bound on one backend: every output finite and in range (CheckFinite).
TEST_P(FiniteBounds, EveryExtremeAtItsBoundFinite) {
    std::string whyNot;
    Backend* backend = BackendFor(GetParam(), whyNot);
    if (!backend) GTEST_SKIP() << "unsupported here: " << whyNot;
    for (const BoundItem& item : BoundItems()) {
        SCOPED_TRACE("item " + item.name);
        RunBoundItem(*backend, item);
    }
}

// Test that a shade call with a resolution outside kShadeResolutions is refused by the backend itself (the
// interface is also called by tests and tools, not only from a validated scene), with the backend's name, and
// that every resolution in the list is taken.
TEST_P(FiniteBounds, ShadeRefusesAResolutionOutsideTheList) {
    std::string whyNot;
    Backend* backend = BackendFor(GetParam(), whyNot);
    if (!backend) GTEST_SKIP() << "unsupported here: " << whyNot;
    const Extent3 e{8, 8, 4};
    auto q = test::MakeFilled(*backend, BufferFormat::F32, e, std::vector<float>(e.Count(), 0.5f));
    auto T = test::MakeBuffer(*backend, BufferFormat::F32, e);
    for (const int f : {0, 3, 8, -1}) {
        ShadeParams p;
        p.resolution = f;
        const Status status = backend->Shade(p, *q, *T);
        ASSERT_FALSE(status) << "resolution " << f;
        EXPECT_EQ(status.error().message, backend->Name() + ": shade resolution must be 1, 2 or 4");
    }
    for (const int64_t f : kShadeResolutions) {
        ShadeParams p;
        p.resolution = int(f);
        const Status status = backend->Shade(p, *q, *T);
        EXPECT_TRUE(status) << "resolution " << f << ": " << status.error().message;
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, FiniteBounds, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// Test the phase peak's bound against what it promises (core/math/Shading.h kMaxPhasePeak): for every float g in
// [0.9, 1) whose peak passes, and its negative, P^ at |cos theta| up to 1 + 2^-19 (16 ulps past 1, the
// renderers' rounding with margin) is finite and at most 2^1.5 times the peak. With the bound 16 times larger
// (2^22) it fails from g = 0.997243 on (denominators within the rounding of cos).
TEST(FiniteBoundsMath, PhasePeakBoundKeepsEveryCosineFinite) {
    for (PhaseKind kind : {PhaseKind::HenyeyGreenstein, PhaseKind::CornetteShanks}) {
        size_t accepted = 0, bad = 0;
        float firstBad = 0;
        for (float g = 0.9f; g < 1.0f; g = std::nextafter(g, 1.0f)) {
            const float peak = PhasePeak({kind, g});
            if (!(peak <= kMaxPhasePeak)) continue;
            ++accepted;
            for (int i = 0; i <= 16; ++i) {
                const float c = 1.0f + float(i) * 0x1p-23f;
                for (const auto& [gg, cc] : {std::pair{g, c}, std::pair{-g, -c}}) {
                    const float v = PhaseValue({kind, gg}, cc);
                    if (!(std::isfinite(v) && v <= 2.8285f * peak)) firstBad = bad++ ? firstBad : gg;
                }
            }
        }
        EXPECT_EQ(bad, 0u) << PhaseKindName(kind) << ": first at g = " << firstBad;
        EXPECT_GT(accepted, 1000000u);
    }
    EXPECT_EQ(kMaxPhasePeak, kPeakBound);  // the bound docs/scenes.md states
}

using test::ErrorOf;
using test::HasLine;
using test::Parsed;

// The scene text of ci-small-sized tests with `fields` added at the top level ("\"phase\": {...}").
std::string With(const std::string& fields) { return R"({"grid": {"size": [8, 8, 8]}, )" + fields + "}"; }

// Test the phase peak's bound on both sides: the largest accepted g runs (above) and its next float is refused,
// naming phase.g, the bound and the peak; so is g = 0.9999999 (before the bound, T was 94 % NaN with scattering).
TEST(FiniteBoundsRefused, PhasePeakJustPastTheBound) {
    for (PhaseKind kind : {PhaseKind::HenyeyGreenstein, PhaseKind::CornetteShanks}) {
        const std::string name(PhaseKindName(kind));
        const float g = LargestAcceptedG(kind), past = std::nextafter(g, 1.0f);
        for (float sign : {1.0f, -1.0f}) {
            Parsed(With(R"("phase": {"function": ")" + name + R"(", "g": )" + G(sign * g) + "}"));
            const std::string message =
                ErrorOf(With(R"("phase": {"function": ")" + name + R"(", "g": )" + G(sign * past) + "}"));
            const std::string prefix = "test.json: phase.g: the phase function's peak P^max (P^ at cos theta = " +
                                       std::string(sign > 0 ? "1" : "-1") +
                                       ", in single precision as the stages evaluate it) must be at most 262144 "
                                       "(2^18), got ";
            ASSERT_TRUE(message.starts_with(prefix)) << message;
            EXPECT_GT(std::stod(message.substr(prefix.size())), 262144.0) << message;
            EXPECT_NE(message.find("(" + name + ", g = " + G(sign * past) + ")"), std::string::npos) << message;
        }
    }
    EXPECT_TRUE(HasLine(ErrorOf(With(R"("phase": {"g": 0.9999999}, "sun": {"intensity": 1e30, "color": [1, 1, 1]},
                                        "shade": {"scattering": {"enabled": true}})")),
                        "test.json: phase.g: the phase function's peak P^max (P^ at cos theta = 1, in single precision "
                        "as the stages evaluate it) must be at most 262144 (2^18), got inf (henyey-greenstein, g = "
                        "0.9999999)"));
}

// Test the lightning's radiance bounds just past them: colour * intensity (1e30 x 1e30 was inf on every backend),
// and at the guard radius colour * intensity / r0^2.
TEST(FiniteBoundsRefused, LightningRadianceJustPastTheBounds) {
    // 2 * 5e29 is 1e30 exactly in double (doubling is exact), 2 * the next double above 5e29 the next above 1e30.
    const std::string pastHalf = Num(std::nextafter(kRadianceBound / 2, kRadianceBound));
    Parsed(With(R"("lightning": {"position": [0, 0, 0], "color": [1, 0.5, 2], "intensity": 5e29, "radius": 1})"));
    EXPECT_TRUE(HasLine(
        ErrorOf(With(R"("lightning": {"position": [0, 0, 0], "color": [1, 0.5, 2], "intensity": )" + pastHalf + "}")),
        "test.json: lightning.intensity: color * intensity (the light's radiance at 1 m) must be at "
        "most 1e+30 in each channel, got 1.0000000000000002e+30"));
    EXPECT_TRUE(
        HasLine(ErrorOf(With(R"("lightning": {"position": [0, 0, 0], "color": [1e30, 1, 1], "intensity": 1e30})")),
                "test.json: lightning.intensity: color * intensity (the light's radiance at 1 m) must be at "
                "most 1e+30 in each channel, got 1.0000000000000001e+60"));
    const std::string pastRadius = Num(std::nextafter(1.0, 0.0));
    EXPECT_TRUE(
        HasLine(ErrorOf(With(R"("lightning": {"position": [0, 0, 0], "color": [1, 1, 1], "intensity": 1e30,
                                                      "radius": )" +
                             pastRadius + "}")),
                "test.json: lightning.radius: color * intensity / radius^2 (the light's radiance at its guard "
                "radius, the most it reaches) must be at most 1e+30 in each channel, got 1.0000000000000003e+30"));
    // Off, the light never shines: its values are not bounded.
    Parsed(With(R"("lightning": {"enabled": false, "color": [1e30, 1, 1], "intensity": 1e30})"));
}

// Test the lightning's distance from the grid in voxel edges just past 1e18 (the light's offset squared overflowed
// float past ~1e19 and the march toward it stepped NaN).
TEST(FiniteBoundsRefused, LightningPositionJustPastTheBound) {
    const std::string grid = R"({"grid": {"size": [8, 8, 8], "voxel_size": 1}, "lightning": {"position": )";
    Parsed(grid + "[1e18, -1e18, 1e18]}}");
    const std::string past = Num(std::nextafter(kLightEdgesBound, 2 * kLightEdgesBound));
    EXPECT_TRUE(HasLine(ErrorOf(grid + "[0, -" + past + ", 0]}}"),
                        "test.json: lightning.position[1]: (position - grid.origin) / grid.voxel_size (the light's "
                        "distance from the grid in voxel edges) must be in [-1e+18, 1e+18], got -1000000000000000128"));
}

// Test the sun's azimuth bound just past it, fixed, on a path (+-1e308 over 2^32 steps, whose
// interpolation overflowed to inf: the CPU ran out of memory in shade, gl and vk drew NaN) and at a speed.
TEST(FiniteBoundsRefused, SunAzimuthJustPastTheBound) {
    const std::string reason =
        "the azimuth must be in [-1000000000, 1000000000] degrees (beyond, double precision no longer fixes the sun's "
        "direction to float's precision), got ";
    const std::string past = Num(std::nextafter(kAzimuthBound, 2 * kAzimuthBound));
    Parsed(With(R"("sun": {"azimuth_deg": -1e9})"));
    EXPECT_TRUE(HasLine(ErrorOf(With(R"("sun": {"azimuth_deg": -)" + past + "}")),
                        "test.json: sun.azimuth_deg: " + reason + "-1000000000.0000001"));
    const std::string message =
        ErrorOf(With(R"("sun": {"path": [{"step": 0, "elevation_deg": 10, "azimuth_deg": -1e308},
        {"step": 4294967295, "elevation_deg": 20, "azimuth_deg": 1e308}]})"));
    EXPECT_TRUE(HasLine(message, "test.json: sun.path[0].azimuth_deg: " + reason + "-1e+308")) << message;
    EXPECT_TRUE(HasLine(message, "test.json: sun.path[1].azimuth_deg: " + reason + "1e+308")) << message;
    // steps 20: az(19) = 1e9 - 359 * 19 + 359 * 19 = 1e9 exactly, accepted; one more degree per step is not.
    const std::string start = Num(kAzimuthBound - 359.0 * 19);
    Parsed(With(R"("steps": 20, "sun": {"azimuth_deg": )" + start + R"(, "speed": {"azimuth_deg": 359}})"));
    EXPECT_TRUE(HasLine(
        ErrorOf(With(R"("steps": 20, "sun": {"azimuth_deg": )" + start + R"(, "speed": {"azimuth_deg": 360}})")),
        "test.json: sun.speed.azimuth_deg: " + reason + "1000000019 at the last step (19)"));
}

}  // namespace
}  // namespace cb::spec12_test
