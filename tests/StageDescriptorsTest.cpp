// The stage list, the descriptors and the scheduler (core/scene/Stage.h,
// core/plan/StageGraph.h). Every backend shares them, so a differential test
// cannot see a mistake here: each is checked against hand-worked cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/plan/StageGraph.h"
#include "impl_cpu/BackendCpu.h"

namespace cb {
namespace {

// Test that the list expands consistently: names round-trip, SPEC sections
// are the documented ones, and each descriptor sits at its stage's index.
TEST(StageList, NamesSectionsAndDescriptorsAgree) {
    EXPECT_EQ(kStageCount, 11u);
    for (Stage s : kAllStages) {
        EXPECT_EQ(ParseStage(StageName(s)), s);
        EXPECT_EQ(Describe(s).stage, s);
    }
    EXPECT_EQ(StageName(Stage::RenderSplat), "render_splat");
    EXPECT_EQ(StageSpecSection(Stage::Shade), "6");
    EXPECT_EQ(StageSpecSection(Stage::Noise), "10a");
    EXPECT_EQ(StageName(Stage::ShadeSky), "shade_sky");
    EXPECT_EQ(StageSpecSection(Stage::ShadeSky), "16");
    EXPECT_EQ(StageName(Stage::RenderLayers), "render_layers");
    EXPECT_EQ(StageSpecSection(Stage::RenderLayers), "15");
    EXPECT_FALSE(IsSplatPipelineStage(Stage::RenderLayers));
    EXPECT_TRUE(IsSplatPipelineStage(Stage::Ca));
    EXPECT_FALSE(IsSplatPipelineStage(Stage::RenderMarch));
    EXPECT_FALSE(ParseStage("smoth").has_value());
}

// A backend that overrides no stage entry: the CPU's buffers, nothing else.
class NoStagesBackend : public Backend {
  public:
    std::string Name() const override { return "none"; }
    std::string Device() const override { return "none"; }
    bool Supports(Stage) const override { return false; }
    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override {
        return mCpu.CreateBuffer(format, extent);
    }
    Status Upload(Buffer& b, std::span<const std::byte> c) override { return mCpu.Upload(b, c); }
    Status Download(const Buffer& b, std::span<std::byte> c) override { return mCpu.Download(b, c); }

  private:
    cpu::BackendCpu mCpu{1};
};

// Test that an entry point a backend does not override reports the stage by name.
TEST(StageList, UnimplementedEntryIsUnsupported) {
    NoStagesBackend backend;
    auto q = backend.CreateBuffer(BufferFormat::F32, {4, 4, 4});
    ASSERT_TRUE(q.has_value());
    Status s = backend.Noise(NoiseParams{}, **q);
    ASSERT_FALSE(s.has_value());
    EXPECT_EQ(s.error().message, "none does not implement stage 'noise'");
    EXPECT_TRUE(cpu::BackendCpu().Supports(Stage::Noise));
}

// Test the splat pipeline's schedule: producers first, the automaton (which
// advances the state it and smooth/density read) last.
TEST(StageSchedule, SplatPipelineOrder) {
    const StageSet all{Stage::Ca,    Stage::RenderSplat, Stage::Shadow, Stage::Region,
                       Stage::Shade, Stage::Density,     Stage::Smooth};
    EXPECT_EQ(ScheduleStages(all), (std::vector<Stage>{Stage::Region, Stage::Smooth, Stage::Density, Stage::Shade,
                                                       Stage::Shadow, Stage::RenderSplat, Stage::Ca}));
    EXPECT_EQ(ScheduleStages({Stage::Region, Stage::Ca}), (std::vector<Stage>{Stage::Region, Stage::Ca}));
    EXPECT_EQ(ScheduleStages({Stage::Shade, Stage::Noise}), (std::vector<Stage>{Stage::Noise, Stage::Shade}));
    EXPECT_TRUE(ScheduleStages({}).empty());
}

// Test the producers and missing inputs: q has two producers; density's cld is optional.
TEST(StageSchedule, MissingInputsNameTheirProducers) {
    EXPECT_EQ(ProducerOf(Resource::Q, {Stage::Noise, Stage::Density}), Stage::Noise);
    EXPECT_EQ(ProducerOf(Resource::Q, {Stage::Ca, Stage::Smooth}), Stage::Smooth);
    EXPECT_FALSE(ProducerOf(Resource::T, {Stage::Smooth}).has_value());

    EXPECT_TRUE(MissingInputs({Stage::Noise, Stage::Density, Stage::Shade}).empty());
    const std::vector<MissingInput> missing = MissingInputs({Stage::Density, Stage::Shadow});
    ASSERT_EQ(missing.size(), 1u);
    EXPECT_EQ(missing[0].stage, Stage::Density);
    EXPECT_EQ(missing[0].resource, Resource::Q);
    EXPECT_EQ(missing[0].producers, (std::vector<Stage>{Stage::Smooth, Stage::Noise}));
    // The automaton reads its own state: only region is missing.
    const std::vector<MissingInput> ca = MissingInputs({Stage::Ca});
    ASSERT_EQ(ca.size(), 1u);
    EXPECT_EQ(ca[0].resource, Resource::Region);
}

// Test the resource plan: what is allocated, double-buffered and kept for the
// previous step, on scenes that differ in one setting.
TEST(StagePlan, AllocatesWhatEnabledStagesWrite) {
    Scene scene;
    scene.stages = {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density, Stage::Shade, Stage::RenderSplat};
    ResourcePlan plan = PlanResources(scene);
    auto used = [&](Resource r) { return plan.used[size_t(r)]; };
    EXPECT_TRUE(used(Resource::Region) && used(Resource::Cld) && used(Resource::Q) && used(Resource::T));
    EXPECT_TRUE(used(Resource::SplatImage));
    EXPECT_FALSE(used(Resource::Shadow));
    EXPECT_FALSE(used(Resource::MarchImage));
    EXPECT_TRUE(plan.doubleBuffered[size_t(Resource::Hum)]);
    EXPECT_FALSE(plan.doubleBuffered[size_t(Resource::Q)]);
    EXPECT_TRUE(plan.previous[size_t(Resource::Q)]);
    EXPECT_TRUE(plan.previous[size_t(Resource::Bands)]);
    scene.splat.skipping = false;  // no skipping: no previous occupancy
    plan = PlanResources(scene);
    EXPECT_TRUE(plan.previous[size_t(Resource::Q)]);
    EXPECT_FALSE(plan.previous[size_t(Resource::Tiles)]);
    EXPECT_FALSE(plan.previous[size_t(Resource::Bands)]);
}

// Test resource shapes on an odd grid: tiles and bands round up, images are (3, width, height).
TEST(StagePlan, ResourceShapes) {
    Scene scene;
    scene.grid.size = {70, 33, 17};
    scene.density.tile = 32;
    scene.density.band = 4;
    scene.render.width = 20;
    scene.render.height = 10;
    EXPECT_EQ(ResourceExtent(Resource::Q, scene), (Extent3{70, 33, 17}));
    EXPECT_EQ(ResourceExtent(Resource::ColumnSum, scene), (Extent3{70, 33, 1}));
    EXPECT_EQ(ResourceExtent(Resource::Tiles, scene), (Extent3{3, 2, 1}));
    EXPECT_EQ(ResourceExtent(Resource::Bands, scene), (Extent3{3, 2, 5}));
    EXPECT_EQ(ResourceExtent(Resource::SplatImage, scene), (Extent3{3, 20, 10}));
    EXPECT_EQ(ResourceFormat(Resource::Cld), BufferFormat::Bits);
    EXPECT_EQ(ResourceFormat(Resource::Region), BufferFormat::U8);
    EXPECT_EQ(ResourceDumpStem(Resource::ColumnSum), "density");
    EXPECT_EQ(ResourceDumpStem(Resource::SplatImage), "");
    EXPECT_TRUE(IsPerCamera(Resource::SplatImage));
    EXPECT_FALSE(IsPerCamera(Resource::T));
    // Every image is per camera with the image's extent; the volumes have the grid's (SPEC 0's table).
    for (Resource r : {Resource::MarchImage, Resource::LayersImage}) {
        EXPECT_TRUE(IsPerCamera(r));
        EXPECT_EQ(ResourceExtent(r, scene), (Extent3{3, 20, 10}));
    }
    for (Resource r : {Resource::Region, Resource::Hum, Resource::Act, Resource::Cld, Resource::T}) {
        EXPECT_FALSE(IsPerCamera(r));
        EXPECT_EQ(ResourceExtent(r, scene), (Extent3{70, 33, 17}));
    }
    EXPECT_EQ(ResourceExtent(Resource::Shadow, scene), (Extent3{70, 33, 1}));
}

// Test that the renderers are the stages that write an image, and that their names join for messages and help.
TEST(StageList, RenderersAreTheImageWriters) {
    std::vector<Stage> imageWriters;
    for (Stage s : kAllStages)
        if (std::ranges::any_of(Describe(s).writes, IsPerCamera)) imageWriters.push_back(s);
    EXPECT_EQ(RendererStages(), imageWriters);
    EXPECT_EQ(RendererStages(), (std::vector<Stage>{Stage::RenderSplat, Stage::RenderMarch, Stage::RenderLayers}));
    EXPECT_EQ(RendererNames(" or "), "render_splat, render_march or render_layers");
    EXPECT_EQ(RendererNames(", "), "render_splat, render_march, render_layers");
}

// Test that each stage's reader owns distinct top-level keys, none of them a shared section's.
TEST(StageList, SceneKeysAreOwnedOnce) {
    std::vector<std::string_view> keys = {"name", "description", "grid",      "steps", "warmup_steps", "stages",
                                          "sun",  "lighting",    "lightning", "phase", "render"};
    for (Stage s : kAllStages) {
        const StageDescriptor& d = Describe(s);
        // shade_sky alone has no settings of its own (it takes shade's and lighting.sky).
        EXPECT_EQ(bool(d.readSettings), s != Stage::ShadeSky) << StageName(s);
        for (std::string_view key : d.sceneKeys) {
            EXPECT_EQ(std::ranges::count(keys, key), 0) << key;
            keys.push_back(key);
        }
    }
    EXPECT_EQ(keys.size(), 11u + 9u);  // every stage but render_splat and shade_sky owns one section
}

// Test the comparison rules as SPEC states them, and their texts.
TEST(StageRules, SpecRulesAndTexts) {
    Scene scene;
    const auto text = [&](Stage s) { return Describe(s).rule(scene).Text(Describe(s).symbol); };
    EXPECT_EQ(text(Stage::Region), "|dR| <= 1, <= 0.5 % differ");
    EXPECT_EQ(text(Stage::Ca), "bit-exact");
    EXPECT_EQ(text(Stage::Shade), "|dT| <= 1e-05");
    EXPECT_EQ(text(Stage::Shadow), "|dG| <= 1e-05");
    EXPECT_EQ(text(Stage::RenderSplat), "2/255 on 99.9 %, 8/255 max");
    EXPECT_EQ(text(Stage::RenderMarch), "0.0001 on 99.9 %");
    EXPECT_EQ(text(Stage::Noise), "|dq| <= 1e-05");
    scene.shade.storage = StorageFormat::Unorm8;  // one storage quantum, on the stored codes (SPEC 6)
    const CompareRule codes = Describe(Stage::Shade).rule(scene);
    EXPECT_EQ(codes.kind, CompareRule::Kind::Codes);
    EXPECT_EQ(codes.tolerance, 1.0);
    EXPECT_EQ(codes.storage, StorageFormat::Unorm8);
    EXPECT_EQ(text(Stage::Shade), "|dT| <= 1 unorm8 code");
    scene.shade.storage = StorageFormat::Fp16;
    EXPECT_EQ(text(Stage::Shade), "|dT| <= 1 fp16 code");
    const CompareRule image = Describe(Stage::RenderSplat).rule(scene);
    EXPECT_EQ(image.kind, CompareRule::Kind::Image);
    EXPECT_DOUBLE_EQ(image.share, 0.001);
}

}  // namespace
}  // namespace cb
