// `cloudbench perf compare` (docs/cli.md, "perf"): compares two result files,
// two records, or interleaved runs of two binaries (each a child `cloudbench
// run`), prints the comparison with its regression verdict and writes --json.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <tuple>

#include "core/base/ShownText.h"
#include "harness/commands/PerfCommon.h"
#include "harness/report/ReportModel.h"

namespace cb::perf_command {
namespace {

std::string SideSummary(const perf::Side& side) {
    std::string text = side.label;
    const json& p = side.provenance;
    std::string commit = p.is_object() && p.contains("git") ? p["git"].value("commit", "") : "";
    if (commit.size() > 10) commit.resize(10);
    if (!side.date.empty() || !commit.empty()) text += " (" + side.date + (commit.empty() ? "" : ", " + commit) + ")";
    return text;
}

json ComparisonJson(const perf::Comparison& c) {
    auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    return {{"scene", c.scene},
            {"backend", c.backend},
            {"stage", c.stage},
            {"metric", c.metric},
            {"base_count", c.baseCount},
            {"head_count", c.headCount},
            {"base_median", number(c.baseMedian)},
            {"head_median", number(c.headMedian)},
            {"ratio", number(c.ratio)},
            {"threshold", number(c.threshold)},
            {"ratio_ci", {number(c.interval.low), number(c.interval.high)}},
            {"p_slower", number(c.pSlower)},
            {"p_faster", number(c.pFaster)},
            {"p_slower_holm", number(c.pSlowerHolm)},
            {"p_faster_holm", number(c.pFasterHolm)},
            {"mark", std::string(1, c.mark)},
            {"regression", c.regression},
            {"note", c.note}};
}

// Prints the comparison, writes --json, returns the exit code.
int PrintComparison(const perf::Side& base, const perf::Side& head, const perf::CompareSettings& settings,
                    const std::string& mode, const std::string& jsonPath) {
    const perf::CompareOutcome outcome = perf::Compare(base, head, settings);
    report::Report rep("perf compare");
    report::Section section;
    section.title = "";
    report::KeyValues header;
    header.items = {{"BASE", SideSummary(base)}, {"HEAD", SideSummary(head)}, {"mode", mode}};
    if (outcome.separate)
        header.items.push_back(
            {"note", "BASE and HEAD were measured at different times, not interleaved: the wider threshold " +
                         Num("%gx", outcome.threshold) + " applies"});
    std::string own;
    for (const auto& [backend, unused] : settings.backendThreshold)
        own += ", " + backend + " " + Num("%gx", perf::ThresholdOf(settings, backend));
    header.items.push_back({"gate", "+ when slower by more than " + Num("%gx", outcome.threshold) + own + " and " +
                                        Num("%g ms", settings.floorMs) + ", Holm-adjusted p < " +
                                        Num("%g", settings.alpha) + "; instructions: more than " +
                                        Num("%g %%", settings.instructionThreshold * 100)});
    section.blocks.push_back(header);
    report::Table table({report::Column(""), report::Column("scene"), report::Column("backend"),
                         report::Column("stage"), report::Column("base"), report::Column("head"),
                         report::Column("ratio").AlignRight(), report::Column("95% CI"),
                         report::Column("p slower (Holm)").AlignRight(), report::Column("note")});
    for (const perf::Comparison& c : outcome.rows) {
        const bool time = c.metric == "time";
        const char* f = time ? "%.3f ms" : "%.0f";
        table.rows.push_back(
            {std::string(1, c.mark), c.scene, c.backend, c.stage + (time ? "" : " (instructions)"),
             Num(f, c.baseMedian), Num(f, c.headMedian), Num("%.3f", c.ratio),
             std::isnan(c.interval.low) ? "" : Num("%.3f", c.interval.low) + "-" + Num("%.3f", c.interval.high),
             Num("%.2g", c.pSlowerHolm), c.note});
    }
    section.blocks.push_back(table);
    rep.sections.push_back(section);
    std::printf("%s", report::RenderText(section).c_str());
    int code = kExitOk;
    if (outcome.Regressions()) {
        code = kExitRegression;
        std::printf("regression:");
        for (const perf::Comparison& c : outcome.rows)
            if (c.regression)
                std::printf(" %s/%s/%s%s (x%.2f)", c.scene.c_str(), c.backend.c_str(), c.stage.c_str(),
                            c.metric == "time" ? "" : " instructions", c.ratio);
        std::printf("\n");
    } else if (outcome.headFailed) {
        code = kExitFailed;
        std::printf("no regression, but HEAD failed or lacks a measurement (marked x)\n");
    } else {
        std::printf("no regression\n");
    }
    if (!jsonPath.empty()) {
        json doc = {{"format", "cloudbench-perf-compare/1"},
                    {"base", {{"label", base.label}, {"date", base.date}, {"provenance", base.provenance}}},
                    {"head", {{"label", head.label}, {"date", head.date}, {"provenance", head.provenance}}},
                    {"mode", mode},
                    {"separate", outcome.separate},
                    {"threshold", outcome.threshold},
                    {"backend_thresholds", json::object()},
                    {"floor_ms", settings.floorMs},
                    {"alpha", settings.alpha},
                    {"instruction_threshold", settings.instructionThreshold},
                    {"comparisons", json::array()},
                    {"regressions", outcome.Regressions()},
                    {"exit_code", code},
                    {"report", report::RenderJson(rep)}};
        for (const perf::Comparison& c : outcome.rows) doc["comparisons"].push_back(ComparisonJson(c));
        for (const auto& [backend, unused] : settings.backendThreshold)
            doc["backend_thresholds"][backend] = perf::ThresholdOf(settings, backend);
        if (!WriteJsonFile(jsonPath, doc) && code == kExitOk) code = kExitFailed;
    }
    return code;
}

}  // namespace

int ComparePerf(const std::vector<std::string>& args) {
    ParsedArgs a;
    if (auto m = Parse(args,
                       {"--threshold", "--separate-threshold", "--floor", "--alpha", "--instruction-threshold",
                        "--json", "--rounds", "--backend", "--steps", "--set"},
                       {"--interleave", "--quiet"}, a))
        return Usage(*m);
    perf::CompareSettings settings;
    // --threshold R sets the default; --threshold BACKEND=R that backend's own.
    if (a.values.count("--threshold")) {
        std::vector<std::string> defaults;
        for (const std::string& value : a.values.at("--threshold")) {
            const size_t equals = value.find('=');
            ParsedArgs one;
            one.values["--threshold"] = {equals == std::string::npos ? value : value.substr(equals + 1)};
            double threshold = 0;
            if (auto m = NumberOption(one, "--threshold", 1.0, 1e6, threshold)) return Usage(*m);
            if (equals == std::string::npos)
                settings.threshold = threshold;
            else if (equals == 0)
                return Usage("--threshold: empty backend name in '" + ShownArgument(value) + "'");
            else if (auto why = UnknownBackend("--threshold", value.substr(0, equals)))
                return Usage(*why);
            else
                settings.backendThreshold[value.substr(0, equals)] = threshold;
        }
    }
    for (auto [name, low, high, field] :
         {std::tuple{"--separate-threshold", 1.0, 1e6, &settings.separateThreshold},
          std::tuple{"--floor", 0.0, 1e9, &settings.floorMs}, std::tuple{"--alpha", 1e-12, 1.0, &settings.alpha},
          std::tuple{"--instruction-threshold", 0.0, 1e6, &settings.instructionThreshold}})
        if (auto m = NumberOption(a, name, low, high, *field)) return Usage(*m);
    const std::string jsonPath = a.Value("--json");
    if (!a.Has("--interleave")) {
        for (const char* o : {"--rounds", "--backend", "--steps", "--set"})
            if (a.Has(o)) return Usage(std::string(o) + " is for perf compare --interleave");
        if (a.positional.size() != 2) return Usage("perf compare needs BASE and HEAD");
        perf::Side sides[2];
        for (int n = 0; n < 2; ++n) {
            if (a.positional[n].empty()) return Usage(std::string(n ? "HEAD" : "BASE") + ": must not be empty");
            auto side = perf::LoadSide(a.positional[n]);
            if (!side) {
                std::fprintf(stderr, "%s\n", side.error().message.c_str());
                return kExitBadScene;
            }
            sides[n] = std::move(*side);
        }
        settings.interleaved = false;
        return PrintComparison(sides[0], sides[1], settings, "separate files", jsonPath);
    }
    if (a.positional.size() < 3) return Usage("perf compare --interleave needs BASE_BINARY HEAD_BINARY SCENE...");
    double rounds = 5;
    if (auto m = NumberOption(a, "--rounds", 1, 1000, rounds)) return Usage(*m);
    std::vector<std::string> extra;
    if (a.Has("--backend")) extra.insert(extra.end(), {"--backend", a.Value("--backend")});
    if (a.Has("--steps")) extra.insert(extra.end(), {"--steps", a.Value("--steps")});
    if (a.values.count("--set"))
        for (const std::string& s : a.values.at("--set")) extra.insert(extra.end(), {"--set", s});
    const std::string binaries[2] = {a.positional[0], a.positional[1]};
    for (const std::string& b : binaries)
        if (::access(b.c_str(), X_OK) != 0) return Usage("'" + ShownArgument(b) + "' is not an executable file");
    const std::vector<std::string> scenes(a.positional.begin() + 2, a.positional.end());
    TemporaryFolder temporary;
    if (temporary.path.empty()) {
        std::fprintf(stderr, "perf compare: cannot create a temporary folder\n");
        return kExitFailed;
    }
    perf::Side sides[2];
    sides[0].label = binaries[0] + " (BASE)";
    sides[1].label = binaries[1] + " (HEAD)";
    bool failed = false;
    for (int round = 0; round < int(rounds); ++round)
        for (size_t s = 0; s < scenes.size(); ++s)
            for (int n = 0; n < 2; ++n) {
                if (!a.Has("--quiet"))
                    std::fprintf(stderr, "perf compare: round %d of %d, %s, %s\n", round + 1, int(rounds),
                                 scenes[s].c_str(), n ? "HEAD" : "BASE");
                const std::string out =
                    temporary.path + "/" + std::to_string(round) + "-" + std::to_string(s) + (n ? "-head" : "-base");
                if (auto code =
                        RunInto(binaries[n], scenes[s], extra, out, temporary.path + "/runs.log", sides[n], failed))
                    return *code;
            }
    settings.interleaved = true;
    const int code = PrintComparison(sides[0], sides[1], settings,
                                     "interleaved, " + std::to_string(int(rounds)) + " rounds", jsonPath);
    return code == kExitOk && failed ? kExitFailed : code;
}

}  // namespace cb::perf_command
