// conform's comparison rules at their boundaries (harness/conform/Conform.cpp, the rules in docs/contract.md and
// each stage's descriptor): exactly at a tolerance passes and one step past it fails. Region (SPEC 2): |dR| <= 1
// on at most 0.5 % of the voxels, so 327 of ci-small's 65536 voxels one off pass and 328 fail; T and G on fp32:
// |d| <= 1e-5, the largest float difference not above it passes and the next float fails; bit-exact: one ulp
// fails; the image rule (SPEC 8) by its pixel share and its limit. Then the statuses and exit codes that
// ConformFeaturesTest does not reach.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "core/plan/SceneLoad.h"
#include "harness/conform/Conform.h"
#include "harness/report/Report.h"
#include "impl_cpu/BackendCpu.h"

namespace cb {
namespace {

// The CPU backend with one stage's output edited after it ran, by a function of the downloaded elements.
class BoundaryCpu : public cpu::BackendCpu {
  public:
    using EditBytes = std::function<void(std::vector<uint8_t>&)>;
    using EditFloats = std::function<void(std::vector<float>&)>;
    BoundaryCpu(Stage stage, EditBytes bytes, EditFloats floats)
        : mStage(stage), mBytes(std::move(bytes)), mFloats(std::move(floats)) {}

    Status Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region, SliceRange slices = {}) override {
        CB_TRY(cpu::BackendCpu::Region(ellipsoids, region, slices));
        return mStage == Stage::Region ? Edit<uint8_t>(region, mBytes) : Status{};
    }
    Status Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices = {}) override {
        CB_TRY(cpu::BackendCpu::Smooth(radius, cld, q, slices));
        return mStage == Stage::Smooth ? Edit<float>(q, mFloats) : Status{};
    }
    Status Shade(const ShadeParams& p, const Buffer& q, Buffer& T) override {
        CB_TRY(cpu::BackendCpu::Shade(p, q, T));
        return mStage == Stage::Shade ? Edit<float>(T, mFloats) : Status{};
    }
    Status Shadow(const ShadowParams& p, const Buffer& D, Buffer& G) override {
        CB_TRY(cpu::BackendCpu::Shadow(p, D, G));
        return mStage == Stage::Shadow ? Edit<float>(G, mFloats) : Status{};
    }

  private:
    template <typename T, typename F>
    Status Edit(Buffer& buffer, const F& edit) {
        std::vector<T> data(buffer.CanonicalBytes() / sizeof(T));
        CB_TRY(Download(buffer, std::as_writable_bytes(std::span(data))));
        if (edit) edit(data);
        return Upload(buffer, std::as_bytes(std::span(data)));
    }
    Stage mStage;
    EditBytes mBytes;
    EditFloats mFloats;
};

const ConformRow* BoundaryRow(const std::vector<ConformRow>& rows, Stage stage) {
    for (const ConformRow& r : rows)
        if (r.stage == StageName(stage)) return &r;
    return nullptr;
}

std::vector<ConformRow> BoundaryConform(Stage stage, BoundaryCpu::EditBytes bytes, BoundaryCpu::EditFloats floats) {
    auto scene =
        LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", {{"steps", "2"}, {"warmup_steps", "0"}});
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    if (!scene) return {};
    cpu::BackendCpu reference;
    std::vector<OpenedBackend> others(1);
    others[0].name = "edited";
    others[0].backend = std::make_unique<BoundaryCpu>(stage, std::move(bytes), std::move(floats));
    others[0].status = BackendStatus::Available;
    auto rows = RunConformance(*scene, reference, others);
    EXPECT_TRUE(rows.has_value()) << rows.error().message;
    return rows ? *rows : std::vector<ConformRow>{};
}

std::string BoundaryStatus(Stage stage, BoundaryCpu::EditBytes bytes, BoundaryCpu::EditFloats floats = {}) {
    const std::vector<ConformRow> rows = BoundaryConform(stage, std::move(bytes), std::move(floats));
    const ConformRow* row = BoundaryRow(rows, stage);
    return row ? row->status : "missing";
}

// Every `every`-th voxel of the first `count` (spread over the grid) one code off (down from 255, else up).
BoundaryCpu::EditBytes OneOffOn(size_t count, size_t every = 97) {
    return [count, every](std::vector<uint8_t>& r) {
        for (size_t n = 0; n < count; ++n) {
            uint8_t& v = r[(n * every) % r.size()];
            v = v == 255 ? 254 : uint8_t(v + 1);
        }
    };
}

// Test region's share: 65536 voxels (64 x 64 x 16), at most 0.5 % = 327.68 may differ (by at most 1).
TEST(ConformBoundary, RegionShareOfVoxels) {
    EXPECT_EQ(BoundaryStatus(Stage::Region, OneOffOn(327)), "pass");
    EXPECT_EQ(BoundaryStatus(Stage::Region, OneOffOn(328)), "fail");
    // |dR| = 2 on one voxel: over the tolerance, whatever the share.
    EXPECT_EQ(BoundaryStatus(Stage::Region,
                             [](std::vector<uint8_t>& r) { r[100] = r[100] >= 128 ? r[100] - 2 : r[100] + 2; }),
              "fail");
}

// The float nearest `v` on its side of the tolerance: the farthest from v (going up where v < 0.5, down otherwise)
// with |x - v| <= tolerance in double when `within`, else the next float past it.
float BoundaryFloat(float v, double tolerance, bool within) {
    const float direction = v < 0.5f ? 2.0f : -1.0f;
    float x = v;
    // Walk by the tolerance, then ulp by ulp: the first float past the tolerance, and the one before it.
    while (std::fabs(double(x) - double(v)) <= tolerance) x = std::nextafter(x, direction);
    float inside = std::nextafter(x, v);
    EXPECT_LE(std::fabs(double(inside) - double(v)), tolerance);
    EXPECT_GT(std::fabs(double(x) - double(v)), tolerance);
    return within ? inside : x;
}

BoundaryCpu::EditFloats MiddleAt(double tolerance, bool within) {
    return [tolerance, within](std::vector<float>& f) {
        float& v = f[f.size() / 2];
        v = BoundaryFloat(v, tolerance, within);
    };
}

// Test T and G (fp32) at |d| = 1e-5: the largest float difference within it passes, the next float fails.
TEST(ConformBoundary, AbsoluteToleranceToTheUlp) {
    for (Stage stage : {Stage::Shade, Stage::Shadow}) {
        EXPECT_EQ(BoundaryStatus(stage, {}, MiddleAt(1e-5, true)), "pass") << StageName(stage);
        EXPECT_EQ(BoundaryStatus(stage, {}, MiddleAt(1e-5, false)), "fail") << StageName(stage);
    }
    // The worst difference is reported, and the tolerance beside it.
    const std::vector<ConformRow> rows = BoundaryConform(Stage::Shade, {}, MiddleAt(1e-5, true));
    const ConformRow* row = BoundaryRow(rows, Stage::Shade);
    ASSERT_NE(row, nullptr);
    EXPECT_EQ(row->tolerance, 1e-5);
    EXPECT_LE(row->worst, 1e-5);
    EXPECT_GT(row->worst, 0.9e-5);
}

// Test bit-exactness: q (smooth) one ulp off fails.
TEST(ConformBoundary, BitExactFailsOnOneUlp) {
    EXPECT_EQ(BoundaryStatus(Stage::Smooth, {},
                             [](std::vector<float>& q) {
                                 float& v = q[q.size() / 2];
                                 v = std::nextafter(v, 2.0f);
                             }),
              "fail");
    EXPECT_EQ(BoundaryStatus(Stage::Smooth, {}, [](std::vector<float>&) {}), "pass");
}

// Test the image rule with values a float holds exactly: per channel |d| <= tolerance on at least 1 - share of the
// pixels and <= limit everywhere. 100 x 100 pixels and share 0.001: 10 pixels over the tolerance pass, 11 fail; a
// difference of exactly the tolerance is not over it; exactly the limit passes, the next float fails.
TEST(ConformBoundary, ImageRuleSharesAndLimit) {
    const uint32_t W = 100, H = 100;
    CompareRule rule{CompareRule::Kind::Image, 0.25, 0.001, 0.5};
    const std::vector<float> a(3 * W * H, 0.125f);
    auto over = [&](size_t pixels, float by) {
        std::vector<float> b = a;
        for (size_t n = 0; n < pixels; ++n) b[3 * (n * 37 % (W * H)) + n % 3] += by;
        return CompareImages(a, b, W, H, rule).value();
    };
    ImageComparison c = over(10, 0.375f);
    EXPECT_EQ(c.pixelsOverTolerance, 10u);
    EXPECT_TRUE(c.Passes());
    c = over(11, 0.375f);
    EXPECT_EQ(c.pixelsOverTolerance, 11u);
    EXPECT_FALSE(c.Passes());
    c = over(200, 0.25f);  // exactly the tolerance: none over it
    EXPECT_EQ(c.pixelsOverTolerance, 0u);
    EXPECT_TRUE(c.Passes());
    c = over(1, 0.5f);  // exactly the limit
    EXPECT_EQ(c.maxError, 0.5);
    EXPECT_TRUE(c.Passes());
    c = over(1, std::nextafter(0.5f, 1.0f));
    EXPECT_FALSE(c.Passes());
    // SPEC 8's own rule (2/255 on 99.9 %, 8/255 everywhere) by its share: 10 of 10000 pixels at 3/255 pass, 11 fail.
    const CompareRule spec8 = Describe(Stage::RenderSplat).rule(Scene{});
    EXPECT_EQ(spec8.share, 0.001);
    EXPECT_EQ(spec8.limit, 8.0 / 255.0);
    std::vector<float> b = a;
    for (size_t n = 0; n < 10; ++n) b[3 * n] += 3.0f / 255.0f;
    EXPECT_TRUE(CompareImages(a, b, W, H).value().Passes());
    b[3 * 10] += 3.0f / 255.0f;
    EXPECT_FALSE(CompareImages(a, b, W, H).value().Passes());
    b = a;
    b[0] += 9.0f / 255.0f;  // over the limit on one pixel alone
    EXPECT_FALSE(CompareImages(a, b, W, H).value().Passes());
    b = a;
    b[0] += 7.0f / 255.0f;  // under it: one pixel over 2/255 is within the share
    EXPECT_TRUE(CompareImages(a, b, W, H).value().Passes());
}

ConformRow BoundaryStatusRow(const std::string& stage, const std::string& status) {
    ConformRow r;
    r.stage = stage, r.backend = "vk", r.status = status, r.detail = "why";
    return r;
}

// Test the statuses' order in the exit code (a broken backend, 1, before a failed check, 5, before nothing
// compared, 4), and --flake-reruns on a crash: a crash that passes on a rerun is flaky, one that crashes again stays.
TEST(ConformBoundary, StatusesAndExitCodes) {
    EXPECT_EQ(ConformExitCode({BoundaryStatusRow("shade", "fail"), BoundaryStatusRow("(all)", "crashed")}), 1);
    EXPECT_EQ(ConformExitCode({BoundaryStatusRow("shade", "unexpected-pass"), BoundaryStatusRow("ca", "out of memory")}),
              1);
    EXPECT_EQ(ConformExitCode({BoundaryStatusRow("shade", "unexpected-pass")}), 5);
    EXPECT_EQ(ConformExitCode({BoundaryStatusRow("shade", "expected-fail")}), 0);
    EXPECT_EQ(ConformExitCode({BoundaryStatusRow("shade", "skipped"), BoundaryStatusRow("ca", "expected-fail")}), 0);
    EXPECT_EQ(ConformExitCode({BoundaryStatusRow("shade", "skipped"), BoundaryStatusRow("ca", "skipped")}), 4);
    EXPECT_EQ(ConformExitCode({}), 4);
    EXPECT_EQ(ConformExitCode({BoundaryStatusRow("shade", "flaky"), BoundaryStatusRow("ca", "skipped")}), 0);
    EXPECT_EQ(ConformExitCode({BoundaryStatusRow("shade", "timed out")}), 1);

    std::vector<ConformRow> first = {BoundaryStatusRow("(all)", "crashed"), BoundaryStatusRow("shade", "failed"),
                                     BoundaryStatusRow("ca", "skipped")};
    MergeRerun(first,
               {BoundaryStatusRow("(all)", "pass"), BoundaryStatusRow("shade", "crashed"),
                BoundaryStatusRow("ca", "pass")},
               1);
    EXPECT_EQ(first[0].status, "flaky");
    EXPECT_EQ(first[0].detail, "passed on rerun 1; the first run: crashed, why");
    EXPECT_EQ(first[1].status, "failed");
    EXPECT_EQ(first[2].status, "skipped");  // not a failure: a rerun does not change it
    // A flaky row is neither a failure nor a pass to a baseline.
    auto baseline = ParseConformBaseline("b", "shade,vk,fail\n");
    ASSERT_TRUE(baseline.has_value());
    std::vector<ConformRow> rows = {BoundaryStatusRow("shade", "flaky")};
    ApplyBaseline(rows, *baseline);
    EXPECT_EQ(rows[0].status, "flaky");
    EXPECT_EQ(ConformExitCode(rows), 0);
}

// Test conform's last line: the rows counted by status in the order they first occur, and the verdict, pass or fail.
TEST(ConformBoundary, SummaryLineCountsAndVerdict) {
    EXPECT_EQ(ConformSummary({BoundaryStatusRow("region", "pass"), BoundaryStatusRow("ca", "fail"),
                              BoundaryStatusRow("shade", "pass"), BoundaryStatusRow("shadow", "skipped")}),
              "4 rows: 2 pass, 1 fail, 1 skipped; exit 5, a row does not conform");
    EXPECT_EQ(ConformSummary({BoundaryStatusRow("shade", "pass")}), "1 row: 1 pass; exit 0, every compared row conforms");
    EXPECT_EQ(ConformSummary({BoundaryStatusRow("(all)", "crashed"), BoundaryStatusRow("ca", "fail")}),
              "2 rows: 1 crashed, 1 fail; exit 1, a backend failed or crashed");
    EXPECT_EQ(ConformSummary({}), "0 rows; exit 4, no backend was compared");
}

}  // namespace
}  // namespace cb
