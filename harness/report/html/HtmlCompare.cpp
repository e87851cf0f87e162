// The verdict of the regression gate on `cloudbench report`'s page (ReportSections.h CompareBlocks): a `perf
// compare --json` file, or a kept interleave's compare.json, as perf compare printed it.
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "harness/report/html/ReportJson.h"
#include "harness/report/html/ReportSections.h"

namespace cb::html {
namespace {

using report::Column;
using report::Table;

// `key` of `doc` printed with `format`; "" when it is null or absent.
std::string CompareNum(const json& doc, const char* key, const char* format) {
    const std::optional<double> v = Number(doc, key);
    return v && std::isfinite(*v) ? Fixed(*v, format) : "";
}

// What a row's test drew on, as perf compare's table says it: "25 rounds", "5+5 runs", "100+100 steps".
std::string CompareTestedOn(const json& c) {
    const std::string test = Str(c, "test");
    if (test == "rounds") return Str(c, "pairs", "?") + " rounds";
    if (test == "runs") return Str(c, "base_runs", "?") + "+" + Str(c, "head_runs", "?") + " runs";
    if (test == "steps") return Str(c, "base_count", "?") + "+" + Str(c, "head_count", "?") + " steps";
    return "";
}

std::string CompareSide(const json& side) {
    std::string commit = Str(Obj(Obj(side, "provenance"), "git"), "commit");
    if (commit.size() > 10) commit.resize(10);
    const std::string date = Str(side, "date");
    return Str(side, "label") +
           (date.empty() && commit.empty() ? "" : " (" + date + (commit.empty() ? "" : ", " + commit) + ")");
}

}  // namespace

std::vector<report::Block> CompareBlocks(const ReportInput& input) {
    const json& doc = input.doc;
    std::vector<report::Block> blocks;
    const Verdict verdict = VerdictOf(input);
    const std::string code = " (exit code " + std::to_string(verdict.exitCode) + ")";
    blocks.emplace_back(report::Paragraph{verdict.exitCode == 6 ? "Verdict: " + verdict.reason + code + "."
                                          : verdict.exitCode == 0
                                              ? "Verdict: no regression" + code + "."
                                              : "Verdict: no regression, but " + verdict.reason + code + "."});

    report::KeyValues header;
    header.items = {{"BASE", CompareSide(Obj(doc, "base"))},
                    {"HEAD", CompareSide(Obj(doc, "head"))},
                    {"mode", Str(doc, "mode")},
                    {"clock", Str(doc, "clock", "wall")}};
    if (doc.contains("plant"))
        header.items.push_back({"planted", Str(doc["plant"], "stage") + " x" +
                                               CompareNum(doc["plant"], "factor", "%g") +
                                               " in HEAD, x1 in BASE (the control), through CLOUDBENCH_TEST_SLOWDOWN"});
    std::string thresholds = CompareNum(doc, "threshold", "%gx");
    for (const auto& [backend, value] : Obj(doc, "backend_thresholds").items())
        thresholds += ", " + backend + " " + (value.is_number() ? Fixed(value.get<double>(), "%gx") : "?");
    header.items.push_back(
        {"gate", "+ when slower by more than " + thresholds + " and the Holm-adjusted p < " +
                     CompareNum(doc, "alpha", "%g") + " (each run's " + Str(doc, "run_statistic", "median") +
                     " step); one run a side: its steps and a floor of " + CompareNum(doc, "floor_ms", "%g") +
                     " ms; instructions: more than " + CompareNum(doc, "instruction_threshold", "%g") + " relative"});
    blocks.emplace_back(std::move(header));

    Table table({Column("mark"), Column("scene"), Column("backend"), Column("stage"), Column("metric"),
                 Column("tested on"), Column("base"), Column("head"), Column("ratio"), Column("95% CI"),
                 Column("p slower (Holm)"), Column("p faster (Holm)"), Column("note")});
    for (const json& c : Arr(doc, "comparisons")) {
        const bool time = Str(c, "metric") == "time";
        const char* f = time ? "%.3f ms" : "%.0f";
        const json& ci = c.contains("ratio_ci") ? c["ratio_ci"] : json::array();
        const bool hasCi = ci.size() == 2 && ci[0].is_number() && ci[1].is_number();
        table.rows.push_back(
            {Str(c, "mark"), Str(c, "scene"), Str(c, "backend"), Str(c, "stage"), Str(c, "metric"), CompareTestedOn(c),
             CompareNum(c, "base_median", f), CompareNum(c, "head_median", f), CompareNum(c, "ratio", "%.3f"),
             hasCi ? Fixed(ci[0].get<double>()) + "-" + Fixed(ci[1].get<double>()) : "",
             CompareNum(c, "p_slower_holm", "%.2g"), CompareNum(c, "p_faster_holm", "%.2g"), Str(c, "note")});
    }
    blocks.emplace_back(std::move(table));

    std::string unjudged;
    for (const json& name : Arr(doc, "unjudged"))
        unjudged += (unjudged.empty() ? "" : ", ") + (name.is_string() ? name.get<std::string>() : name.dump());
    blocks.emplace_back(report::Paragraph{unjudged.empty()
                                              ? "Every time comparison was judged (no ?)."
                                              : "Not judged (?): " + unjudged + " (each row's note says why)."});

    const json& failedRuns = Arr(doc, "failed_runs");
    if (failedRuns.empty()) {
        blocks.emplace_back(report::Paragraph{"No run failed."});
    } else {
        Table failed({Column("failed run"), Column("side"), Column("scene"), Column("round").Integer(),
                      Column("exit code").Integer(), Column("compared")});
        for (size_t n = 0; n < failedRuns.size(); ++n) {
            const json& run = failedRuns[n];
            failed.rows.push_back({std::to_string(n + 1), Str(run, "side"), Str(run, "scene"),
                                   int64_t(Number(run, "round").value_or(0) + 1),
                                   int64_t(Number(run, "exit").value_or(0)),
                                   run.value("compared", false) ? "yes" : "no: it wrote no valid results.json"});
        }
        blocks.emplace_back(std::move(failed));
    }
    if (const std::string cut = Str(doc, "cut_short"); !cut.empty())
        blocks.emplace_back(report::Paragraph{"Cut short: " + cut + "."});
    return blocks;
}

}  // namespace cb::html
