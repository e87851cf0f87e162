// conform's deqp-runner features: the cover count compared
// bit-exactly, --baseline, --flake-reruns' merge, the exit code and conform.csv.
#include <gtest/gtest.h>

#include "core/plan/SceneLoad.h"
#include "harness/conform/Conform.h"
#include "impl_cpu/BackendCpu.h"

namespace cb {
namespace {

// The CPU backend whose density reports a cover count off by `delta`; its buffers are the CPU's.
class CoverOffCpu : public cpu::BackendCpu {
  public:
    explicit CoverOffCpu(int delta) : mDelta(delta) {}
    Status Density(const DensityParams& p, const Buffer& q, const Buffer* cld, DensityOutputs& out) override {
        CB_TRY(cpu::BackendCpu::Density(p, q, cld, out));
        out.coveredColumns = uint32_t(int64_t(out.coveredColumns) + mDelta);
        return {};
    }

  private:
    int mDelta;
};

const ConformRow* FindRow(const std::vector<ConformRow>& rows, const std::string& stage) {
    for (const ConformRow& r : rows)
        if (r.stage == stage) return &r;
    return nullptr;
}

std::vector<ConformRow> ConformCover(int delta) {
    auto scene =
        LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", {{"steps", "2"}, {"warmup_steps", "0"}});
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    cpu::BackendCpu reference;
    std::vector<OpenedBackend> others(1);
    others[0].name = "coveroff";
    others[0].backend = std::make_unique<CoverOffCpu>(delta);
    others[0].status = BackendStatus::Available;
    auto rows = RunConformance(*scene, reference, others);
    EXPECT_TRUE(rows.has_value()) << rows.error().message;
    return rows ? *rows : std::vector<ConformRow>{};
}

// Test that a cover count off by one fails the density.cover row (worst 1)
// while density's buffers, which are the CPU's, pass; and that an honest
// backend passes it with worst 0.
TEST(ConformFeatures, CoverCountIsComparedBitExactly) {
    for (int delta : {1, 3}) {
        const std::vector<ConformRow> rows = ConformCover(delta);
        const ConformRow* cover = FindRow(rows, kCoverRowStage);
        ASSERT_NE(cover, nullptr);
        EXPECT_EQ(cover->status, "fail") << delta;
        EXPECT_EQ(cover->worst, double(delta));
        EXPECT_EQ(cover->rule, "bit-exact");
        ASSERT_NE(FindRow(rows, "density"), nullptr);
        EXPECT_EQ(FindRow(rows, "density")->status, "pass");
    }
    const std::vector<ConformRow> rows = ConformCover(0);
    const ConformRow* cover = FindRow(rows, kCoverRowStage);
    ASSERT_NE(cover, nullptr);
    EXPECT_EQ(cover->status, "pass");
    EXPECT_EQ(cover->worst, 0.0);
    // ci-small has cloud by its last step: the count compared is not a trivial zero.
    EXPECT_EQ(cover->detail.find("cpu 0 columns"), std::string::npos) << cover->detail;
}

// Test the comparison itself: equal counts pass; the worst difference over the
// steps is kept with its step and both counts, and one differing step fails the row.
TEST(ConformFeatures, FoldCoverComparison) {
    ConformRow row{kCoverRowStage, "x", "pass", "bit-exact", 0, 0, "", "", ""};
    FoldCoverComparison(row, 0, 100, 100);
    FoldCoverComparison(row, 1, 90, 90);
    EXPECT_EQ(row.status, "pass");
    EXPECT_EQ(row.worst, 0.0);
    EXPECT_EQ(row.detail, "step 1: cpu 90 columns, x 90");
    FoldCoverComparison(row, 2, 10, 12);
    FoldCoverComparison(row, 3, 7, 6);
    FoldCoverComparison(row, 4, 5, 5);
    EXPECT_EQ(row.status, "fail");
    EXPECT_EQ(row.worst, 2.0);
    EXPECT_EQ(row.detail, "step 2: cpu 10 columns, x 12");
    // Counts too large for a float's 24-bit mantissa still differ by one.
    ConformRow big{kCoverRowStage, "x", "pass", "bit-exact", 0, 0, "", "", ""};
    FoldCoverComparison(big, 0, 16777217u, 16777216u);
    EXPECT_EQ(big.status, "fail");
    EXPECT_EQ(big.worst, 1.0);
}

ConformRow Row(const std::string& stage, const std::string& status) {
    return {stage, "vk", status, "bit-exact", 0, 0, "why", "", ""};
}

TEST(ConformFeatures, BaselineParses) {
    auto b = ParseConformBaseline("b.csv",
                                  "# known\r\nstage,backend,status,rule\n\n  shade , vk , fail,extra,fields\n"
                                  "smooth,gl,pass\n(all),gl,crashed\nca,vk,expected-fail\n");
    ASSERT_TRUE(b.has_value()) << b.error().message;
    EXPECT_TRUE(b->Lists("shade", "vk"));
    EXPECT_TRUE(b->Lists("(all)", "gl"));
    EXPECT_TRUE(b->Lists("ca", "vk"));
    EXPECT_FALSE(b->Lists("smooth", "gl"));  // a pass line lists nothing
    EXPECT_FALSE(b->Lists("shade", "gl"));
    EXPECT_EQ(b->knownFailures.size(), 3u);
}

TEST(ConformFeatures, BadBaselineNamesFileAndLine) {
    const std::pair<const char*, const char*> cases[] = {
        {"shade,vk,fail\nsmooth,vk\n", "b.csv: line 2: expected stage,backend,status"},
        {"shade,vk,fial\n", "b.csv: line 1: unknown status 'fial'"},
        {"# c\n,vk,fail\n", "b.csv: line 2: empty stage"},
        {"shade,,fail\n", "b.csv: line 1: empty backend"},
        {"shade,vk,fail\nshade,vk,failed\n", "b.csv: line 2: shade,vk is listed twice"},
        {"shde,vk,fail\n", "b.csv: line 1: unknown stage 'shde'; did you mean 'shade'?"},
        {"shade,vkk,fail\n", "b.csv: line 1: backend: unknown backend 'vkk' (known: cpu, gl, vk); did you mean 'vk'?"},
    };
    for (auto [text, message] : cases) {
        auto b = ParseConformBaseline("b.csv", text);
        ASSERT_FALSE(b.has_value()) << text;
        EXPECT_EQ(b.error().message.rfind(message, 0), 0u) << b.error().message;
    }
    auto missing = LoadConformBaseline("/nonexistent/baseline.csv");
    ASSERT_FALSE(missing.has_value());
    EXPECT_EQ(missing.error().message, "/nonexistent/baseline.csv: cannot read the file: No such file or directory");
}

// Test the outcome of each kind of row against a baseline, and the exit code:
// expected failures pass (0), a new failure fails (5), an unexpected pass fails (5),
// a crash not listed is 1, a listed crash is expected.
TEST(ConformFeatures, BaselineAndExitCode) {
    auto b = ParseConformBaseline("b", "shade,vk,fail\nshadow,vk,fail\n(all),vk,crashed\n");
    ASSERT_TRUE(b.has_value());
    std::vector<ConformRow> rows = {Row("shade", "fail"), Row("smooth", "pass"), Row("region", "skipped")};
    EXPECT_EQ(ConformExitCode(rows), 5);
    ApplyBaseline(rows, *b);
    EXPECT_EQ(rows[0].status, "expected-fail");
    EXPECT_EQ(rows[0].detail, "known failure (fail): why");
    EXPECT_EQ(rows[1].status, "pass");
    EXPECT_EQ(rows[2].status, "skipped");
    EXPECT_EQ(ConformExitCode(rows), 0);

    rows = {Row("shade", "fail"), Row("shadow", "pass")};
    ApplyBaseline(rows, *b);
    EXPECT_EQ(rows[1].status, "unexpected-pass");
    EXPECT_EQ(ConformExitCode(rows), 5);

    rows = {Row("shade", "fail"), Row("smooth", "fail")};
    ApplyBaseline(rows, *b);
    EXPECT_EQ(rows[1].status, "fail");
    EXPECT_EQ(ConformExitCode(rows), 5);

    rows = {Row("(all)", "crashed"), Row("ca", "timed out")};
    EXPECT_EQ(ConformExitCode(rows), 1);
    ApplyBaseline(rows, *b);
    EXPECT_EQ(rows[0].status, "expected-fail");
    EXPECT_EQ(rows[1].status, "timed out");
    EXPECT_EQ(ConformExitCode(rows), 1);

    EXPECT_EQ(ConformExitCode({Row("shade", "flaky"), Row("ca", "pass")}), 0);
    EXPECT_EQ(ConformExitCode({Row("shade", "skipped")}), 4);
}

// Test --flake-reruns' merge: a failure that passes on a rerun is flaky (with the
// first run's reason), one that fails again stays, and passing rows are kept as they were.
TEST(ConformFeatures, RerunMerge) {
    std::vector<ConformRow> first = {Row("shade", "fail"), Row("smooth", "fail"), Row("ca", "pass")};
    first[0].detail = "step 1 at (0, 0, 0): cpu 0.5, vk 1.5";
    std::vector<ConformRow> rerun = {Row("shade", "pass"), Row("smooth", "fail"), Row("ca", "fail")};
    rerun[0].detail = "step 0";
    MergeRerun(first, rerun, 2);
    EXPECT_EQ(first[0].status, "flaky");
    EXPECT_EQ(first[0].detail, "passed on rerun 2; the first run: fail, step 1 at (0, 0, 0): cpu 0.5, vk 1.5");
    EXPECT_EQ(first[1].status, "fail");
    EXPECT_EQ(first[2].status, "pass");
    EXPECT_FALSE(IsConformFailure(first[0]));
    EXPECT_TRUE(IsConformFailure(first[1]));
}

// Test conform.csv: a header, one line per row, fields with commas or quotes quoted (RFC 4180).
TEST(ConformFeatures, Csv) {
    std::vector<ConformRow> rows = {{"shade", "vk", "fail", "|dT| <= 1e-05", 0.25, 1e-5, "at (1, 2, 3): \"x\"", "", ""},
                                    {"ca", "gl", "pass", "bit-exact", 0, 0, "", "", ""}};
    EXPECT_EQ(ConformCsv(rows),
              "stage,backend,status,rule,worst,tolerance,detail\n"
              "shade,vk,fail,|dT| <= 1e-05,0.25,1e-05,\"at (1, 2, 3): \"\"x\"\"\"\n"
              "ca,gl,pass,bit-exact,0,0,\n");
    // A run's CSV is a baseline listing exactly its failing rows.
    auto b = ParseConformBaseline("conform.csv", ConformCsv(rows));
    ASSERT_TRUE(b.has_value()) << b.error().message;
    EXPECT_TRUE(b->Lists("shade", "vk"));
    EXPECT_FALSE(b->Lists("ca", "gl"));
}

// Test the coverage summary: the options each compared stage ran under, from
// the scene as set here, and only the backends that compared it.
TEST(ConformFeatures, CoverageSummary) {
    Scene scene;
    scene.smooth.radius = 2;
    scene.shade.storage = StorageFormat::Unorm8;
    scene.shade.scattering = false;
    scene.shadow.form = ShadowForm::Thesis;
    scene.splat.culling = false;
    std::vector<ConformRow> rows = {Row("smooth", "pass"),   Row("shade", "fail"), Row("shadow", "skipped"),
                                    Row("(all)", "crashed"), Row("ca", "flaky"),   Row(kCoverRowStage, "pass")};
    rows.push_back({"smooth", "gl", "expected-fail", "", 0, 0, "", "", ""});
    const nlohmann::json c = ConformCoverage(scene, rows);
    EXPECT_EQ(c["smooth"]["options"]["radius"], 2);
    EXPECT_EQ(c["smooth"]["compared_on"], nlohmann::json({"vk", "gl"}));
    EXPECT_EQ(c["shade"]["options"]["storage"], "unorm8");
    EXPECT_EQ(c["shade"]["options"]["phase"], "none");
    EXPECT_TRUE(c.contains("ca"));
    EXPECT_TRUE(c.contains(kCoverRowStage));
    EXPECT_FALSE(c.contains("shadow"));  // skipped: not compared
    EXPECT_FALSE(c.contains("(all)"));
    EXPECT_EQ(c.size(), 4u);
    rows.push_back(Row("shadow", "pass"));
    rows.push_back(Row("render_splat", "pass"));
    const nlohmann::json d = ConformCoverage(scene, rows);
    EXPECT_EQ(d["shadow"]["options"]["form"], "thesis");
    EXPECT_EQ(d["render_splat"]["options"]["culling"], false);
    EXPECT_EQ(d["render_splat"]["options"]["skipping"], true);
}

}  // namespace
}  // namespace cb
