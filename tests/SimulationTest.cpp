// The harness's step driver: only the work a scene needs, on the steps that need it.
#include <gtest/gtest.h>

#include "core/Scene.h"
#include "harness/Simulation.h"
#include "impl_cpu/BackendCpu.h"

namespace cb {
namespace {

Scene SmallScene(uint32_t everySteps) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
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
        if (everyStep) EXPECT_EQ(lit.size(), scene.steps);
        else EXPECT_EQ(lit, (std::vector<uint32_t>{2, 7, 11}));
    }
}

// Test that a scene without lighting stages allocates none of their buffers.
TEST(Simulation, AllocatesOnlyEnabledStages) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
                           {{"stages", R"(["region", "ca"])"}});
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

}  // namespace
}  // namespace cb
