// `conform` walks the stage descriptors: every stage's outputs are compared by
// its own rule. A CPU backend with one deliberate fault per stage must fail
// exactly that stage's row, and only when the fault exceeds the rule.
#include <gtest/gtest.h>

#include <type_traits>

#include "core/plan/SceneLoad.h"
#include "harness/conform/Conform.h"
#include "impl_cpu/BackendCpu.h"

namespace cb {
namespace {

// The CPU backend with one stage's output changed after it ran.
class FaultyCpu : public cpu::BackendCpu {
  public:
    FaultyCpu(Stage stage, float amount) : mStage(stage), mAmount(amount) {}

    Status Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region, SliceRange slices = {}) override {
        CB_TRY(cpu::BackendCpu::Region(ellipsoids, region, slices));
        return mStage == Stage::Region ? Bump<uint8_t>(region) : Status{};
    }
    Status CaStep(const CaStepParams& p, ConstCaFields in, const Buffer& region, CaFields out) override {
        CB_TRY(cpu::BackendCpu::CaStep(p, in, region, out));
        return mStage == Stage::Ca ? Bump<uint8_t>(*out.cld) : Status{};
    }
    Status Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices = {}) override {
        CB_TRY(cpu::BackendCpu::Smooth(radius, cld, q, slices));
        return mStage == Stage::Smooth ? Bump<float>(q) : Status{};
    }
    Status Shade(const ShadeParams& p, const Buffer& q, Buffer& T) override {
        CB_TRY(cpu::BackendCpu::Shade(p, q, T));
        return mStage == Stage::Shade ? Bump<float>(T) : Status{};
    }
    Status Shadow(const ShadowParams& p, const Buffer& D, Buffer& G) override {
        CB_TRY(cpu::BackendCpu::Shadow(p, D, G));
        return mStage == Stage::Shadow ? Bump<float>(G) : Status{};
    }
    Status RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& image, SplatStats* stats) override {
        CB_TRY(cpu::BackendCpu::RenderSplat(p, in, image, stats));
        return mStage == Stage::RenderSplat ? Bump<float>(image) : Status{};
    }

  private:
    // Changes the middle element by mAmount (a bit field's: flips it).
    template <typename T>
    Status Bump(Buffer& buffer) {
        std::vector<T> data(buffer.CanonicalBytes() / sizeof(T));
        CB_TRY(Download(buffer, std::as_writable_bytes(std::span(data))));
        T& v = data[data.size() / 2];
        if constexpr (std::is_integral_v<T>)
            v = buffer.Format() == BufferFormat::Bits ? T(v ^ 1) : T(v + T(mAmount));
        else
            v = v + mAmount;
        return Upload(buffer, std::as_bytes(std::span(data)));
    }
    Stage mStage;
    float mAmount;
};

std::string StatusOf(const std::vector<ConformRow>& rows, Stage stage) {
    for (const ConformRow& r : rows)
        if (r.stage == StageName(stage)) return r.status;
    return "missing";
}

Scene SmallScene() {
    auto scene =
        LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", {{"steps", "2"}, {"warmup_steps", "0"}});
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    return *scene;
}

std::vector<ConformRow> Conform(Stage faulty, float amount, StorageFormat storage = StorageFormat::Fp32) {
    Scene scene = SmallScene();
    scene.shade.storage = storage;
    cpu::BackendCpu reference;
    std::vector<OpenedBackend> others(1);
    others[0].name = "faulty";
    others[0].backend = std::make_unique<FaultyCpu>(faulty, amount);
    others[0].status = BackendStatus::Available;
    auto rows = RunConformance(scene, reference, others);
    EXPECT_TRUE(rows.has_value()) << rows.error().message;
    return rows ? *rows : std::vector<ConformRow>{};
}

// Test that a fault beyond each stage's rule fails that stage's row and no other
// (region: 2 > |dR| <= 1; exact stages: any change; T and G: 1e-4 > 1e-5;
// image: 0.1 > 8/255).
TEST(ConformRules, EachStageFailsItsOwnRow) {
    const std::pair<Stage, float> faults[] = {{Stage::Region, 2},           {Stage::Ca, 0},
                                              {Stage::Smooth, 1.0f / 4096}, {Stage::Shade, 1e-4f},
                                              {Stage::Shadow, 1e-4f},       {Stage::RenderSplat, 0.1f}};
    for (auto [faulty, amount] : faults) {
        const std::vector<ConformRow> rows = Conform(faulty, amount);
        for (Stage stage :
             {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density, Stage::Shade, Stage::Shadow, Stage::RenderSplat})
            EXPECT_EQ(StatusOf(rows, stage), stage == faulty ? "fail" : "pass")
                << "fault in " << StageName(faulty) << ", row " << StageName(stage);
    }
}

// Test that faults within a rule pass: |dR| = 1 on one voxel, |dT| = |dG| = 5e-6,
// and one pixel off by 0.02 (under 8/255, one pixel of 0.1 % allowed over 2/255).
TEST(ConformRules, FaultsWithinTheRulePass) {
    const std::pair<Stage, float> faults[] = {
        {Stage::Region, 1}, {Stage::Shade, 5e-6f}, {Stage::Shadow, 5e-6f}, {Stage::RenderSplat, 0.02f}};
    for (auto [faulty, amount] : faults) {
        const std::vector<ConformRow> rows = Conform(faulty, amount);
        EXPECT_EQ(StatusOf(rows, faulty), "pass") << "fault in " << StageName(faulty);
    }
}

// Test that unorm8 T is compared on its stored codes (SPEC 6): one
// code lower passes even where the float difference exceeds 1/255 by an ulp,
// two codes lower fail. (Lower, since T = 1 is common and higher would clamp.)
TEST(ConformRules, Unorm8ShadeIsComparedOnCodes) {
    EXPECT_EQ(StatusOf(Conform(Stage::Shade, -1.0f / 255.0f, StorageFormat::Unorm8), Stage::Shade), "pass");
    EXPECT_EQ(StatusOf(Conform(Stage::Shade, -1.00001f / 255.0f, StorageFormat::Unorm8), Stage::Shade), "pass");
    EXPECT_EQ(StatusOf(Conform(Stage::Shade, -2.0f / 255.0f, StorageFormat::Unorm8), Stage::Shade), "fail");
}

}  // namespace
}  // namespace cb
