// The pieces of `cloudbench report` (harness/report/html/): the SVG plot generators,
// the HTML renderer, the report model read back from JSON, the source documents' figures,
// the history reader and the verdicts. Expected numbers are worked out by hand
// (NumPy's linear quantiles, Tukey's fences, RFC 4648's vectors), not taken
// from the code's output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

#include "core/scene/Stage.h"
#include "harness/report/ReportModel.h"
#include "harness/report/html/HtmlRender.h"
#include "harness/report/html/HtmlReport.h"
#include "harness/report/html/ReportSections.h"
#include "harness/report/html/SvgPlot.h"

namespace cb::html {
namespace {

// Every value of attribute `name` in `markup`, in order.
std::vector<std::string> Attributes(const std::string& markup, const std::string& name) {
    std::vector<std::string> out;
    const std::regex pattern(" " + name + "=\"([^\"]*)\"");
    for (auto it = std::sregex_iterator(markup.begin(), markup.end(), pattern); it != std::sregex_iterator(); ++it)
        out.push_back((*it)[1]);
    return out;
}

size_t Count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// Test that the quartiles are NumPy's linear ones: 1..9 gives 3, 5, 7 (positions 2, 4, 6).
TEST(HtmlPlot, BoxStatsOddCount) {
    const BoxStats s = BoxStatsOf({9, 1, 8, 2, 7, 3, 6, 4, 5});
    EXPECT_EQ(s.count, 9u);
    EXPECT_DOUBLE_EQ(s.q1, 3);
    EXPECT_DOUBLE_EQ(s.median, 5);
    EXPECT_DOUBLE_EQ(s.q3, 7);
    EXPECT_DOUBLE_EQ(s.whiskerLo, 1);
    EXPECT_DOUBLE_EQ(s.whiskerHi, 9);
    EXPECT_TRUE(s.outliers.empty());
}

// Test interpolation between order statistics: 1,2,3,4 has q1 at position 0.75 (1.75), median 2.5, q3 3.25.
TEST(HtmlPlot, BoxStatsInterpolates) {
    const BoxStats s = BoxStatsOf({4, 3, 2, 1});
    EXPECT_DOUBLE_EQ(s.q1, 1.75);
    EXPECT_DOUBLE_EQ(s.median, 2.5);
    EXPECT_DOUBLE_EQ(s.q3, 3.25);
}

// Test Tukey's whiskers: 1..9 and 100 have q1 3.25, q3 7.75 (positions 2.25, 6.75), IQR 4.5, upper fence
// 14.5: the whisker stops at 9 and 100 is an outlier.
TEST(HtmlPlot, BoxStatsOutlierBeyondFence) {
    const BoxStats s = BoxStatsOf({1, 2, 3, 4, 5, 6, 7, 8, 9, 100});
    EXPECT_DOUBLE_EQ(s.q1, 3.25);
    EXPECT_DOUBLE_EQ(s.median, 5.5);
    EXPECT_DOUBLE_EQ(s.q3, 7.75);
    EXPECT_DOUBLE_EQ(s.whiskerHi, 9);
    EXPECT_DOUBLE_EQ(s.whiskerLo, 1);
    ASSERT_EQ(s.outliers.size(), 1u);
    EXPECT_DOUBLE_EQ(s.outliers[0], 100);
}

// Test that a linear axis widens to round steps: [0.3, 7.2] over 5 ticks steps by 2 from 0 to 8.
TEST(HtmlPlot, LinearAxisRoundSteps) {
    const Axis a = MakeAxis(0.3, 7.2, false);
    EXPECT_FALSE(a.log);
    EXPECT_DOUBLE_EQ(a.lo, 0);
    EXPECT_DOUBLE_EQ(a.hi, 8);
    EXPECT_EQ(a.ticks, (std::vector<double>{0, 2, 4, 6, 8}));
    EXPECT_DOUBLE_EQ(a.ToPixel(0, 100, 300), 100);
    EXPECT_DOUBLE_EQ(a.ToPixel(8, 100, 300), 300);
    EXPECT_DOUBLE_EQ(a.ToPixel(2, 100, 300), 150);
    EXPECT_DOUBLE_EQ(a.ToPixel(-5, 100, 300), 100);  // clamped
}

// Test that a log axis spans whole decades: [0.05, 30] shows 0.01 to 100, 10 at the middle of [1, 100].
TEST(HtmlPlot, LogAxisDecades) {
    const Axis a = MakeAxis(0.05, 30, true);
    EXPECT_TRUE(a.log);
    EXPECT_DOUBLE_EQ(a.lo, 0.01);
    EXPECT_DOUBLE_EQ(a.hi, 100);
    ASSERT_EQ(a.ticks.size(), 5u);
    EXPECT_NEAR(MakeAxis(1, 100, true).ToPixel(10, 0, 200), 100, 1e-9);
    // A log axis of a range touching 0 falls back to linear.
    EXPECT_FALSE(MakeAxis(0, 30, true).log);
}

// Test that an axis of whole numbers has whole ticks: records 0 to 3 over 8 ticks would step by 0.5.
TEST(HtmlPlot, WholeNumberAxis) {
    EXPECT_EQ(MakeAxis(0, 3, false, 8).ticks, (std::vector<double>{0, 0.5, 1, 1.5, 2, 2.5, 3}));
    const Axis a = MakeAxis(0, 3, false, 8, /*whole=*/true);
    EXPECT_EQ(a.ticks, (std::vector<double>{0, 1, 2, 3}));
    EXPECT_EQ(MakeAxis(0, 40, false, 8, true).ticks, (std::vector<double>{0, 5, 10, 15, 20, 25, 30, 35, 40}));
}

// Test the degenerate ranges: one value is widened around it, no value gives [0, 1].
TEST(HtmlPlot, DegenerateAxes) {
    const Axis one = MakeAxis(5, 5, false);
    EXPECT_LT(one.lo, 5);
    EXPECT_GT(one.hi, 5);
    const Axis none = MakeAxis(INFINITY, -INFINITY, false);
    EXPECT_DOUBLE_EQ(none.lo, 0);
    EXPECT_DOUBLE_EQ(none.hi, 1);
    EXPECT_EQ(TickLabel(0.05), "0.05");
    EXPECT_EQ(TickLabel(1000), "1000");
}

// Test that the box plot's marks carry the quartiles of their samples, and its axis covers them.
TEST(HtmlPlot, BoxPlotMarkup) {
    BoxPlot plot;
    plot.title = "t <&>";
    plot.series = {"cpu", "vk"};
    plot.groups = {{"region", {{0, {1, 2, 3, 4}}, {1, {10, 20, 30, 40, 50}}}}, {"ca", {{1, {}}}}};
    const std::string svg = RenderBoxPlot(plot);
    EXPECT_EQ(Attributes(svg, "data-plot"), std::vector<std::string>{"box"});
    EXPECT_EQ(Count(svg, "<g class=\"box\""), 2u);  // the empty box is left out
    EXPECT_EQ(Attributes(svg, "data-q1"), (std::vector<std::string>{"1.75", "20"}));
    EXPECT_EQ(Attributes(svg, "data-median"), (std::vector<std::string>{"2.5", "30"}));
    EXPECT_EQ(Attributes(svg, "data-q3"), (std::vector<std::string>{"3.25", "40"}));
    const auto lo = Attributes(svg, "data-lo"), hi = Attributes(svg, "data-hi");
    ASSERT_EQ(lo.size(), 1u);
    EXPECT_LE(std::stod(lo[0]), 1);
    EXPECT_GE(std::stod(hi[0]), 50);
    EXPECT_EQ(Attributes(svg, "data-log"), std::vector<std::string>{"1"});
    EXPECT_NE(svg.find("t &lt;&amp;&gt;"), std::string::npos);
}

// Test that change points are drawn at the marked records only, and a plot without marks has none.
TEST(HtmlPlot, HistoryChangePoints) {
    LinePlot plot{"h", "record", "ms", {{"cpu", {0, 1, 2, 3}, {1, 1, 2, 2}, {}, {2}}, {"vk", {0, 1}, {3, 3}, {}, {}}}};
    const std::string svg = RenderHistoryPlot(plot);
    EXPECT_EQ(Attributes(svg, "data-plot"), std::vector<std::string>{"history"});
    EXPECT_EQ(Attributes(svg, "data-change-point"), std::vector<std::string>{"2"});
    plot.series[0].marks.clear();
    EXPECT_TRUE(Attributes(RenderHistoryPlot(plot), "data-change-point").empty());
    // The y axis starts at 0 so that a step reads at its true size.
    EXPECT_EQ(Attributes(svg, "data-lo")[0], "0");
}

// Test the Pareto front: a point survives when nothing is both faster and more accurate.
TEST(HtmlPlot, ParetoFront) {
    const auto front = ParetoFront({{2, 6}, {1, 5}, {3, 4}, {2, 3}, {4, 1}, {5, 1}});
    EXPECT_EQ(front, (std::vector<std::pair<double, double>>{{1, 5}, {2, 3}, {4, 1}}));
    ScatterPlot plot{"p", "ms", "error", true, true, {{"cpu", {1, 2, 3}, {5, 3, 4}, {}, {}}}, {{1, 5}, {2, 3}}};
    const std::string svg = RenderParetoPlot(plot);
    EXPECT_EQ(Attributes(svg, "data-plot"), std::vector<std::string>{"pareto"});
    EXPECT_EQ(Count(svg, "class=\"front\""), 1u);
    EXPECT_EQ(Attributes(svg, "data-x"), (std::vector<std::string>{"1", "2", "3"}));
}

// Test that the renderers share one Pareto plot, a series per renderer and backend, beside one plot per other stage:
// in a sweep (its rows) and in accuracy.json (its image rows), where they were drawn apart or not at all.
TEST(HtmlPareto, RenderersShareOnePlot) {
    auto row = [](const char* stage, const char* backend, double ms, double error) {
        return nlohmann::json{{"stage", stage},
                              {"backend", backend},
                              {"status", "ok"},
                              {"time", {{"median_ms", ms}}},
                              {"error", {{"all", {{"max", error}}}}},
                              {"settings", nlohmann::json::object()}};
    };
    ReportInput sweep{"s.json", InputKind::Sweep, {{"scene", "x"}, {"metric", "max"}}};
    sweep.doc["rows"] = {row("shade", "cpu", 1, 0.1), row("render_march", "cpu", 10, 0.01),
                         row("render_layers", "cpu", 2, 0.05), row("render_splat", "vk", 3, 0.2)};
    const std::vector<report::Block> blocks = ParetoBlocks(sweep);
    ASSERT_EQ(blocks.size(), 2u);
    const std::string images = std::get<report::Figure>(blocks[1]).svg;
    for (const char* series : {"march cpu", "layers cpu", "splat vk"})
        EXPECT_NE(images.find(series), std::string::npos) << series;
    EXPECT_EQ(images.find("shade"), std::string::npos);
    ReportInput accuracy{"a.json", InputKind::Accuracy, {{"scene", "x"}}};
    accuracy.doc["image_rows"] = {{{"renderer", "render_layers"},
                                   {"backend", "gl"},
                                   {"status", "ok"},
                                   {"time", {{"median_ms", 4}}},
                                   {"error", {{"max", 0.3}}}},
                                  {{"renderer", "render_splat"}, {"backend", "gl"}, {"status", "failed"}}};
    const std::vector<report::Block> image = ParetoBlocks(accuracy);
    ASSERT_EQ(image.size(), 1u);
    EXPECT_NE(std::get<report::Figure>(image[0]).svg.find("layers gl"), std::string::npos);
}

// Test that accuracy.json's stages get a plot of the max and one of the mean: the ground shadow's max is near 1 for
// every form (its shadow edges), and only its mean tells the forms apart.
TEST(HtmlPareto, AccuracyPlotsMaxAndMean) {
    auto row = [](const char* form, double ms, double max, double mean) {
        return nlohmann::json{{"stage", "shadow"},
                              {"backend", "cpu"},
                              {"status", "ok"},
                              {"time", {{"median_ms", ms}}},
                              {"error", {{"all", {{"max", max}, {"mean", mean}}}}},
                              {"settings", {{"shadow.form", form}}}};
    };
    ReportInput accuracy{"a.json", InputKind::Accuracy, {{"scene", "x"}}};
    accuracy.doc["rows"] = {row("beer", 0.02, 0.9996, 0.128), row("thesis", 0.03, 0.9995, 0.31)};
    const std::vector<report::Block> blocks = ParetoBlocks(accuracy);
    ASSERT_EQ(blocks.size(), 2u);
    const std::string max = std::get<report::Figure>(blocks[0]).svg, mean = std::get<report::Figure>(blocks[1]).svg;
    EXPECT_NE(max.find("shadow, max"), std::string::npos);
    EXPECT_NE(mean.find("shadow, mean"), std::string::npos);
    EXPECT_NE(mean.find("error 0.128"), std::string::npos);
    EXPECT_NE(mean.find("error 0.31"), std::string::npos);
}

// Test a sweep on PSNR: the front drawn is the rows sweep.json marks (higher PSNR is better, so a plain
// lower-is-better front would keep one of them), on a PSNR axis; an infinite PSNR (null) is left out.
TEST(HtmlPareto, PsnrSweepDrawsTheMarkedFront) {
    auto row = [](double ms, nlohmann::json psnr, bool pareto) {
        return nlohmann::json{{"stage", "render_march"},
                              {"backend", "cpu"},
                              {"status", "ok"},
                              {"time", {{"median_ms", ms}}},
                              {"error", {{"all", {{"max", 0.1}}}, {"psnr_db", psnr}}},
                              {"settings", nlohmann::json::object()},
                              {"pareto", pareto}};
    };
    ReportInput sweep{"s.json", InputKind::Sweep, {{"scene", "x"}, {"metric", "psnr"}}};
    sweep.doc["rows"] = {row(1, 30, true), row(2, 28, false), row(3, 40, true), row(4, nullptr, true)};
    const std::vector<report::Block> blocks = ParetoBlocks(sweep);
    ASSERT_EQ(blocks.size(), 1u);
    const std::string svg = std::get<report::Figure>(blocks[0]).svg;
    EXPECT_NE(svg.find("class=\"front\" data-points=\"2\""), std::string::npos) << svg;
    EXPECT_NE(svg.find("data-series=\"march cpu\" data-points=\"3\""), std::string::npos) << svg;
    EXPECT_NE(svg.find("PSNR (dB)"), std::string::npos);
}

// Test base64 against RFC 4648's vectors.
TEST(HtmlRender, Base64Rfc4648) {
    EXPECT_EQ(Base64(""), "");
    EXPECT_EQ(Base64("f"), "Zg==");
    EXPECT_EQ(Base64("fo"), "Zm8=");
    EXPECT_EQ(Base64("foo"), "Zm9v");
    EXPECT_EQ(Base64("foob"), "Zm9vYg==");
    EXPECT_EQ(Base64("fooba"), "Zm9vYmE=");
    EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
    EXPECT_EQ(Base64(std::string("\xff\xfe\x00", 3)), "//4A");
}

// Test the page: status cells get their class, text is escaped, images are data: URIs, and no URL
// points outside the page.
TEST(HtmlRender, SelfContainedPage) {
    report::Report r("R <1>");
    report::Table t({report::Column("stage"), report::Column("vk"), report::Column("ms").Real("%.2f")});
    t.rows.push_back({"shade", "fail", 1.5});
    r.sections.push_back({"S", {t, report::Image{"a.png", "cap", "PNG"}, report::Image{"b.png", "nodata"},
                                report::Link{"https://example.org", "x"}, report::Figure{"box", "<svg></svg>", "f"}}});
    const std::string page = RenderHtml(r);
    EXPECT_NE(page.find("<td class=\"st-fail\">fail</td>"), std::string::npos);
    EXPECT_NE(page.find("<td class=\"num\">1.50</td>"), std::string::npos);
    EXPECT_NE(page.find("<title>R &lt;1&gt;</title>"), std::string::npos);
    EXPECT_NE(page.find("src=\"data:image/png;base64,UE5H\""), std::string::npos);
    EXPECT_EQ(Count(page, "<img"), 1u);  // an image without data is named, not linked
    EXPECT_EQ(page.find("href=\"http"), std::string::npos);
    EXPECT_EQ(page.find("src=\"http"), std::string::npos);
    EXPECT_EQ(Count(page, "<table"), 1u);
}

// Test that a report read back from its JSON renders to the same JSON.
TEST(HtmlRender, ReportJsonRoundTrip) {
    report::Report r("T");
    report::Table t({report::Column("a"), report::Column("n").Integer(), report::Column("x").Real("%g").Unit("ms")});
    t.rows.push_back({"one", int64_t(2), 0.25});
    t.rows.push_back({report::Cell(), int64_t(-1), 1e-9});
    r.sections.push_back({"S", {t, report::KeyValues{{{"k", "v"}}}, report::Paragraph{"p"},
                                report::Image{"i.png", "c"}, report::Link{"#a", "l"}}});
    const nlohmann::json once = report::RenderJson(r);
    EXPECT_EQ(report::RenderJson(report::ReportFromJson(once)), once);
    EXPECT_THROW(report::ReportFromJson(nlohmann::json{{"title", 1}}), nlohmann::json::exception);
}

// Test the source documents' figures: every cited table is there, every stage is one of ours, and each time agrees with
// the rate the document printed (1000 / fps, or 1000 / updates per second).
TEST(HtmlSeedTimings, TablesStagesAndRates) {
    const nlohmann::json& seeds = SeedTimings();
    std::set<std::string> tables;
    const std::regex rate(R"((?:about )?([0-9.]+) (fps|FPS|updates/s|per second))");
    size_t checked = 0;
    for (const nlohmann::json& f : seeds.at("figures")) {
        tables.insert(f.at("seed").get<std::string>() + " " + f.at("table").get<std::string>());
        const std::string stage = f.at("stage");
        EXPECT_TRUE(std::ranges::any_of(kAllStages, [&](Stage s) { return StageName(s) == stage; })) << stage;
        EXPECT_TRUE(seeds.at("sources").contains(f.at("seed").get<std::string>()));
        std::smatch m;
        const std::string printed = f.value("rate", "");
        if (std::regex_match(printed, m, rate)) {
            EXPECT_NEAR(f.at("ms").get<double>(), 1000 / std::stod(m[1]), 1e-3) << printed;
            ++checked;
        }
    }
    EXPECT_EQ(checked, 25u);  // all but full-resolution shading, which the thesis gives as a time
    for (const char* t : {"000 Table 8.1", "000 Table 8.2", "000 Table 8.3", "000 Table 8.4", "000 section 8.2",
                          "001 Table 3.1", "001 Table 3.2", "001 Table 3.3", "001 Table 3.4", "002 section 7"})
        EXPECT_TRUE(tables.count(t)) << t;
}

// Test the verdicts: a failed check is 5, a crashed backend 1 before it, nothing compared 4.
TEST(HtmlVerdict, ExitCodesAsTheCommandsGive) {
    auto conform = [](std::vector<std::string> statuses) {
        ReportInput input{"c.json", InputKind::Conform, {{"results", nlohmann::json::array()}}};
        for (const std::string& s : statuses)
            input.doc["results"].push_back({{"stage", "shade"}, {"backend", "vk"}, {"status", s}});
        return VerdictOf(input).exitCode;
    };
    EXPECT_EQ(conform({"pass", "skipped"}), 0);
    EXPECT_EQ(conform({"pass", "fail"}), 5);
    EXPECT_EQ(conform({"fail", "crashed"}), 1);
    EXPECT_EQ(conform({"skipped"}), 4);
    ReportInput results{"r.json", InputKind::Results, {{"backends", {{"cpu", {{"status", "ok"}}}}}}};
    EXPECT_EQ(VerdictOf(results).exitCode, 0);
    results.doc["backends"]["gl"] = {{"status", "crashed"}};
    EXPECT_EQ(VerdictOf(results).exitCode, 1);
    EXPECT_EQ(CombinedExitCode({{0, ""}, {4, ""}, {5, ""}}), 5);
    EXPECT_EQ(CombinedExitCode({{5, ""}, {1, ""}}), 1);
    EXPECT_EQ(CombinedExitCode({{0, ""}}), 0);
}

}  // namespace
}  // namespace cb::html
