// The CPU kernels' SIMD targets (impl_cpu/CpuIsa.h): choosing one, and the
// same bits from every target for every stage and renderer of the CPU backend.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/pipeline/StageDescriptor.h"
#include "core/plan/SceneLoad.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/CpuIsaTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// Test that the list of targets starts with the scalar one, which every CPU
// runs, and that choosing a target makes it the active one, named in the
// backend's device; the automatic choice is the last (best) of the list.
TEST(CpuIsa, EveryListedTargetCanBeChosen) {
    const std::vector<cpu::CpuIsa> here = cpu::SupportedCpuIsas();
    ASSERT_FALSE(here.empty());
    EXPECT_EQ(here.front(), cpu::CpuIsa::Scalar);
    for (cpu::CpuIsa isa : here) {
        ASSERT_TRUE(cpu::SelectCpuIsa(isa).has_value()) << cpu::CpuIsaName(isa);
        EXPECT_EQ(cpu::ActiveCpuIsa(), isa);
        EXPECT_NE(cpu::BackendCpu(1).Device().find("SIMD " + std::string(cpu::CpuIsaName(isa)) + " (Highway "),
                  std::string::npos);
    }
    ASSERT_TRUE(cpu::SelectCpuIsa(cpu::CpuIsa::Auto).has_value());
    EXPECT_EQ(cpu::ActiveCpuIsa(), here.back());
}

// Test that a target this CPU lacks is refused with the targets it has, and
// that the active target stays as it was.
TEST(CpuIsa, RefusesATargetThisCpuLacks) {
    const std::vector<cpu::CpuIsa> here = cpu::SupportedCpuIsas();
    for (cpu::CpuIsa isa : {cpu::CpuIsa::Sse4, cpu::CpuIsa::Avx2, cpu::CpuIsa::Avx512}) {
        if (std::ranges::find(here, isa) != here.end()) continue;
        const cpu::CpuIsa before = cpu::ActiveCpuIsa();
        const Status s = cpu::SelectCpuIsa(isa);
        ASSERT_FALSE(s.has_value());
        EXPECT_TRUE(s.error().message.starts_with("--cpu-isa: this CPU cannot run " +
                                                  std::string(cpu::CpuIsaName(isa)) + " (it runs scalar"))
            << s.error().message;
        EXPECT_EQ(cpu::ActiveCpuIsa(), before);
        return;
    }
    GTEST_SKIP() << "unsupported here: this CPU runs every target (scalar, sse4, avx2, avx512)";
}

struct Output {
    std::string name;  // "step 2: T", "step 0: image_splat, camera 1"
    std::vector<std::byte> bytes;
};

// Every output of every step (each camera's frames too), downloaded in the
// canonical layout, for `scene` on a 2-thread CPU backend at the active target.
std::vector<Output> EveryOutput(const Scene& scene) {
    cpu::BackendCpu backend(2);
    auto sim = Simulation::Create(scene, backend, /*everyStepOutputs=*/true);
    EXPECT_TRUE(sim.has_value()) << sim.error().message;
    std::vector<Output> outputs;
    if (!sim) return outputs;
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord record;
        const Status stepped = (*sim)->Step(record);
        EXPECT_TRUE(stepped.has_value()) << stepped.error().message;
        for (Resource resource : kAllResources)
            for (size_t n = 0; n < (IsPerCamera(resource) ? scene.render.cameras.size() : 1); ++n)
                if (const Buffer* buffer = (*sim)->Get(resource, n)) {
                    Output out{"step " + std::to_string(t) + ": " + std::string(ResourceName(resource)) +
                                   (IsPerCamera(resource) ? ", camera " + std::to_string(n) : ""),
                               std::vector<std::byte>(buffer->CanonicalBytes())};
                    EXPECT_TRUE(backend.Download(*buffer, out.bytes).has_value());
                    outputs.push_back(std::move(out));
                }
    }
    return outputs;
}

struct IsaScene {
    const char* name;
    const char* file;
    std::vector<SceneOverride> overrides;
};
void PrintTo(const IsaScene& c, std::ostream* os) { *os << c.name; }

// Scenes that between them run every CPU stage with its options: the
// automaton with and without wind, fp16 and coarse shade, shade's sweep along
// each axis, the ground, the sky light, the noise, and the splat, march and
// layers renderers.
const IsaScene kIsaScenes[] = {
    {"SplatWind", "ci-small-wind.json", {{"steps", "4"}, {"warmup_steps", "1"}}},
    {"SplatCoarseFp16",
     "ci-small.json",
     {{"steps", "3"}, {"warmup_steps", "1"}, {"shade.resolution", "2"}, {"shade.storage", "\"fp16\""}}},
    // shade's sweep along x (rows transposed 16 at a time) and along z (whole planes).
    {"SunAlongX",
     "ci-small.json",
     {{"steps", "2"}, {"warmup_steps", "0"}, {"sun.azimuth_deg", "10"}, {"sun.elevation_deg", "20"}}},
    {"SunAlongZ", "ci-small.json", {{"steps", "2"}, {"warmup_steps", "0"}, {"sun.elevation_deg", "70"}}},
    {"SplatGround", "ground-shadow.json", {{"steps", "2"}, {"warmup_steps", "0"}, {"grid.size", "[64,64,16]"}}},
    {"MarchNoise",
     "noise-layer.json",
     {{"steps", "1"},
      {"warmup_steps", "0"},
      {"grid.size", "[32,32,16]"},
      {"render.width", "64"},
      {"render.height", "48"}}},
    {"Layers", "layers-small.json", {{"render.width", "64"}, {"render.height", "48"}}},
    {"SkyLight", "wang-sunset.json", {{"render.width", "64"}, {"render.height", "48"}, {"grid.size", "[32,32,8]"}}},
};

class CpuIsaSameBits : public ::testing::TestWithParam<IsaScene> {};
INSTANTIATE_TEST_SUITE_P(Scenes, CpuIsaSameBits, ::testing::ValuesIn(kIsaScenes),
                         [](const ::testing::TestParamInfo<IsaScene>& info) { return std::string(info.param.name); });

// Test that every target this CPU runs gives the scalar target's bits in
// every output of every stage (no FMA contraction, no reordering).
TEST_P(CpuIsaSameBits, EveryTargetGivesTheScalarBits) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + GetParam().file, GetParam().overrides);
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    ASSERT_TRUE(cpu::SelectCpuIsa(cpu::CpuIsa::Scalar).has_value());
    const std::vector<Output> scalar = EveryOutput(*scene);
    ASSERT_FALSE(scalar.empty());
    for (cpu::CpuIsa isa : cpu::SupportedCpuIsas()) {
        if (isa == cpu::CpuIsa::Scalar) continue;
        ASSERT_TRUE(cpu::SelectCpuIsa(isa).has_value());
        const std::vector<Output> vector = EveryOutput(*scene);
        ASSERT_EQ(vector.size(), scalar.size()) << cpu::CpuIsaName(isa);
        for (size_t n = 0; n < scalar.size(); ++n)
            EXPECT_TRUE(vector[n].bytes == scalar[n].bytes)
                << cpu::CpuIsaName(isa) << ": " << scalar[n].name << " differs";
    }
    ASSERT_TRUE(cpu::SelectCpuIsa(cpu::CpuIsa::Auto).has_value());
}

}  // namespace
}  // namespace cb
