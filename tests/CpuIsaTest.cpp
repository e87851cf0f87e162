// The CPU kernels' SIMD targets (impl_cpu/CpuIsa.h): choosing one, and the
// same bits from every target for every stage and renderer of the CPU backend.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/pipeline/StageDescriptor.h"
#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
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
        // Each frame's counters but how full the SIMD lanes were (which the lane count sets), as an output.
        for (const FrameRecord& frame : record.frames) {
            Output out{"step " + std::to_string(t) + ": counters of " + std::string(StageName(frame.renderer)) +
                           ", camera " + frame.camera,
                       {}};
            const auto& fields = Describe(frame.renderer).renderer->counters;
            for (size_t i = 0; i < fields.size(); ++i) {
                if (fields[i].name.starts_with("lane_")) continue;
                const auto* bytes = reinterpret_cast<const std::byte*>(&frame.counters[i]);
                out.bytes.insert(out.bytes.end(), bytes, bytes + sizeof(frame.counters[i]));
            }
            outputs.push_back(std::move(out));
        }
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

// noise-track's clouds and cameras on a small grid of its size in metres, a small image, and `extra` on top.
std::vector<SceneOverride> MarchOptions(std::vector<SceneOverride> extra) {
    std::vector<SceneOverride> o{
        {"steps", "1"},         {"warmup_steps", "0"},  {"grid.size", "[32,32,32]"}, {"grid.voxel_size", "200"},
        {"render.width", "64"}, {"render.height", "48"}};
    o.insert(o.end(), extra.begin(), extra.end());
    return o;
}

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
    // The layers' pixels in lanes against LayersPixel, option by option: rows that end inside a packet (61
    // columns), the box without tiling, the wind's drift, LOD0's billboards, wang's opacity, the falloff,
    // relighting and fewer layers.
    {"LayersBoxWindLod0",
     "layers-small.json",
     {{"steps", "2"},
      {"render.every_steps", "1"},
      {"render.width", "61"},
      {"render.height", "37"},
      {"grid.tiling", "false"},
      {"layers.wind", "[30, -20]"},
      {"layers.lod0_radius", "600"},
      {"layers.fade", "0.4"}}},
    {"LayersWangFadeRelight",
     "layers-small.json",
     {{"render.width", "64"},
      {"render.height", "48"},
      {"layers.count", "5"},
      {"layers.fade", "0.3"},
      {"layers.relight", "\"vector\""},
      {"layers.wang", R"({"coverage": 0.6, "density": 1.3})"}}},
    {"SkyLight", "wang-sunset.json", {{"render.width", "64"}, {"render.height", "48"}, {"grid.size", "[32,32,8]"}}},
    // The ray march's rays in SIMD lanes against its scalar kernel, option by option: every camera of the track
    // (outside, at the edge of and inside the clouds), the jitter, the adaptive step with small bricks, the light
    // march with powder, tiling, no skipping, no early stop, the point light, city glow and eye scattering, every
    // phase, the sky light and the ground.
    {"MarchTrack", "noise-track.json", MarchOptions({})},
    {"MarchJitterAdaptive", "noise-track.json",
     MarchOptions({{"march.jitter", "true"},
                   {"march.adaptive.enabled", "true"},
                   {"march.adaptive.kappa", "0.3"},
                   {"march.adaptive.start", "4"},
                   {"march.skipping.brick", "2"}})},
    {"MarchLightPowderMie", "noise-track.json",
     MarchOptions({{"march.light", "\"march\""},
                   {"march.light_steps", "3"},
                   {"march.powder.enabled", "true"},
                   {"phase.function", "\"mie\""}})},
    {"MarchTiledAdaptive", "noise-track.json",
     MarchOptions({{"grid.tiling", "true"},
                   {"march.adaptive.enabled", "true"},
                   {"march.light", "\"march\""},
                   {"march.skipping.brick", "3"},
                   {"phase.function", "\"cornette-shanks\""}})},
    {"MarchNoSkipNoStop", "noise-track.json",
     MarchOptions({{"march.skipping.enabled", "false"}, {"march.epsilon", "0"}, {"phase.function", "\"none\""}})},
    {"MarchFineStep", "noise-track.json", MarchOptions({{"march.step", "0.05"}, {"render.width", "24"}})},
    {"MarchCoarseStep", "noise-track.json", MarchOptions({{"march.step", "7"}})},
    {"MarchDualLobe", "noise-track.json",
     MarchOptions({{"phase.function", "\"dual-lobe\""}, {"phase.g_backward", "-0.6"}, {"phase.blend", "0.3"}})},
    {"MarchGlowEye", "noise-track.json",
     MarchOptions({{"lighting.city_glow", R"({"blobs": [{"center": [3000, 3000], "radius": 2000}]})"},
                   {"lighting.eye_scattering", "{}"},
                   {"march.powder.enabled", "true"}})},
    {"MarchLightning", "lightning.json", MarchOptions({{"steps", "3"}})},
    // Frames 1 to 3 reprojected from the frame before, along a camera track.
    {"MarchReprojected", "noise-track.json",
     MarchOptions({{"steps", "4"},
                   {"render.every_steps", "1"},
                   {"march.reprojection", R"({"block": 2})"},
                   {"render.cameras", R"([{"name": "fly", "track": [
                       {"frame": 0, "eye": [1600, 1800, 150], "target": [4600, 4800, 1800]},
                       {"frame": 3, "eye": [1900, 2100, 260], "target": [4700, 4500, 1700]}]}])"}})},
    {"MarchSky",
     "wang-sunset.json",
     {{"render.width", "64"},
      {"render.height", "48"},
      {"grid.size", "[32,32,8]"},
      {"stages", R"(["noise", "shade", "shade_sky", "render_march"])"}}},
    {"MarchGround",
     "ground-shadow.json",
     {{"steps", "2"},
      {"warmup_steps", "0"},
      {"grid.size", "[64,64,16]"},
      {"render.width", "64"},
      {"render.height", "48"},
      {"stages", R"(["region", "ca", "smooth", "density", "shade", "shadow", "render_march"])"}}},
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

class MarchLanes : public test::OnEveryCpuIsa {};
INSTANTIATE_TEST_SUITE_P(Targets, MarchLanes, test::EveryCpuIsa(), test::CpuIsaTestName);

// Test that the ray march's lane counters add up on every camera of a track: each lane-step samples, or meets an
// empty brick, or ends a walk through empty bricks at a brick that is not (at most once per walk, and a walk
// skips at least one brick), so samples + skipped <= lane-steps <= samples + 2 skipped; the slots are the packet
// steps times the lanes, so a multiple of the lane count and at least the lane-steps. The scalar target runs one
// ray at a time and counts neither.
TEST_P(MarchLanes, CountersAddUp) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/noise-track.json", MarchOptions({}));
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    cpu::BackendCpu backend(2);
    auto sim = Simulation::Create(*scene, backend, /*everyStepOutputs=*/false);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    StepRecord record;
    ASSERT_TRUE((*sim)->Step(record).has_value());
    ASSERT_EQ(record.frames.size(), scene->render.cameras.size());
    const uint64_t lanes = GetParam() == cpu::CpuIsa::Avx512 ? 16 : GetParam() == cpu::CpuIsa::Avx2 ? 8 : 4;
    for (const FrameRecord& frame : record.frames) {
        const auto counter = [&](std::string_view name) {
            const auto& fields = Describe(Stage::RenderMarch).renderer->counters;
            for (size_t i = 0; i < fields.size(); ++i)
                if (fields[i].name == name) return frame.counters[i];
            ADD_FAILURE() << "no counter " << name;
            return uint64_t(0);
        };
        const uint64_t samples = counter("samples"), skipped = counter("bricks_skipped");
        const uint64_t steps = counter("lane_steps"), slots = counter("lane_slots");
        SCOPED_TRACE(frame.camera);
        ASSERT_GT(samples, 0u);
        if (GetParam() == cpu::CpuIsa::Scalar) {
            EXPECT_EQ(steps, 0u);
            EXPECT_EQ(slots, 0u);
            continue;
        }
        EXPECT_GE(steps, samples + skipped);
        EXPECT_LE(steps, samples + 2 * skipped);
        EXPECT_EQ(slots % lanes, 0u);
        EXPECT_GE(slots, steps);
    }
}

}  // namespace
}  // namespace cb
