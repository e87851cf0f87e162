// No state survives a backend call unless it should, on every backend and
// every GL automaton layout: an automaton state uploaded between steps (the
// --resume path) is what the next step reads, however the backend caches the
// state it left (gl rgba8 keeps it repacked); shade and shadow after a sunset
// and a sunrise equal them on a fresh backend; and a scene run after another
// on the same backend object equals it on a fresh backend, every resource at
// every step, bit for bit.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <span>

#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"
#include "tests/BackendTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

const Extent3 kSlsGrid{37, 11, 6};

// The three fields of one automaton state on a backend.
struct SlsState {
    std::unique_ptr<Buffer> f[3];
    CaFields Out() { return {f[0].get(), f[1].get(), f[2].get()}; }
    ConstCaFields In() const { return {f[0].get(), f[1].get(), f[2].get()}; }
};

SlsState SlsMakeState(Backend& b) {
    SlsState s;
    for (auto& f : s.f) f = test::MakeBuffer(b, BufferFormat::Bits, kSlsGrid);
    return s;
}

// A state unlike any the automaton reaches from its initial one: hum, act, cld each random.
std::vector<uint8_t> SlsUploadedField(int n) { return test::RandomBits(kSlsGrid, 91u + uint32_t(n), 3u + uint32_t(n)); }

Status SlsUpload(Backend& b, Buffer& buffer, const std::vector<uint8_t>& bytes) {
    return b.Upload(buffer, std::as_bytes(std::span(bytes)));
}

std::vector<uint8_t> SlsRegion() {
    std::vector<uint8_t> region(kSlsGrid.Count());
    for (size_t i = 0; i < region.size(); ++i) region[i] = uint8_t((i * 2654435761u >> 7) % 256u);
    return region;
}

// How the steps run: wind or none; whole, or in shares of two slices (time-slicing).
struct SlsMode {
    bool wind = false, shares = false;
};

// Steps `from` -> `to` with step number t; the three fields of `to` as bytes.
std::vector<std::vector<uint8_t>> SlsStep(Backend& b, const SlsState& from, SlsState& to, const Buffer& region,
                                          uint32_t t, SlsMode mode) {
    static const std::vector<int32_t> sx = {1, -2, 0, 3, -1, 2}, sy = {-1, 0, 2, 1, -2, 0};
    CaStepParams p{11, t, QuantizeProbability(0.2), QuantizeProbability(0.2), QuantizeProbability(0.05), {}, {}, {}};
    if (mode.wind) p.shiftX = sx, p.shiftY = sy;
    for (uint32_t k = 0; k < kSlsGrid.nz; k += mode.shares ? 2 : kSlsGrid.nz) {
        if (mode.shares) p.slices = {k, k + 2};
        const Status s = b.CaStep(p, from.In(), region, to.Out());
        EXPECT_TRUE(s.has_value()) << b.Name() << ": " << s.error().message;
    }
    std::vector<std::vector<uint8_t>> fields;
    for (const auto& f : to.f) fields.push_back(test::Read<uint8_t>(b, *f));
    return fields;
}

class StateLeakCaUpload : public test::BackendTest {
  protected:
    // Three steps, the state uploaded into the last one's output (the buffer the backend may keep a copy of), three
    // more; each of these equals the same steps on a fresh backend that starts from the uploaded state.
    void ExpectUploadedStateRead(SlsMode mode) {
        const std::vector<uint8_t> regionBytes = SlsRegion();
        std::vector<std::vector<std::vector<uint8_t>>> want;
        {
            auto fresh = test::MakeTestBackend(GetParam());
            ASSERT_TRUE(fresh.has_value()) << fresh.error().message;
            Backend& b = **fresh;
            auto region = test::MakeFilled(b, BufferFormat::U8, kSlsGrid, regionBytes);
            SlsState s[2] = {SlsMakeState(b), SlsMakeState(b)};
            for (int n = 0; n < 3; ++n) ASSERT_TRUE(SlsUpload(b, *s[1].f[n], SlsUploadedField(n)));
            for (uint32_t t = 3; t < 6; ++t) want.push_back(SlsStep(b, s[t % 2], s[1 - t % 2], *region, t, mode));
            test::ExpectNoValidationMessages(&b);
        }
        Backend& b = *mBackend;
        auto region = test::MakeFilled(b, BufferFormat::U8, kSlsGrid, regionBytes);
        SlsState s[2] = {SlsMakeState(b), SlsMakeState(b)};
        ASSERT_TRUE(b.CaInitialize({11, QuantizeProbability(0.4), QuantizeProbability(0.05)}, s[0].Out()));
        std::vector<uint8_t> before;
        for (uint32_t t = 0; t < 3; ++t) before = SlsStep(b, s[t % 2], s[1 - t % 2], *region, t, mode)[1];
        for (int n = 0; n < 3; ++n) ASSERT_TRUE(SlsUpload(b, *s[1].f[n], SlsUploadedField(n)));
        EXPECT_NE(before, SlsUploadedField(1)) << "the upload changes nothing: the test proves nothing";
        for (uint32_t t = 3; t < 6; ++t) {
            const auto got = SlsStep(b, s[t % 2], s[1 - t % 2], *region, t, mode);
            const char* names[3] = {"hum", "act", "cld"};
            for (int n = 0; n < 3; ++n)
                EXPECT_TRUE(got[n] == want[t - 3][n])
                    << names[n] << " at step " << t << " differs from a fresh backend's that started from the upload";
        }
    }
};

// Test that the step after an uploaded state reads it, without wind and with, whole and in shares.
TEST_P(StateLeakCaUpload, StepsAfterAnUploadEqualAFreshBackend) {
    for (bool wind : {false, true})
        for (bool shares : {false, true}) {
            SCOPED_TRACE(std::string(wind ? "wind" : "no wind") + (shares ? ", in shares" : ", whole steps"));
            ExpectUploadedStateRead({wind, shares});
        }
}

INSTANTIATE_TEST_SUITE_P(Backends, StateLeakCaUpload, ::testing::ValuesIn(test::TestBackendsAndCaLayouts()),
                         [](const auto& info) { return info.param; });

using StateLeakSunset = test::BackendTest;

// Test that shade and shadow under a sun that has risen again equal a fresh backend's, bit for bit, after a call
// with the sun above the horizon and one with it below (no sun: G = 1 everywhere), for every shadow form: a backend
// that keeps "no sun" from the sunset (gl's shadow program setting its noSun uniform only to 1) shades the sunrise
// without its shadow.
TEST_P(StateLeakSunset, SunriseAfterSunsetEqualsAFreshBackend) {
    const Extent3 e{23, 19, 7};
    const std::vector<float> q = test::GaussianBlobField(e, {{6, 5, 3, 2.5}, {15, 12, 4, 3}});
    std::vector<float> D(size_t(e.nx) * e.ny, 0.0f);
    for (size_t v = 0; v < q.size(); ++v) D[v % D.size()] += q[v];
    const Vec3 suns[] = {SunDirection(0.5, 0.4), SunDirection(-0.3, 1.2), SunDirection(0.7, 2.0)};
    ASSERT_LT(suns[1][2], 0.0f) << "the second sun must be below the horizon";
    for (ShadowForm form : {ShadowForm::Beer, ShadowForm::Thesis, ShadowForm::Wang}) {
        SCOPED_TRACE("shadow form " + std::to_string(int(form)));
        // Shade's T and shadow's G on `b` for each sun in turn; the last call's.
        auto run = [&](Backend& b, std::span<const Vec3> path) {
            auto qb = test::MakeFilled(b, BufferFormat::F32, e, q);
            auto Db = test::MakeFilled(b, BufferFormat::F32, {e.nx, e.ny, 1}, D);
            auto T = test::MakeBuffer(b, BufferFormat::F32, e);
            auto G = test::MakeBuffer(b, BufferFormat::F32, {e.nx, e.ny, 1});
            std::vector<float> t, g;
            for (const Vec3& sun : path) {
                ShadeParams sp;
                sp.sun = sun, sp.sigma = 0.05f;
                ShadowParams gp;
                gp.sun = sun, gp.form = form, gp.sigma = 0.05f, gp.nz = e.nz, gp.coverage = 0.8f;
                Status s = b.Shade(sp, *qb, *T);
                EXPECT_TRUE(s.has_value()) << s.error().message;
                s = b.Shadow(gp, *Db, *G);
                EXPECT_TRUE(s.has_value()) << s.error().message;
                t = test::Read<float>(b, *T), g = test::Read<float>(b, *G);
                if (sun[2] < 0) {
                    EXPECT_EQ(g, std::vector<float>(g.size(), 1.0f)) << "no sun casts no shadow (docs/pipeline.md)";
                }
            }
            return std::pair{t, g};
        };
        std::pair<std::vector<float>, std::vector<float>> want;
        {
            auto fresh = test::MakeTestBackend(GetParam());
            ASSERT_TRUE(fresh.has_value()) << fresh.error().message;
            want = run(**fresh, std::span(suns).last(1));
            test::ExpectNoValidationMessages(fresh->get());
        }
        EXPECT_NE(want.second, std::vector<float>(want.second.size(), 1.0f)) << "the risen sun casts no shadow here";
        const auto got = run(*mBackend, suns);
        EXPECT_TRUE(got.first == want.first) << "T after sunrise differs from a fresh backend's";
        EXPECT_TRUE(got.second == want.second) << "G after sunrise differs from a fresh backend's";
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, StateLeakSunset, ::testing::ValuesIn(test::TestBackends()),
                         [](const auto& info) { return info.param; });

// scenes/ci-small.json with `sets` applied as --set does, a few small steps.
Scene SlsScene(std::vector<SceneOverride> sets) {
    std::ifstream file(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json");
    nlohmann::json root = nlohmann::json::parse(file);
    const std::vector<SceneOverride> common = {
        {"steps", "3"},
        {"warmup_steps", "1"},
        {"ca.act0", "0.03"},
        {"ca.p_act", "0.02"},
        {"render.width", "24"},
        {"render.height", "18"},
        {"render.every_steps", "1"},
    };
    sets.insert(sets.begin(), common.begin(), common.end());
    auto scene = ParseScene(root.dump(), "ci-small.json", sets);
    EXPECT_TRUE(scene.has_value()) << (scene ? "" : scene.error().message);
    return scene ? *scene : Scene{};
}

// Scene A: 23 x 19 x 7, density in 8 x 8 tiles, the sun near the x axis.
Scene SlsSceneA() {
    return SlsScene({{"grid.size", "[23, 19, 7]"},
                     {"density.tile", "8"},
                     {"sun.elevation_deg", "20"},
                     {"sun.azimuth_deg", "10"},
                     {"render.cameras",
                      R"([{"name": "a", "eye": [575, -700, 1100], "target": [575, 475, 150], "up": [0, 0, 1],
                           "fov_deg": 70, "near": 1, "far": 20000}])"}});
}

// Scene B: another grid, density in one tile, the sun near the y axis, wind, another smoothing radius and seed.
// (grid.tiling needs a q that wraps, which the automaton's does not.)
Scene SlsSceneB() {
    return SlsScene({{"grid.size", "[29, 13, 5]"},
                     {"density.tile", "29"},
                     {"density.band", "2"},
                     {"smooth.radius", "2"},
                     {"ca.seed", "3"},
                     {"ca.wind_shift", "[[1, -1]]"},
                     {"sun.elevation_deg", "30"},
                     {"sun.azimuth_deg", "80"},
                     {"render.cameras",
                      R"([{"name": "b", "eye": [700, 1400, 900], "target": [725, 325, 100], "up": [0, 0, 1],
                           "fov_deg": 60, "near": 1, "far": 20000}])"}});
}

// Every resource's bytes at every step (images per camera), and the columns the last step covered.
struct SlsSceneRun {
    std::vector<std::map<std::string, std::vector<std::byte>>> steps;
    uint32_t covered = 0;
};

SlsSceneRun SlsRunScene(const Scene& scene, Backend& backend) {
    auto sim = Simulation::Create(scene, backend);
    EXPECT_TRUE(sim.has_value()) << sim.error().message;
    if (!sim) return {};
    SlsSceneRun run;
    for (uint32_t t = 0; t < scene.steps; ++t) {
        std::map<std::string, std::vector<std::byte>> bytes;
        StepRecord record;
        Status s = (*sim)->Step(record, [&](const Simulation& at) -> Status {
            for (Resource r : kAllResources)
                for (size_t n = 0; at.Get(r, n); ++n) {
                    std::vector<std::byte> data(at.Get(r, n)->CanonicalBytes());
                    CB_TRY(backend.Download(*at.Get(r, n), data));
                    bytes[std::string(ResourceName(r)) + "#" + std::to_string(n)] = std::move(data);
                }
            return {};
        });
        EXPECT_TRUE(s.has_value()) << s.error().message;
        run.steps.push_back(std::move(bytes));
        run.covered = record.coveredColumns.value_or(0);
    }
    return run;
}

using StateLeakSceneSequence = test::BackendTest;

// Test that scene B after scene A on one backend equals B on a fresh backend, every resource at every step.
TEST_P(StateLeakSceneSequence, SecondSceneEqualsAFreshBackend) {
    const Scene a = SlsSceneA(), b = SlsSceneB();
    ASSERT_GT(a.steps, 0u);
    ASSERT_GT(b.steps, 0u);
    SlsSceneRun fromFresh;
    {
        auto fresh = test::MakeTestBackend(GetParam());
        ASSERT_TRUE(fresh.has_value()) << fresh.error().message;
        fromFresh = SlsRunScene(b, **fresh);
        test::ExpectNoValidationMessages(fresh->get());
    }
    const auto& want = fromFresh.steps;
    ASSERT_EQ(want.size(), b.steps);
    EXPECT_GT(fromFresh.covered, 0u) << "scene B needs clouds";
    const SlsSceneRun first = SlsRunScene(a, *mBackend);
    ASSERT_EQ(first.steps.size(), a.steps);
    EXPECT_GT(first.covered, 0u) << "scene A needs clouds";
    const auto got = SlsRunScene(b, *mBackend).steps;
    ASSERT_EQ(got.size(), want.size());
    for (size_t t = 0; t < got.size(); ++t) {
        SCOPED_TRACE("scene B, step " + std::to_string(t));
        EXPECT_EQ(got[t].size(), want[t].size());
        for (const auto& [name, data] : want[t]) {
            ASSERT_TRUE(got[t].count(name)) << name;
            // Warm-up steps write no T, G or image: until then such a buffer holds whatever its memory held.
            const bool output = name.starts_with("T#") || name.starts_with("G#") || name.starts_with("image");
            if (output && t < b.warmupSteps) continue;
            EXPECT_TRUE(got[t].at(name) == data) << name << " differs from a fresh backend's";
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, StateLeakSceneSequence, ::testing::ValuesIn(test::TestBackendsAndCaLayouts()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace cb
