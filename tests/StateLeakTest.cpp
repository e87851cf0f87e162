// No state leaks between calls: a backend that has already run other scenes
// (another grid and stage set, a sun below the horizon and then above it,
// another shade resolution, buffers filled with stray data) gives the same
// bits for every array and frame of every step of a scene as a fresh backend
// does, on every backend and automaton layout. A stage that kept a texture,
// pipeline, scratch buffer or uniform from an earlier call, or read one it
// did not write, shows here as a difference.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/math/Random.h"
#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
#include "harness/run/Simulation.h"
#include "tests/BackendTestUtil.h"
#include "tests/Spec12Outputs.h"

namespace cb {
namespace {

Scene Load(const std::string& file, const std::vector<SceneOverride>& overrides) {
    // No warm-up: every step of these short runs is an output step.
    std::vector<SceneOverride> all = {{"warmup_steps", "0"}};
    all.insert(all.end(), overrides.begin(), overrides.end());
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + file, all);
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    return scene ? *scene : Scene{};
}

// One output array as it stands after a step, canonical (bytes widened to float, exactly), and its name.
struct Array {
    std::string name;
    std::vector<float> values;
};
using Step = std::vector<Array>;

// Every array the enabled stages write (one per camera for images) and the previous step's copies.
Step Outputs(const Simulation& sim) {
    Step arrays;
    for (Stage stage : sim.Schedule())
        for (Resource r : Describe(stage).writes) {
            const std::string name(ResourceName(r));
            const size_t buffers = IsPerCamera(r) ? sim.GetScene().render.cameras.size() : 1;
            for (size_t n = 0; n < buffers; ++n)
                if (const Buffer* buffer = sim.Get(r, n))
                    arrays.push_back({name + "[" + std::to_string(n) + "]",
                                      spec12_test::DownloadAsFloat(sim.GetBackend(), *buffer)});
            if (const Buffer* previous = sim.Previous(r))
                arrays.push_back({"previous " + name, spec12_test::DownloadAsFloat(sim.GetBackend(), *previous)});
        }
    return arrays;
}

// Every output of every step of `scene` on `backend`.
std::vector<Step> RunScene(const Scene& scene, Backend& backend, const std::string& what) {
    std::vector<Step> steps;
    auto sim = Simulation::Create(scene, backend, /*everyStepOutputs=*/true);
    if (!sim) {
        ADD_FAILURE() << what << ": " << sim.error().message;
        return steps;
    }
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord record;
        if (Status s = (*sim)->Step(record); !s) {
            ADD_FAILURE() << what << ", step " << t << ": " << s.error().message;
            return steps;
        }
        steps.push_back(Outputs(**sim));
    }
    return steps;
}

// Buffers of every format filled with a hash (never what a stage writes), then dropped, so that a stage that
// reads memory it did not write meets stray values rather than zeros.
void FillStrayBuffers(Backend& backend) {
    const Extent3 extent{48, 40, 12};
    for (BufferFormat format : {BufferFormat::Bits, BufferFormat::U8, BufferFormat::F32}) {
        auto buffer = backend.CreateBuffer(format, extent);
        ASSERT_TRUE(buffer.has_value()) << buffer.error().message;
        std::vector<std::byte> data(CanonicalBufferBytes(format, extent));
        for (size_t i = 0; i < data.size(); ++i) {
            const uint32_t h = LowBias32(uint32_t(i) * 2654435761u + uint32_t(format));
            // F32: a finite value in [0, 1) per float; bytes and bits: any value (bit fields take 0 or 1 per byte).
            data[i] = std::byte(format == BufferFormat::Bits ? (h & 1u) : (h & 0x3Fu));
        }
        ASSERT_TRUE(backend.Upload(**buffer, data).has_value());
    }
}

class StateLeak : public test::BackendTest {};

TEST_P(StateLeak, EveryArrayAndFrameMatchesAFreshBackendAfterOtherScenes) {
    // Both renderers, the ground, shade and shadow, the automaton and density.
    const Scene target = Load("ground-shadow.json", {{"steps", "3"}});
    auto fresh = test::MakeTestBackend(GetParam());
    ASSERT_TRUE(fresh.has_value()) << fresh.error().message;
    const std::vector<Step> expected = RunScene(target, **fresh, "on a fresh backend");
    test::ExpectNoValidationMessages(fresh->get());
    fresh->reset();

    const std::vector<std::pair<std::string, Scene>> before = {
        {"noise and the ray marcher on another grid", Load("noise-layer.json", {{"grid.size", "[40, 36, 24]"}})},
        {"the sun below the horizon", Load("ground-shadow.json", {{"steps", "2"}, {"sun.elevation_deg", "-10"}})},
        {"shade at resolution 2 on another grid",
         Load("ci-small.json", {{"steps", "2"}, {"shade.resolution", "2"}, {"grid.size", "[48, 40, 12]"}})},
        {"the sun above the horizon again, other cameras", Load("ci-small.json", {{"steps", "2"}})},
    };
    for (const auto& [what, scene] : before) RunScene(scene, *mBackend, what);
    FillStrayBuffers(*mBackend);
    const std::vector<Step> got = RunScene(target, *mBackend, "after the other scenes");

    ASSERT_EQ(got.size(), expected.size());
    size_t compared = 0;
    for (size_t t = 0; t < got.size(); ++t) {
        ASSERT_EQ(got[t].size(), expected[t].size()) << "arrays at step " << t;
        for (size_t k = 0; k < got[t].size(); ++k, ++compared) {
            const std::vector<float>&a = got[t][k].values, &b = expected[t][k].values;
            ASSERT_EQ(got[t][k].name, expected[t][k].name);
            ASSERT_EQ(a.size(), b.size()) << got[t][k].name << " at step " << t;
            if (std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0) continue;
            size_t i = 0;
            while (std::memcmp(&a[i], &b[i], sizeof(float)) == 0) ++i;
            ADD_FAILURE() << got[t][k].name << " at step " << t << " differs from a fresh backend's first at element "
                          << i << ": " << a[i] << " vs " << b[i];
        }
    }
    // ground-shadow writes region, the automaton's three fields, q, the column sums, tiles and bands, T, G and two
    // frames on every step: a comparison that saw none of them would pass for nothing.
    EXPECT_GE(compared, 3u * 10u);
}

INSTANTIATE_TEST_SUITE_P(Backends, StateLeak, ::testing::ValuesIn(test::TestBackendsAndCaLayouts()));

}  // namespace
}  // namespace cb
