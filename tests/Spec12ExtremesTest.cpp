// SPEC 12, "Numerical stability at the extremes", as one suite run on every
// backend. Each item is a scene (ci-small with overrides)
// run through the Simulation with every output on every step. At each step,
// every output array of every enabled stage (found through the stage
// descriptors, so a new stage's outputs are checked too) is downloaded in
// canonical form and checked: no NaN or Inf, within the resource's documented
// range, 0/1 for bit fields and occupancy, T never subnormal; then the item's
// own property, hand-derived from docs/contract.md and docs/pipeline.md.
//
// The generic checks are in tests/Spec12Outputs.cpp, the items' own
// properties in tests/Spec12Checks.cpp, the soak in tests/Spec12SoakTest.cpp.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <tuple>
#include <vector>

#include "core/math/Random.h"
#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"
#include "tests/BackendTestUtil.h"
#include "tests/Spec12Checks.h"
#include "tests/Spec12Outputs.h"

namespace cb::spec12_test {

struct Item {
    std::string name;
    std::vector<SceneOverride> overrides;
    // The item's own property, checked at every step after the generic checks.
    std::function<void(const ItemContext&)> check;
    // A value at the edge of what docs/scenes.md accepts: the scene may
    // instead be refused at load time, naming this field.
    std::string mayBeRefusedAt = "";
};

std::vector<Item> Items() {
    // Overhead, cos(90 deg) ~ 6e-17 leaves s_x, s_y tiny. At azimuth 225 both
    // are negative: column 0's taps are -1 and 0 with weights 0 and 1 (the
    // fraction 1 - 4e-17 rounds to 1), every other column's its own, so the
    // taps are exact even for an infinitely opaque neighbour.
    const std::string sunOverhead = R"({"elevation_deg": 90, "azimuth_deg": 225})";
    std::vector<Item> items;
    items.push_back({"SunOverhead", {{"sun", sunOverhead}}, [](const ItemContext& c) { CheckVerticalSun(c, true); }});
    items.push_back({"SunStraightBelow",
                     {{"sun", R"({"elevation_deg": -90, "azimuth_deg": 60})"}},
                     [](const ItemContext& c) { CheckVerticalSun(c, false); }});
    // The switches of docs/accuracy.md: z/y at azimuth 60 (elevation atan(sin 60)),
    // x/y at azimuth 45 (elevation 25), and z/x at azimuth 0 (elevation 45). The
    // simulation runs with the sun exactly on the switch; the sides are shaded on its q.
    const double zy = std::atan(std::sin(60 * kDeg));
    items.push_back({"SunOnSwitchZY",
                     {{"sun.elevation_deg", Num(zy / kDeg)}, {"sun.azimuth_deg", "60"}},
                     [zy](const ItemContext& c) { CheckAcrossSwitch(c, zy, 60 * kDeg, true); }});
    items.push_back({"SunOnSwitchXY",
                     {{"sun.elevation_deg", "25"}, {"sun.azimuth_deg", "45"}},
                     [](const ItemContext& c) { CheckAcrossSwitch(c, 25 * kDeg, 45 * kDeg, false); }});
    items.push_back({"SunOnSwitchZX",
                     {{"sun.elevation_deg", "45"}, {"sun.azimuth_deg", "0"}},
                     [](const ItemContext& c) { CheckAcrossSwitch(c, 45 * kDeg, 0, true); }});
    // Grazing: s_z = 1e-4 sends the ground shadow's tap (s_x, s_y) nz / (2 s_z)
    // ~ 8e4 cells away, outside the grid (D = 0): G = exp(0) = 1 exactly.
    // On and below the horizon, s_z <= 0: G = 1 (SPEC 7, docs/pipeline.md).
    auto groundIsLit = [](const ItemContext& c) { ExpectAll(c.now.Of(Resource::Shadow), 1, "G"); };
    items.push_back({"SunGrazing", {{"sun.elevation_deg", Num(std::asin(1e-4) / kDeg)}}, groundIsLit});
    items.push_back({"SunOnHorizon", {{"sun.elevation_deg", "0"}}, groundIsLit});
    items.push_back({"SunBelowHorizon", {{"sun.elevation_deg", "-10"}}, groundIsLit});
    items.push_back({"SunGrazingThesisForms",
                     {{"sun.elevation_deg", Num(std::asin(1e-4) / kDeg)},
                      {"shade.attenuation", "thesis"},
                      {"shadow.form", "thesis"}},
                     groundIsLit});
    // sigma = 0: every factor is exp(0) = 1, so T = 1 and G = 1 exactly (SPEC 12).
    items.push_back({"SigmaZero", {{"shade.sigma", "0"}}, [](const ItemContext& c) {
                         ExpectAll(c.now.Of(Resource::T), 1, "T");
                         ExpectAll(c.now.Of(Resource::Shadow), 1, "G");
                     }});
    // sigma = 1e6: sigma h q >= 1e6 * 50 / 64 for any q > 0, so T = 0 behind cloud.
    items.push_back({"SigmaHugeOverhead",
                     {{"shade.sigma", "1e6"}, {"sun", sunOverhead}},
                     [](const ItemContext& c) { CheckOpaqueColumns(c, true); }});
    // SPEC 12: "No stage may return NaN or Inf for any valid input". sigma and
    // voxel_size accept any finite positive number (docs/scenes.md), but
    // sigma h overflows float beyond ~3e38: such a scene must either be refused
    // or shade as opaque cloud, like sigma = 1e6 (T = 0 behind cloud, 1 on
    // clear paths; G = 0 under cloud, 1 elsewhere).
    auto opaqueOverhead = [](const ItemContext& c) {
        CheckOpaqueColumns(c, true);
        const std::vector<float>& D = c.now.Of(Resource::ColumnSum);
        std::vector<double> G(D.size());
        for (size_t n = 0; n < D.size(); ++n) G[n] = D[n] > 0 ? 0 : 1;
        EXPECT_LE(WorstDifference(c.now.Of(Resource::Shadow), G), 1e-5) << "G: 0 under cloud, 1 elsewhere";
    };
    for (const auto& [name, path, value] : std::vector<std::tuple<std::string, std::string, std::string>>{
             {"SigmaBeyondFloat", "shade.sigma", "1e39"},
             {"SigmaLargestDouble", "shade.sigma", "1.7976931348623157e308"},
             {"VoxelSizeBeyondFloat", "grid.voxel_size", "1e39"},
             {"VoxelSize1e300", "grid.voxel_size", "1e300"}}) {
        items.push_back({name, {{path, value}, {"sun", sunOverhead}}, opaqueOverhead, path});
        items.push_back({name + "Scattering",
                         {{path, value}, {"shade.scattering", R"({"enabled": true})"}, {"shade.storage", "fp16"}},
                         {},
                         path});
    }
    items.push_back({"SigmaHugeTilted", {{"shade.sigma", "1e6"}, {"shade.resolution", "2"}}, {}});
    items.push_back({"SigmaHugeScattering",
                     {{"shade.sigma", "1e6"}, {"shade.scattering", R"({"enabled": true, "albedo": 1})"}},
                     {}});
    // Empty sky: no ellipsoid, so R = 0 and no cloud ever (cld2 & R > 0):
    // q = D = 0, no occupancy, cover 0, T = G = 1, every pixel the background.
    items.push_back({"EmptyVolume", {{"ellipsoids.target_count", "0"}}, [](const ItemContext& c) {
                         ExpectAll(c.now.Of(Resource::Region), 0, "R");
                         ExpectAll(c.now.Of(Resource::Cld), 0, "cld");
                         ExpectAll(c.now.Of(Resource::Q), 0, "q");
                         ExpectAll(c.now.Of(Resource::ColumnSum), 0, "D");
                         ExpectAll(c.now.Of(Resource::Tiles), 0, "tiles");
                         ExpectAll(c.now.Of(Resource::Bands), 0, "bands");
                         EXPECT_EQ(c.now.coveredColumns, std::optional<uint32_t>(0));
                         ExpectAll(c.now.Of(Resource::T), 1, "T");
                         ExpectAll(c.now.Of(Resource::Shadow), 1, "G");
                         const std::vector<float>& image = c.now.Of(Resource::SplatImage);
                         for (size_t n = 0; n < image.size(); ++n)
                             ASSERT_EQ(image[n], float(c.scene.lighting.background[n % 3])) << "pixel value " << n;
                     }});
    items.push_back({"FullVolume", FullVolume(), CheckFullVolume});
    items.push_back({"FullVolumeSigmaHuge", Plus(FullVolume(), {{"shade.sigma", "1e6"}}), CheckFullVolume});
    items.push_back({"Grid1x1x1", Plus(FullVolume(), {{"grid.size", "[1, 1, 1]"}}), CheckFullVolume});
    items.push_back({"Grid1x1xNz", Plus(FullVolume(), {{"grid.size", "[1, 1, 16]"}}), CheckFullVolume});
    items.push_back({"Grid1x1x1Clouds", {{"grid.size", "[1, 1, 1]"}}, {}});
    items.push_back({"Grid1x1xNzClouds", {{"grid.size", "[1, 1, 16]"}, {"ca.act0", "0.05"}}, {}});
    // Sizes that are not multiples of 64 or of the tile (16) or band (4; 3).
    items.push_back({"OddSizes70x33x17", {{"grid.size", "[70, 33, 17]"}}, CheckDensityOnPartialTiles});
    items.push_back({"OddSizes65x63x5Tile7Band3",
                     {{"grid.size", "[65, 63, 5]"}, {"density.tile", "7"}, {"density.band", "3"}},
                     CheckDensityOnPartialTiles});
    items.push_back({"OddSizesFull70x33x17", Plus(FullVolume(), {{"grid.size", "[70, 33, 17]"}}),
                     [](const ItemContext& c) {
                         CheckFullVolume(c);
                         CheckDensityOnPartialTiles(c);
                     }});
    // p = 1 always fires: with R = 255 (P = Q), hum2 = act2 = 1 every step and
    // nothing is extinguished (P_ext = 0), and step 0's act makes cld = 1.
    items.push_back({"ProbabilitiesOne",
                     Plus(FullRegion(), {{"ca", R"({"hum0": 1, "act0": 1, "p_ext": 1, "p_hum": 1, "p_act": 1})"}}),
                     [](const ItemContext& c) {
                         ExpectAll(c.now.Of(Resource::Hum), 1, "hum");
                         ExpectAll(c.now.Of(Resource::Act), 1, "act");
                         ExpectAll(c.now.Of(Resource::Cld), c.now.step == 0 ? 0 : 1, "cld");
                     }});
    // p = 0 never fires: act0 = 0 and p_act = 0 leave act = 0, so nothing
    // grows, cld stays 0, and hum (hum & !act | never) keeps its initial
    // draw, rand24(seed, 0xFFFFFFFF, 1, v) < Q(0.5), at every step (SPEC 3).
    items.push_back({"ProbabilitiesZero",
                     Plus(FullRegion(), {{"ca", R"({"seed": 9, "hum0": 0.5, "act0": 0, "p_ext": 0, "p_hum": 0, "p_act": 0})"}}),
                     [](const ItemContext& c) {
                         ExpectAll(c.now.Of(Resource::Act), 0, "act");
                         ExpectAll(c.now.Of(Resource::Cld), 0, "cld");
                         const std::vector<float>& hum = c.now.Of(Resource::Hum);
                         size_t differ = 0, humid = 0;
                         for (uint32_t v = 0; v < hum.size(); ++v) {
                             const bool expected = Rand24(9, kInitialStateStep, 1, v) < QuantizeProbability(0.5);
                             differ += (hum[v] != 0) != expected;
                             humid += expected;
                         }
                         EXPECT_EQ(differ, 0u) << "hum differs from its initial draw";
                         EXPECT_NEAR(double(humid) / double(hum.size()), 0.5, 0.02);
                     }});
    const Extent3 camGrid{32, 32, 8};
    const std::string cameras = CamerasJson(camGrid, 50);
    items.push_back({"CamerasInClouds", {{"grid.size", "[32, 32, 8]"}, {"render.cameras", cameras}}, CheckCameras});
    items.push_back({"CamerasInFullVolume",
                     Plus(FullVolume(), {{"grid.size", "[32, 32, 8]"}, {"render.cameras", cameras}}),
                     CheckCameras});
    // fp16 and unorm8 storage at full resolution: T holds storage codes. At
    // f = 2 and 4, T is read trilinearly from the coarse grid's codes (not a
    // code itself): checked for range only.
    items.push_back({"StorageFp16", {{"shade.storage", "fp16"}}, CheckStorageCodes});
    items.push_back({"StorageUnorm8", {{"shade.storage", "unorm8"}}, CheckStorageCodes});
    items.push_back({"StorageFp16SigmaHuge", {{"shade.storage", "fp16"}, {"shade.sigma", "1e6"}}, CheckStorageCodes});
    items.push_back({"StorageUnorm8Thesis", {{"shade.storage", "unorm8"}, {"shade.attenuation", "thesis"}}, CheckStorageCodes});
    items.push_back({"StorageFp16Coarse", {{"shade.storage", "fp16"}, {"shade.resolution", "2"}}, {}});
    items.push_back({"StorageUnorm8Coarse", {{"shade.storage", "unorm8"}, {"shade.resolution", "4"}}, {}});
    // A strongly forward phase function makes the scattering factor exceed 1
    // (docs/pipeline.md: clamped to [0, 1]).
    items.push_back({"ScatteringStrongForwardFp16",
                     {{"shade.storage", "fp16"},
                      {"shade.scattering", R"({"enabled": true, "albedo": 1, "solid_angle": 1})"},
                      {"phase.g", "0.9"}},
                     {}});
    return items;
}

// Every item shares: ci-small, kSteps steps from step 0, a 64 x 48 image.
std::vector<SceneOverride> BaseOverrides() {
    return {{"steps", std::to_string(kSteps)}, {"warmup_steps", "0"}, {"render.width", "64"}, {"render.height", "48"}};
}

// Runs one SPEC 12 item on one backend: every output of every enabled stage
// at every step is finite and in its documented range, and the item's own property holds.
void RunItem(Backend& backend, const Item& item) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", Plus(BaseOverrides(), item.overrides));
    if (!scene && !item.mayBeRefusedAt.empty()) {
        EXPECT_NE(scene.error().message.find(item.mayBeRefusedAt), std::string::npos) << scene.error().message;
        return;
    }
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    auto sim = Simulation::Create(*scene, backend, /*everyStepOutputs=*/true);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    size_t arrays = 0;
    Snapshot first;
    for (uint32_t t = 0; t < scene->steps; ++t) {
        StepRecord record;
        const Status status = (*sim)->Step(record, [&](const Simulation& s) -> Status {
            const Snapshot now = CheckEveryOutput(s, t, record.coveredColumns, arrays);
            if (t == 0) first = now;
            if (item.check) item.check({*scene, s, backend, now, first});
            return {};
        });
        ASSERT_TRUE(status.has_value()) << "step " << t << ": " << status.error().message;
    }
    // After the last step the automaton's next state is current: check it too.
    CheckEveryOutput(**sim, scene->steps, std::nullopt, arrays);
    // Every buffer the enabled stages write (less the automaton's next-step
    // buffers, swapped in each step) was checked after every step.
    size_t perStep = 0;
    for (const PlannedBuffer& planned : PlanBuffers(*scene)) perStep += planned.role != BufferRole::Next;
    EXPECT_EQ(arrays, perStep * (scene->steps + 1));
}

class Spec12Extremes : public ::testing::TestWithParam<std::string> {};

// Test every SPEC 12 item on one backend (RunItem). One test per backend, the
// items in a loop, each failure naming its item: one process per item and
// backend cost more in start-up than the items themselves (docs: reports/reliability/spec12.md).
TEST_P(Spec12Extremes, EveryItemEveryOutputFiniteAndInRange) {
    std::string whyNot;
    Backend* backend = BackendFor(GetParam(), whyNot);
    if (!backend) GTEST_SKIP() << "unsupported here: " << whyNot;
    for (const Item& item : Items()) {
        SCOPED_TRACE("item " + item.name);
        const auto start = std::chrono::steady_clock::now();
        RunItem(*backend, item);
        std::printf("%s %s: %.0f ms\n", GetParam().c_str(), item.name.c_str(),
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, Spec12Extremes, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace cb::spec12_test
