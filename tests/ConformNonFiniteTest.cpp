// conform under NaN and Inf (harness/conform/Conform.cpp): a non-finite float in a backend's output, or in the
// CPU's where the backend's is finite, fails its row under every rule a float stage has (bit-exact: smooth's q;
// absolute |d| <= 1e-5: shade's T on fp32, shadow's G, noise's q; stored codes: T on unorm8 and fp16; the image
// rule with a finite limit, render_splat, and an infinite one, render_march), with worst = inf and a detail that
// names the step, the voxel or the camera, pixel and channel, and both values. Byte outputs (region) hold no NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/plan/SceneLoad.h"
#include "harness/conform/Conform.h"
#include "impl_cpu/BackendCpu.h"

namespace cb {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// The CPU backend with one element of one stage's float output set to a value after the stage ran.
class NonFiniteCpu : public cpu::BackendCpu {
  public:
    NonFiniteCpu(Stage stage, size_t element, float value) : mStage(stage), mElement(element), mValue(value) {}

    Status Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices = {}) override {
        CB_TRY(cpu::BackendCpu::Smooth(radius, cld, q, slices));
        return Plant(Stage::Smooth, q);
    }
    Status Shade(const ShadeParams& p, const Buffer& q, Buffer& T) override {
        CB_TRY(cpu::BackendCpu::Shade(p, q, T));
        return Plant(Stage::Shade, T);
    }
    Status Shadow(const ShadowParams& p, const Buffer& D, Buffer& G) override {
        CB_TRY(cpu::BackendCpu::Shadow(p, D, G));
        return Plant(Stage::Shadow, G);
    }
    Status Noise(const NoiseParams& p, Buffer& q) override {
        CB_TRY(cpu::BackendCpu::Noise(p, q));
        return Plant(Stage::Noise, q);
    }
    Status RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& image, SplatStats* stats) override {
        CB_TRY(cpu::BackendCpu::RenderSplat(p, in, image, stats));
        return Plant(Stage::RenderSplat, image);
    }
    Status RenderMarch(const MarchParams& p, const MarchInputs& in, Buffer& image, MarchStats* stats) override {
        CB_TRY(cpu::BackendCpu::RenderMarch(p, in, image, stats));
        return Plant(Stage::RenderMarch, image);
    }

  private:
    Status Plant(Stage stage, Buffer& buffer) {
        if (stage != mStage) return {};
        std::vector<float> data(buffer.CanonicalBytes() / sizeof(float));
        CB_TRY(Download(buffer, std::as_writable_bytes(std::span(data))));
        data.at(mElement) = mValue;
        return Upload(buffer, std::as_bytes(std::span(data)));
    }
    Stage mStage;
    size_t mElement;
    float mValue;
};

// One step of `scene` with `overrides`; the planted value goes into the backend "edited" or, with
// `inReference`, into the CPU reference, compared against the plain CPU as "edited".
ConformRow NonFiniteRow(const std::string& scene, std::vector<SceneOverride> overrides, Stage stage, size_t element,
                        float value, bool inReference = false) {
    overrides.push_back({"steps", "1"});
    overrides.push_back({"warmup_steps", "0"});
    auto loaded = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + scene + ".json", overrides);
    EXPECT_TRUE(loaded.has_value()) << loaded.error().message;
    if (!loaded) return {};
    std::unique_ptr<Backend> reference = std::make_unique<cpu::BackendCpu>();
    std::vector<OpenedBackend> others(1);
    others[0].name = "edited";
    others[0].backend = std::make_unique<NonFiniteCpu>(stage, element, value);
    others[0].status = BackendStatus::Available;
    if (inReference) std::swap(reference, others[0].backend);
    auto rows = RunConformance(*loaded, *reference, others);
    EXPECT_TRUE(rows.has_value()) << rows.error().message;
    if (rows)
        for (const ConformRow& r : *rows)
            if (r.stage == StageName(stage)) return r;
    ADD_FAILURE() << "no row for " << StageName(stage);
    return {};
}

// ci-small's grid is 64 x 64 x 16: voxel (5, 3, 2) is element 5 + 64 * (3 + 64 * 2) = 8389.
constexpr size_t kVoxel = 8389;
constexpr const char* kVoxelText = "step 0 at (5, 3, 2): not finite: cpu ";

void ExpectNonFiniteRow(const ConformRow& row, const std::string& where, const std::string& backendText,
                        const std::string& rule) {
    EXPECT_EQ(row.status, "fail") << row.stage << ": " << row.detail;
    EXPECT_EQ(row.rule, rule);
    EXPECT_EQ(row.worst, std::numeric_limits<double>::infinity());
    EXPECT_NE(row.detail.find(where), std::string::npos) << row.detail;
    EXPECT_NE(row.detail.find(backendText), std::string::npos) << row.detail;
}

// Test the bit-exact rule (smooth's q): NaN, +Inf and -Inf in the backend, and +Inf in the reference.
TEST(ConformNonFinite, BitExactRule) {
    ExpectNonFiniteRow(NonFiniteRow("ci-small", {}, Stage::Smooth, kVoxel, kNaN), kVoxelText, ", edited nan",
                       "bit-exact");
    ExpectNonFiniteRow(NonFiniteRow("ci-small", {}, Stage::Smooth, kVoxel, kInf), kVoxelText, ", edited inf",
                       "bit-exact");
    ExpectNonFiniteRow(NonFiniteRow("ci-small", {}, Stage::Smooth, kVoxel, -kInf), kVoxelText, ", edited -inf",
                       "bit-exact");
    const ConformRow row = NonFiniteRow("ci-small", {}, Stage::Smooth, kVoxel, kInf, /*inReference=*/true);
    ExpectNonFiniteRow(row, "step 0 at (5, 3, 2): not finite: cpu inf, edited ", "edited", "bit-exact");
    EXPECT_EQ(row.detail.find("edited inf"), std::string::npos) << row.detail;
}

// Test the absolute rule |d| <= 1e-5 (shade's T on fp32, shadow's G on its 64 x 64 columns: (5, 3) is 197).
TEST(ConformNonFinite, AbsoluteRule) {
    for (float value : {kNaN, kInf, -kInf}) {
        const std::string text = std::isnan(value) ? ", edited nan" : value > 0 ? ", edited inf" : ", edited -inf";
        ExpectNonFiniteRow(NonFiniteRow("ci-small", {}, Stage::Shade, kVoxel, value), kVoxelText, text,
                           "|dT| <= 1e-05");
        ExpectNonFiniteRow(NonFiniteRow("ci-small", {}, Stage::Shadow, 197, value),
                           "step 0 at (5, 3, 0): not finite: cpu ", text, "|dG| <= 1e-05");
    }
    // The reference's T infinite where the backend's is finite: Inf - finite is inf, over the tolerance.
    const ConformRow row = NonFiniteRow("ci-small", {}, Stage::Shade, kVoxel, -kInf, /*inReference=*/true);
    ExpectNonFiniteRow(row, "step 0 at (5, 3, 2): not finite: cpu -inf, edited ", "edited", "|dT| <= 1e-05");
}

// Test the rule on stored codes (T stored as unorm8 and fp16): a NaN has no code, so it is caught before the codes.
TEST(ConformNonFinite, CodesRule) {
    for (const char* storage : {"unorm8", "fp16"}) {
        const std::vector<SceneOverride> set = {{"shade.storage", storage}};
        for (float value : {kNaN, kInf, -kInf}) {
            const ConformRow row = NonFiniteRow("ci-small", set, Stage::Shade, kVoxel, value);
            EXPECT_EQ(row.status, "fail") << storage << ": " << row.detail;
            EXPECT_EQ(row.worst, std::numeric_limits<double>::infinity()) << storage;
            EXPECT_NE(row.detail.find(kVoxelText), std::string::npos) << row.detail;
        }
        const ConformRow row = NonFiniteRow("ci-small", set, Stage::Shade, kVoxel, kInf, /*inReference=*/true);
        EXPECT_EQ(row.status, "fail") << storage;
        EXPECT_NE(row.detail.find("step 0 at (5, 3, 2): not finite: cpu inf, edited "), std::string::npos)
            << row.detail;
    }
}

// Test the image rule with a finite limit (render_splat, 8/255): ci-small's 160 x 120 image, pixel (7, 4) channel 1
// is element 3 * (7 + 160 * 4) + 1 = 1942.
TEST(ConformNonFinite, ImageRuleFiniteLimit) {
    constexpr const char* kPixel = "step 0 camera above pixel (7, 4) channel 1: not finite: cpu ";
    for (float value : {kNaN, kInf, -kInf}) {
        const ConformRow row = NonFiniteRow("ci-small", {}, Stage::RenderSplat, 1942, value);
        EXPECT_EQ(row.status, "fail") << row.detail;
        EXPECT_EQ(row.worst, std::numeric_limits<double>::infinity());
        EXPECT_NE(row.detail.find(kPixel), std::string::npos) << row.detail;
    }
    const ConformRow row = NonFiniteRow("ci-small", {}, Stage::RenderSplat, 1942, kInf, /*inReference=*/true);
    EXPECT_EQ(row.status, "fail");
    EXPECT_NE(row.detail.find("pixel (7, 4) channel 1: not finite: cpu inf, edited "), std::string::npos) << row.detail;
}

// Test the image rule with an infinite limit (render_march: |d| <= 1e-4 on 99.9 %, no limit), where an Inf pixel
// would be within the limit, and noise's absolute rule on the way: a 32 x 24 image, pixel (31, 23) channel 2 is
// element 3 * (31 + 32 * 23) + 2 = 2303, the last.
TEST(ConformNonFinite, ImageRuleInfiniteLimit) {
    const std::vector<SceneOverride> small = {{"render.width", "32"}, {"render.height", "24"}};
    for (float value : {kNaN, kInf, -kInf}) {
        const ConformRow row = NonFiniteRow("noise-layer", small, Stage::RenderMarch, 2303, value);
        EXPECT_EQ(row.status, "fail") << row.detail;
        EXPECT_EQ(row.tolerance, std::numeric_limits<double>::infinity());
        EXPECT_NE(row.detail.find("step 0 camera above pixel (31, 23) channel 2: not finite: cpu "), std::string::npos)
            << row.detail;
    }
    const ConformRow march = NonFiniteRow("noise-layer", small, Stage::RenderMarch, 2303, kInf, true);
    EXPECT_EQ(march.status, "fail");
    EXPECT_NE(march.detail.find("channel 2: not finite: cpu inf, edited "), std::string::npos) << march.detail;
    // noise's q on its 128 x 128 x 128 grid: voxel (1, 2, 3) is element 1 + 128 * (2 + 128 * 3) = 49409.
    const ConformRow noise = NonFiniteRow("noise-layer", small, Stage::Noise, 49409, kNaN);
    ExpectNonFiniteRow(noise, "step 0 at (1, 2, 3): not finite: cpu ", ", edited nan", "|dq| <= 1e-05");
}

// Test the exit code: a non-finite row is a failed check, exit 5.
TEST(ConformNonFinite, ExitCodeFive) {
    std::vector<ConformRow> rows = {NonFiniteRow("ci-small", {}, Stage::Smooth, kVoxel, kNaN)};
    EXPECT_EQ(ConformExitCode(rows), 5);
}

}  // namespace
}  // namespace cb
