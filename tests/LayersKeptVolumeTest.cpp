// The CPU's layers keep their padded volume and its empty-taps bits between calls whose inputs carry the same
// non-zero stamp (LayersInputs::stamp, StageHostInputs::inputsStamp), and form them anew otherwise: a call with the
// same stamp after the buffers were rewritten still draws what was kept, while a new stamp, stamp 0, another alpha
// or other buffers draw what the buffers hold, as a fresh backend does. And the loop's side: every frame of a run
// equals a fresh backend's call with stamp 0 on the run's buffers, with clouds that change every step (the
// automaton) and with static ones lit by a moving sun (noise, several frames a step at different alphas), three
// cameras a call.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/math/Random.h"
#include "core/plan/SceneLoad.h"
#include "core/stages/render_layers/RenderLayers.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/MarchTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

const Extent3 kGrid{12, 10, 5};

// Sparse clouds, a voxel in three, that differ with `salt`.
std::vector<float> Clouds(uint32_t salt) {
    std::vector<float> q(kGrid.Count());
    for (size_t i = 0; i < q.size(); ++i) {
        const uint32_t h = LowBias32(uint32_t(i) * 7u + salt);
        q[i] = h % 3u == 0 ? 0.2f + float(h % 700u) / 1000.0f : 0.0f;
    }
    return q;
}

LayersParams Params(float alpha) {
    const MarchParams camera = test::CameraParams(kGrid, {0.3 * kGrid.nx, -0.4 * kGrid.ny, 2.5 * kGrid.nz + 6},
                                                  {0.5 * kGrid.nx, 0.5 * kGrid.ny, 0}, 31, 23);
    LayersParams p = test::LayersFromCamera(camera, kGrid, kGrid.nz, false);
    p.alpha = alpha;
    return p;
}

// One call: the image of `p` over (qPrev, qCur, T) with `stamp`.
std::vector<float> Draw(Backend& b, const LayersParams& p, const Buffer& qPrev, const Buffer& qCur, const Buffer& T,
                        uint64_t stamp) {
    auto image = test::MakeBuffer(b, BufferFormat::F32, {3, p.camera.width, p.camera.height});
    const Status s = b.RenderLayers(p, {&qPrev, &qCur, &T, nullptr, stamp}, *image, nullptr);
    EXPECT_TRUE(s.has_value()) << s.error().message;
    return test::Read<float>(b, *image);
}

// What a fresh backend draws from these volumes.
std::vector<float> Fresh(const LayersParams& p, const std::vector<float>& qPrev, const std::vector<float>& qCur,
                         const std::vector<float>& T) {
    cpu::BackendCpu b(2);
    auto a = test::MakeFilled(b, BufferFormat::F32, kGrid, qPrev);
    auto c = test::MakeFilled(b, BufferFormat::F32, kGrid, qCur);
    auto t = test::MakeFilled(b, BufferFormat::F32, kGrid, T);
    return Draw(b, p, *a, *c, *t, 0);
}

TEST(LayersKeptVolume, SameStampKeepsOtherwiseFormsAnew) {
    const std::vector<float> first = Clouds(1), second = Clouds(2), T(kGrid.Count(), 0.6f);
    const LayersParams p = Params(0.5f);
    const std::vector<float> firstImage = Fresh(p, first, first, T), secondImage = Fresh(p, second, second, T);
    ASSERT_NE(firstImage, secondImage);

    cpu::BackendCpu b(2);
    auto qPrev = test::MakeFilled(b, BufferFormat::F32, kGrid, first);
    auto qCur = test::MakeFilled(b, BufferFormat::F32, kGrid, first);
    auto t = test::MakeFilled(b, BufferFormat::F32, kGrid, T);
    EXPECT_EQ(Draw(b, p, *qPrev, *qCur, *t, 7), firstImage);
    // Rewritten in place: the same stamp draws what was kept, a new stamp what the buffers hold.
    ASSERT_TRUE(b.Upload(*qPrev, std::as_bytes(std::span(second))).has_value());
    ASSERT_TRUE(b.Upload(*qCur, std::as_bytes(std::span(second))).has_value());
    EXPECT_EQ(Draw(b, p, *qPrev, *qCur, *t, 7), firstImage);
    EXPECT_EQ(Draw(b, p, *qPrev, *qCur, *t, 8), secondImage);
    // Stamp 0 is unknown: formed anew every call.
    ASSERT_TRUE(b.Upload(*qCur, std::as_bytes(std::span(first))).has_value());
    EXPECT_EQ(Draw(b, p, *qPrev, *qCur, *t, 0), Fresh(p, second, first, T));
    ASSERT_TRUE(b.Upload(*qPrev, std::as_bytes(std::span(first))).has_value());
    EXPECT_EQ(Draw(b, p, *qPrev, *qCur, *t, 0), firstImage);
    // The same stamp with another alpha, or with the buffers swapped, is formed anew.
    ASSERT_TRUE(b.Upload(*qPrev, std::as_bytes(std::span(second))).has_value());
    EXPECT_EQ(Draw(b, p, *qPrev, *qCur, *t, 9), Fresh(p, second, first, T));
    const LayersParams later = Params(0.25f);
    EXPECT_EQ(Draw(b, later, *qPrev, *qCur, *t, 9), Fresh(later, second, first, T));
    EXPECT_EQ(Draw(b, later, *qCur, *qPrev, *t, 9), Fresh(later, first, second, T));
}

// Runs `scene` on the CPU; at every rendering step, each camera's image equals a fresh backend's call with stamp 0
// on the run's q_prev, q_cur and T at the step's last frame.
void ExpectFramesAsFreshCalls(const Scene& scene) {
    cpu::BackendCpu backend(2);
    auto sim = Simulation::Create(scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    const uint32_t frames = std::max(scene.render.framesPerStep, 1u);
    uint32_t compared = 0;
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord record;
        const Status s = (*sim)->Step(record, [&](const Simulation& at) -> Status {
            if (record.framesRendered == 0) return {};
            cpu::BackendCpu fresh(2);
            auto copy = [&](const Buffer* from) {
                return test::MakeFilled(fresh, BufferFormat::F32, from->Extent(), test::Read<float>(backend, *from));
            };
            auto qPrev = copy(at.QPrev()), qCur = copy(at.Q()), T = copy(at.T());
            for (size_t n = 0; n < scene.render.cameras.size(); ++n) {
                const LayersParams p = MakeLayersParams(scene, scene.render.cameras[n], t, frames - 1, frames);
                EXPECT_EQ(test::Read<float>(backend, *at.Get(Resource::LayersImage, n)),
                          Draw(fresh, p, *qPrev, *qCur, *T, 0))
                    << "step " << t << ", camera " << n;
                ++compared;
            }
            return {};
        });
        ASSERT_TRUE(s.has_value()) << s.error().message;
    }
    EXPECT_GE(compared, 3u * scene.steps);
}

TEST(LayersKeptVolume, LoopFramesEqualFreshCalls) {
    const std::string layers = std::string(CLOUDBENCH_SCENES_DIR) + "/layers-small.json";
    const std::vector<SceneOverride> small{
        {"render.width", "40"}, {"render.height", "30"}, {"warmup_steps", "0"}, {"render.every_steps", "1"}};
    // The automaton's clouds, new every step.
    std::vector<SceneOverride> changing = small;
    changing.insert(changing.end(), {{"steps", "4"},
                                     {"grid.tiling", "false"},
                                     {"stages", R"(["region", "ca", "smooth", "shade", "render_layers"])"},
                                     {"ca.p_act", "0.05"}});
    auto a = LoadScene(layers, changing);
    ASSERT_TRUE(a.has_value()) << a.error().message;
    ExpectFramesAsFreshCalls(*a);
    // Static noise under a moving sun (T rewritten in place every step, q's buffers unchanged), one frame a step at
    // alpha 1 and three frames a step at 1/3, 2/3 and 1 (the scene's own alpha and sun angles removed: the frames
    // and the path set them).
    std::ifstream file(layers);
    nlohmann::json root = nlohmann::json::parse(file);
    root["render"].erase("alpha");
    root["sun"].erase("elevation_deg");
    root["sun"].erase("azimuth_deg");
    for (const char* frames : {"1", "3"}) {
        std::vector<SceneOverride> still = small;
        still.insert(still.end(), {{"steps", "3"},
                                   {"render.frames_per_step", frames},
                                   {"sun.path", R"([{"step": 0, "elevation_deg": 20, "azimuth_deg": 10},
                                                    {"step": 2, "elevation_deg": 60, "azimuth_deg": 80}])"}});
        auto b = ParseScene(root.dump(), "layers-small.json", still);
        ASSERT_TRUE(b.has_value()) << b.error().message;
        SCOPED_TRACE(std::string("frames a step: ") + frames);
        ExpectFramesAsFreshCalls(*b);
    }
}

}  // namespace
}  // namespace cb
