// The harness's step driver: only the work a scene needs, on the steps that need it.
#include <gtest/gtest.h>

#include <cmath>

#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

Scene SmallScene(uint32_t everySteps) {
    auto scene =
        LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
                  {{"steps", "12"}, {"warmup_steps", "2"}, {"render.every_steps", std::to_string(everySteps)}});
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    return *scene;
}

// Test that shade, shadow and the renderer run only on render steps (every 5
// steps after the 2 warm-up steps, and the last), while the simulation stages
// run every step; and that a dump's driver lights every step.
TEST(Simulation, LightingRunsOnlyOnOutputSteps) {
    const Scene scene = SmallScene(5);
    cpu::BackendCpu backend;
    for (bool everyStep : {false, true}) {
        auto sim = Simulation::Create(scene, backend, everyStep);
        ASSERT_TRUE(sim.has_value()) << sim.error().message;
        std::vector<uint32_t> lit;
        for (uint32_t t = 0; t < scene.steps; ++t) {
            StepRecord r;
            ASSERT_TRUE((*sim)->Step(r).has_value());
            EXPECT_TRUE(r.stageMs[size_t(Stage::Ca)].has_value());
            EXPECT_TRUE(r.stageMs[size_t(Stage::Smooth)].has_value());
            const bool shaded = r.stageMs[size_t(Stage::Shade)].has_value();
            EXPECT_EQ(shaded, r.stageMs[size_t(Stage::Shadow)].has_value());
            EXPECT_EQ(shaded, !r.frames.empty());
            if (shaded) lit.push_back(t);
        }
        if (everyStep)
            EXPECT_EQ(lit.size(), scene.steps);
        else
            EXPECT_EQ(lit, (std::vector<uint32_t>{2, 7, 11}));
    }
}

// Test that a scene without lighting stages allocates none of their buffers.
TEST(Simulation, AllocatesOnlyEnabledStages) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", {{"stages", R"(["region", "ca"])"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    cpu::BackendCpu backend;
    auto sim = Simulation::Create(*scene, backend);
    ASSERT_TRUE(sim.has_value());
    EXPECT_NE((*sim)->Region(), nullptr);
    EXPECT_NE((*sim)->Cld(), nullptr);
    EXPECT_EQ((*sim)->Q(), nullptr);
    EXPECT_EQ((*sim)->ColumnSum(), nullptr);
    EXPECT_EQ((*sim)->T(), nullptr);
    EXPECT_EQ((*sim)->Shadow(), nullptr);
    EXPECT_EQ((*sim)->Image(0), nullptr);
}

// A test-only producer of q in place of the automaton and smoothing: a
// Gaussian blob whose centre moves one voxel along x per step.
class BlobProducer : public cpu::BackendCpu {
  public:
    static float Q(const Extent3& e, uint32_t step, uint32_t i, uint32_t j, uint32_t k) {
        const double x = double(i) - (double(e.nx) / 3 + step), y = double(j) - e.ny / 2.0, z = double(k) - e.nz / 2.0;
        const double q = std::exp(-(x * x + y * y + 4 * z * z) / 40.0);
        return q > 0.05 ? float(q) : 0.0f;
    }
    bool Supports(Stage stage) const override { return stage == Stage::Noise || cpu::BackendCpu::Supports(stage); }
    Status Noise(const NoiseParams& params, Buffer& q) override {
        ++calls;
        const Extent3 e = q.Extent();
        std::vector<float> values(e.Count());
        for (uint32_t k = 0; k < e.nz; ++k)
            for (uint32_t j = 0; j < e.ny; ++j)
                for (uint32_t i = 0; i < e.nx; ++i) values[VoxelIndex(e, i, j, k)] = Q(e, params.step, i, j, k);
        return Upload(q, std::as_bytes(std::span(values)));
    }
    int calls = 0;
};

// Test that a scene whose q comes from a producer other than smooth runs: the
// stages are scheduled by what they read (the producer first, the automaton's
// fields never allocated), density sums the producer's q and, without cld,
// counts the columns with D > 0 as the cover; shade and the renderer consume it.
TEST(Simulation, AnotherProducerOfQ) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
                           {{"steps", "3"},
                            {"warmup_steps", "0"},
                            {"stages", R"(["noise", "density", "shade", "shadow", "render_splat"])"},
                            {"noise.drift", "[1, 0, 0]"}});  // animated: the producer runs every step
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    BlobProducer backend;
    auto sim = Simulation::Create(*scene, backend, /*everyStepOutputs=*/true);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    EXPECT_EQ((*sim)->Schedule(),
              (std::vector<Stage>{Stage::Noise, Stage::Density, Stage::Shade, Stage::Shadow, Stage::RenderSplat}));
    EXPECT_EQ((*sim)->Cld(), nullptr);
    EXPECT_EQ((*sim)->Region(), nullptr);
    const Extent3 e = scene->grid.size;
    for (uint32_t t = 0; t < scene->steps; ++t) {
        StepRecord r;
        Status s = (*sim)->Step(r);
        ASSERT_TRUE(s.has_value()) << s.error().message;
        EXPECT_TRUE(r.stageMs[size_t(Stage::Noise)].has_value());
        EXPECT_FALSE(r.stageMs[size_t(Stage::Smooth)].has_value());
        const std::vector<float> D = test::Read<float>(backend, *(*sim)->ColumnSum());
        uint32_t covered = 0;
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) {
                float sum = 0;  // k ascending, as SPEC 5 sums
                for (uint32_t k = 0; k < e.nz; ++k) sum += BlobProducer::Q(e, t, i, j, k);
                ASSERT_EQ(D[i + e.nx * j], sum) << i << "," << j << " at step " << t;
                covered += sum > 0;
            }
        ASSERT_TRUE(r.coveredColumns.has_value());
        EXPECT_EQ(*r.coveredColumns, covered);
        EXPECT_GT(covered, 0u);
        EXPECT_LT(covered, e.nx * e.ny);
        EXPECT_EQ(r.frames.size(), scene->render.cameras.size());
    }
    EXPECT_EQ(backend.calls, 3);
    // The last image shows cloud: some pixel differs from the background.
    const std::vector<float> image = test::Read<float>(backend, *(*sim)->Image(0));
    const auto& bg = scene->lighting.background;
    bool cloudy = false;
    for (size_t p = 0; p + 2 < image.size(); p += 3)
        cloudy |= std::fabs(image[p] - float(bg[0])) > 1e-3f || std::fabs(image[p + 1] - float(bg[1])) > 1e-3f;
    EXPECT_TRUE(cloudy);
}

// Test that without a producer of q the scene is refused, naming the resource.
TEST(Simulation, MissingProducerIsNamed) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", {{"stages", R"(["density"])"}});
    ASSERT_FALSE(scene.has_value());
    EXPECT_NE(scene.error().message.find(R"("density" needs "q")"), std::string::npos) << scene.error().message;
}

}  // namespace
}  // namespace cb
