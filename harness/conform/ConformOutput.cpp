// What `cloudbench conform` makes of its rows (harness/conform/Conform.h): the text
// table, conform.json with its coverage summary, conform.csv, --baseline,
// --flake-reruns and the exit code. The comparisons are in harness/conform/Conform.cpp.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "core/base/NamedValues.h"
#include "core/base/PathPolicy.h"
#include "core/base/ShownText.h"
#include "core/math/Shading.h"
#include "core/scene/SceneNames.h"
#include "harness/conform/Conform.h"
#include "harness/platform/Command.h"
#include "harness/platform/TransferJson.h"
#include "harness/report/JUnit.h"

namespace cb {
namespace {

// A backend that could not run its stages, or whose process died (ChildFailure::status).
bool IsBrokenStatus(const std::string& status) {
    return status == "failed" || status == "crashed" || status == "timed out" || status == "out of memory";
}

}  // namespace

namespace {
bool AnyCase(const std::vector<ConformRow>& rows) {
    return std::ranges::any_of(rows, [](const ConformRow& r) { return !r.caseName.empty(); });
}
}  // namespace

report::Table ConformTable(const std::vector<ConformRow>& rows) {
    using report::Column;
    const bool cases = AnyCase(rows);
    std::vector<Column> columns = {Column("stage").Width(13).Separator("  "),
                                   Column("backend").Width(8),
                                   Column("result").Width(8),
                                   Column("rule").Width(28),
                                   Column("worst").Real("%.4g").Width(12).AlignRight(),
                                   Column("where").Separator("  ")};
    if (cases) columns.insert(columns.begin(), Column("case").Width(24).Separator("  "));
    report::Table table(columns, report::TextLayout::Columns);
    for (const ConformRow& r : rows) {
        table.rows.push_back({r.stage, r.backend, r.status, r.rule, r.worst, r.detail});
        if (cases) table.rows.back().insert(table.rows.back().begin(), r.caseName);
    }
    return table;
}

nlohmann::json ConformJson(const Scene& scene, const std::vector<ConformRow>& rows) {
    nlohmann::json list = nlohmann::json::array();
    for (const ConformRow& r : rows)
        list.push_back({{"stage", r.stage},
                        {"backend", r.backend},
                        {"status", r.status},
                        {"rule", r.rule},
                        {"worst", transfer::D(r.worst)},
                        {"tolerance", transfer::D(r.tolerance)},
                        {"detail", r.detail},
                        {"difference_image", r.differenceImage}});
    for (size_t i = 0; i < rows.size(); ++i)
        if (!rows[i].caseName.empty()) list[i]["case"] = rows[i].caseName;
    return {{"format", "cloudbench-conform/1"},
            {"scene", scene.name},
            {"steps", scene.steps},
            {"results", list},
            {"coverage", ConformCoverage(scene, rows)}};
}

nlohmann::json ConformStageOptions(const Scene& scene, const std::string& stage) {
    {
        if (stage == "ca") return {{"wind", scene.ca.HasWind()}};
        if (stage == "smooth") return {{"radius", scene.smooth.radius}};
        if (stage == "density" || stage == kCoverRowStage)
            return {{"tile", scene.density.tile}, {"band", scene.density.band}, {"cld", scene.stages.Has(Stage::Ca)}};
        if (stage == "shade")
            return {{"attenuation", AttenuationKindName(scene.shade.attenuation)},
                    {"filter", SampleFilterName(scene.shade.filter)},
                    {"resolution", scene.shade.resolution},
                    {"storage", StorageFormatName(scene.shade.storage)},
                    {"scattering", scene.shade.scattering},
                    {"phase", scene.shade.scattering ? PhaseKindName(scene.phase.kind) : "none"}};
        if (stage == "shadow") return {{"form", ShadowFormName(scene.shadow.form)}};
        if (const std::optional<Stage> parsed = ParseStage(stage))
            if (const RendererDescriptor* renderer = Describe(*parsed).renderer; renderer && renderer->conformOptions)
                return renderer->conformOptions(scene);
        return nlohmann::json::object();
    }
}

nlohmann::json ConformCoverage(const Scene& scene, const std::vector<ConformRow>& rows) {
    nlohmann::json coverage = nlohmann::json::object();
    for (const ConformRow& r : rows) {
        if (r.stage == "(all)" || r.status == "skipped" || IsBrokenStatus(r.status)) continue;
        if (!coverage.contains(r.stage))
            coverage[r.stage] = {{"options", ConformStageOptions(scene, r.stage)},
                                 {"compared_on", nlohmann::json::array()}};
        coverage[r.stage]["compared_on"].push_back(r.backend);
    }
    return coverage;
}

nlohmann::json ConformMatrixCoverage(const std::vector<ConformCaseScene>& caseScenes,
                                     const std::vector<ConformRow>& rows) {
    auto addOnce = [](nlohmann::json& list, const std::string& item) {
        if (std::ranges::find(list, nlohmann::json(item)) == list.end()) list.push_back(item);
    };
    nlohmann::json coverage = nlohmann::json::object();
    for (const ConformRow& r : rows) {
        if (r.stage == "(all)" || r.status == "skipped" || IsBrokenStatus(r.status)) continue;
        auto c = std::ranges::find_if(caseScenes, [&](const ConformCaseScene& k) { return k.name == r.caseName; });
        if (c == caseScenes.end() || !c->scene) continue;
        if (!coverage.contains(r.stage))
            coverage[r.stage] = {{"options", nlohmann::json::object()},
                                 {"compared_on", nlohmann::json::array()},
                                 {"cases", nlohmann::json::array()}};
        nlohmann::json& entry = coverage[r.stage];
        addOnce(entry["compared_on"], r.backend);
        addOnce(entry["cases"], r.caseName);
        nlohmann::json options = ConformStageOptions(*c->scene, r.stage);
        if (r.stage == "ca" && r.backend == "gl" && !c->glCaLayout.empty()) options["gl_ca_layout"] = c->glCaLayout;
        // The axis shade marches along, which the matrix's sun cases vary (step 0's sun).
        if (r.stage == "shade")
            options["principal_axis"] = std::string(1, "xyz"[PrincipalAxis(c->scene->sun.Direction())]);
        for (const auto& [option, value] : options.items()) {
            const std::string text = value.is_string() ? value.get<std::string>() : value.dump();
            nlohmann::json& backends = entry["options"][option][text];
            if (backends.is_null()) backends = nlohmann::json::array();
            addOnce(backends, r.backend);
        }
    }
    return coverage;
}

bool IsConformFailure(const ConformRow& row) { return row.status == "fail" || IsBrokenStatus(row.status); }

void MergeRerun(std::vector<ConformRow>& first, const std::vector<ConformRow>& rerun, uint32_t attempt) {
    for (ConformRow& row : first) {
        if (!IsConformFailure(row)) continue;
        auto again = std::ranges::find_if(rerun, [&](const ConformRow& r) {
            return r.caseName == row.caseName && r.stage == row.stage && r.backend == row.backend;
        });
        if (again == rerun.end() || again->status != "pass") continue;
        const std::string why = row.detail;
        const std::string was = row.status;
        row = *again;
        row.status = "flaky";
        row.detail =
            "passed on rerun " + std::to_string(attempt) + "; the first run: " + was + (why.empty() ? "" : ", " + why);
    }
}

bool ConformBaseline::Lists(const std::string& caseName, const std::string& stage, const std::string& backend) const {
    return std::ranges::find(knownFailures, Entry{caseName, stage, backend}) != knownFailures.end();
}

namespace {
// The fields of one CSV line (RFC 4180 quoting, as ConformCsv writes), each trimmed of blanks outside quotes.
std::vector<std::string> SplitCsvLine(const std::string& line) {
    std::vector<std::string> fields(1);
    bool quoted = false, wasQuoted = false;
    std::string pending;  // blanks after a field's text, kept only if more text follows
    for (size_t i = 0; i < line.size(); ++i) {
        const char ch = line[i];
        if (quoted) {
            if (ch == '"' && i + 1 < line.size() && line[i + 1] == '"')
                fields.back() += '"', ++i;
            else if (ch == '"')
                quoted = false;
            else
                fields.back() += ch;
        } else if (ch == ',') {
            fields.emplace_back();
            pending.clear();
            wasQuoted = false;
        } else if (ch == '"' && fields.back().empty() && !wasQuoted) {
            quoted = wasQuoted = true;
        } else if (ch == ' ' || ch == '\t') {
            if (!fields.back().empty() || wasQuoted) pending += ch;
        } else {
            fields.back() += pending + ch;
            pending.clear();
        }
    }
    return fields;
}
}  // namespace

Result<ConformBaseline> ParseConformBaseline(const std::string& file, const std::string& text) {
    ConformBaseline baseline;
    bool withCase = false;  // after a "case,stage,backend,status" header
    std::istringstream in(text);
    std::string line;
    for (uint32_t number = 1; std::getline(in, line); ++number) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const size_t start = line.find_first_not_of(" \t");
        if (start == std::string::npos || line[start] == '#') continue;
        // The first three fields (four after a "case,..." header); further ones (a conform.csv's rule,
        // worst, ...) are ignored.
        const std::vector<std::string> fields = SplitCsvLine(line);
        auto bad = [&](const std::string& reason) -> Result<ConformBaseline> {
            return MakeError(file + ": line " + std::to_string(number) + ": " + reason);
        };
        auto header = [&](std::initializer_list<const char*> names) {
            if (fields.size() < names.size()) return false;
            size_t i = 0;
            for (const char* name : names)
                if (fields[i++] != name) return false;
            return true;
        };
        if (header({"case", "stage", "backend", "status"})) {  // a --matrix conform.csv's header
            withCase = true;
            continue;
        }
        if (header({"stage", "backend", "status"})) {  // a conform.csv's header
            withCase = false;
            continue;
        }
        const size_t first = withCase ? 1 : 0;
        if (fields.size() < first + 3)
            return bad(withCase ? "expected case,stage,backend,status" : "expected stage,backend,status");
        const std::string caseName = withCase ? fields[0] : "";
        if (withCase && caseName.empty()) return bad("empty case");
        const std::string &stage = fields[first], &backend = fields[first + 1], &status = fields[first + 2];
        if (stage.empty()) return bad("empty stage");
        if (backend.empty()) return bad("empty backend");
        // The names a conform row can hold: a stage, the density stage's cover, or "(all)" for a backend that was
        // skipped whole.
        static const std::vector<std::string_view> kRowStages = [] {
            std::vector<std::string_view> names = {"(all)", kCoverRowStage};
            for (Stage s : kAllStages) names.push_back(StageName(s));
            return names;
        }();
        if (std::ranges::find(kRowStages, stage) == kRowStages.end()) {
            const std::string_view best = ClosestName(stage, kRowStages);
            return bad("unknown stage '" + ShownArgument(stage) + "'" +
                       (best.empty() ? "" : "; did you mean '" + std::string(best) + "'?"));
        }
        if (auto why = UnknownBackend("backend", backend)) return bad(*why);
        if (status == "fail" || IsBrokenStatus(status) || status == "expected-fail") {
            if (baseline.Lists(caseName, stage, backend))
                return bad((withCase ? caseName + "," : "") + stage + "," + backend + " is listed twice");
            baseline.knownFailures.push_back({caseName, stage, backend});
        } else if (status != "pass" && status != "skipped" && status != "flaky" && status != "unexpected-pass") {
            static constexpr std::string_view kStatuses[] = {"fail",          "failed",         "crashed", "timed out",
                                                             "out of memory", "expected-fail",  "pass",    "skipped",
                                                             "flaky",         "unexpected-pass"};
            const std::string_view best = ClosestName(status, kStatuses);
            return bad("unknown status '" + ShownArgument(status) + "'" +
                       (best.empty() ? "" : " (did you mean '" + std::string(best) + "'?)") +
                       " (fail, failed, crashed, timed out, out of memory or expected-fail list a known "
                       "failure; pass, skipped, flaky and unexpected-pass are ignored)");
        }
    }
    return baseline;
}

Result<ConformBaseline> LoadConformBaseline(const std::string& file) {
    Result<std::string> text = ReadInputFile(file, kBaselineInput);
    if (!text) return std::unexpected(text.error());
    return ParseConformBaseline(file, *text);
}

void ApplyBaseline(std::vector<ConformRow>& rows, const ConformBaseline& baseline) {
    for (ConformRow& row : rows) {
        if (!baseline.Lists(row.caseName, row.stage, row.backend)) continue;
        if (IsConformFailure(row)) {
            row.detail = "known failure (" + row.status + ")" + (row.detail.empty() ? "" : ": " + row.detail);
            row.status = "expected-fail";
        } else if (row.status == "pass") {
            row.status = "unexpected-pass";
            row.detail = "listed in the baseline as a failure" + (row.detail.empty() ? "" : "; " + row.detail);
        }
    }
}

int ConformExitCode(const std::vector<ConformRow>& rows) {
    bool failed = false, compared = false, broken = false;
    for (const ConformRow& r : rows) {
        failed |= r.status == "fail" || r.status == "unexpected-pass";
        broken |= IsBrokenStatus(r.status);
        compared |= r.status != "skipped";
    }
    // A backend that crashed or could not run its stages is a failure (1), before a check that failed (5).
    if (broken) return kExitFailed;
    if (failed) return kExitNonConformant;
    return compared ? kExitOk : kExitNoBackend;
}

std::string ConformSummary(const std::vector<ConformRow>& rows) {
    std::vector<std::pair<std::string, size_t>> counts;
    for (const ConformRow& r : rows) {
        auto it = std::ranges::find(counts, r.status, &std::pair<std::string, size_t>::first);
        if (it == counts.end())
            counts.emplace_back(r.status, 1);
        else
            ++it->second;
    }
    std::string text = std::to_string(rows.size()) + (rows.size() == 1 ? " row" : " rows");
    for (size_t k = 0; k < counts.size(); ++k)
        text += (k ? ", " : ": ") + std::to_string(counts[k].second) + " " + counts[k].first;
    const int code = ConformExitCode(rows);
    const char* meaning = code == kExitOk            ? "every compared row conforms"
                          : code == kExitFailed      ? "a backend failed or crashed"
                          : code == kExitNoBackend   ? "no backend was compared"
                                                     : "a row does not conform";
    return text + "; exit " + std::to_string(code) + ", " + meaning;
}

namespace {
std::string CsvField(const std::string& text) {
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) {
        if (c == '"') quoted += '"';
        quoted += c;
    }
    return quoted + "\"";
}
}  // namespace

std::string ConformCsv(const std::vector<ConformRow>& rows) {
    const bool cases = AnyCase(rows);
    std::string csv = std::string(cases ? "case," : "") + "stage,backend,status,rule,worst,tolerance,detail\n";
    char number[64];
    for (const ConformRow& r : rows) {
        if (cases) csv += CsvField(r.caseName) + ",";
        csv += CsvField(r.stage) + "," + CsvField(r.backend) + "," + CsvField(r.status) + "," + CsvField(r.rule) + ",";
        std::snprintf(number, sizeof number, "%.9g", r.worst);
        csv += std::string(number) + ",";
        std::snprintf(number, sizeof number, "%.9g", r.tolerance);
        csv += std::string(number) + "," + CsvField(r.detail) + "\n";
    }
    return csv;
}

std::string ConformJUnit(const std::vector<ConformRow>& rows, const std::string& scene) {
    std::vector<JUnitCase> cases;
    char numbers[96];
    for (const ConformRow& r : rows) {
        JUnitCase c;
        c.classname = scene + (r.caseName.empty() ? "" : "." + r.caseName) + "." + r.backend;
        c.name = r.stage;
        if (r.status == "fail" || r.status == "unexpected-pass") {
            std::snprintf(numbers, sizeof numbers, "worst %.9g, tolerance %.9g", r.worst, r.tolerance);
            c.result = JUnitCase::Result::Failure;
            c.type = r.status;
            c.message = std::string(r.status == "fail" ? "" : "listed as a known failure, but passes: ") + numbers +
                        " (" + r.rule + ")";
            c.text = r.detail;
        } else if (r.status == "failed") {
            c.result = JUnitCase::Result::Error;
            c.type = "failed";
            c.message = r.detail;
        } else if (r.status == "skipped" || r.status == "expected-fail") {
            c.result = JUnitCase::Result::Skipped;
            c.message = r.status == "skipped" ? r.detail : "a known failure (--baseline): " + r.detail;
        } else if (r.status != "pass") {  // flaky: passed on a rerun
            c.text = r.status + ": " + r.detail;
        }
        cases.push_back(std::move(c));
    }
    return JUnitXml("cloudbench conform", "conform " + scene, cases);
}

}  // namespace cb
