// What `cloudbench conform` makes of its rows (harness/Conform.h): the text
// table, conform.json with its coverage summary, conform.csv, --baseline,
// --flake-reruns and the exit code. The comparisons are in harness/Conform.cpp.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/SceneNames.h"
#include "harness/Command.h"
#include "harness/Conform.h"

namespace cb {
namespace {

// A backend that could not run its stages, or whose process died (ChildFailure::status).
bool IsBrokenStatus(const std::string& status) {
    return status == "failed" || status == "crashed" || status == "timed out" || status == "out of memory";
}

}  // namespace

report::Table ConformTable(const std::vector<ConformRow>& rows) {
    using report::Column;
    report::Table table({Column("stage").Width(13).Separator("  "), Column("backend").Width(8),
                         Column("result").Width(8), Column("rule").Width(28),
                         Column("worst").Real("%.4g").Width(12).AlignRight(), Column("where").Separator("  ")},
                        report::TextLayout::Columns);
    for (const ConformRow& r : rows) table.rows.push_back({r.stage, r.backend, r.status, r.rule, r.worst, r.detail});
    return table;
}

nlohmann::json ConformJson(const Scene& scene, const std::vector<ConformRow>& rows) {
    nlohmann::json list = nlohmann::json::array();
    for (const ConformRow& r : rows)
        list.push_back({{"stage", r.stage},
                        {"backend", r.backend},
                        {"status", r.status},
                        {"rule", r.rule},
                        {"worst", r.worst},
                        {"tolerance", r.tolerance},
                        {"detail", r.detail},
                        {"difference_image", r.differenceImage}});
    return {{"format", "cloudbench-conform/1"},
            {"scene", scene.name},
            {"steps", scene.steps},
            {"results", list},
            {"coverage", ConformCoverage(scene, rows)}};
}

nlohmann::json ConformCoverage(const Scene& scene, const std::vector<ConformRow>& rows) {
    auto options = [&](const std::string& stage) -> nlohmann::json {
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
        if (stage == "render_splat")
            return {{"phase", PhaseKindName(scene.phase.kind)},
                    {"culling", scene.splat.culling},
                    {"skipping", scene.splat.skipping},
                    {"storage", StorageFormatName(scene.shade.storage)},
                    {"cameras", scene.render.cameras.size()},
                    {"frames_per_step", std::max(scene.render.framesPerStep, 1u)}};
        return nlohmann::json::object();
    };
    nlohmann::json coverage = nlohmann::json::object();
    for (const ConformRow& r : rows) {
        if (r.stage == "(all)" || r.status == "skipped" || IsBrokenStatus(r.status)) continue;
        if (!coverage.contains(r.stage))
            coverage[r.stage] = {{"options", options(r.stage)}, {"compared_on", nlohmann::json::array()}};
        coverage[r.stage]["compared_on"].push_back(r.backend);
    }
    return coverage;
}

bool IsConformFailure(const ConformRow& row) { return row.status == "fail" || IsBrokenStatus(row.status); }

void MergeRerun(std::vector<ConformRow>& first, const std::vector<ConformRow>& rerun, uint32_t attempt) {
    for (ConformRow& row : first) {
        if (!IsConformFailure(row)) continue;
        auto again = std::ranges::find_if(
            rerun, [&](const ConformRow& r) { return r.stage == row.stage && r.backend == row.backend; });
        if (again == rerun.end() || again->status != "pass") continue;
        const std::string why = row.detail;
        const std::string was = row.status;
        row = *again;
        row.status = "flaky";
        row.detail = "passed on rerun " + std::to_string(attempt) + "; the first run: " + was +
                     (why.empty() ? "" : ", " + why);
    }
}

bool ConformBaseline::Lists(const std::string& stage, const std::string& backend) const {
    return std::ranges::find(knownFailures, std::pair{stage, backend}) != knownFailures.end();
}

Result<ConformBaseline> ParseConformBaseline(const std::string& file, const std::string& text) {
    ConformBaseline baseline;
    std::istringstream in(text);
    std::string line;
    for (uint32_t number = 1; std::getline(in, line); ++number) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const size_t start = line.find_first_not_of(" \t");
        if (start == std::string::npos || line[start] == '#') continue;
        // The first three fields; further ones (a conform.csv's rule, worst, ...) are ignored.
        std::vector<std::string> fields;
        size_t at = 0;
        while (fields.size() < 3) {
            const size_t comma = line.find(',', at);
            std::string field = line.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
            const size_t b = field.find_first_not_of(" \t"), e = field.find_last_not_of(" \t");
            fields.push_back(b == std::string::npos ? "" : field.substr(b, e - b + 1));
            if (comma == std::string::npos) break;
            at = comma + 1;
        }
        auto bad = [&](const std::string& reason) -> Result<ConformBaseline> {
            return MakeError(file + ": line " + std::to_string(number) + ": " + reason);
        };
        if (fields.size() < 3) return bad("expected stage,backend,status");
        if (fields[0] == "stage" && fields[1] == "backend" && fields[2] == "status") continue;  // a CSV header
        if (fields[0].empty()) return bad("empty stage");
        if (fields[1].empty()) return bad("empty backend");
        const std::string& status = fields[2];
        if (status == "fail" || IsBrokenStatus(status) || status == "expected-fail") {
            if (baseline.Lists(fields[0], fields[1]))
                return bad(fields[0] + "," + fields[1] + " is listed twice");
            baseline.knownFailures.emplace_back(fields[0], fields[1]);
        } else if (status != "pass" && status != "skipped" && status != "flaky" && status != "unexpected-pass") {
            return bad("unknown status '" + status +
                       "' (fail, failed, crashed, timed out, out of memory or expected-fail list a known "
                       "failure; pass, skipped, flaky and unexpected-pass are ignored)");
        }
    }
    return baseline;
}

Result<ConformBaseline> LoadConformBaseline(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return MakeError(file + ": cannot read: " + std::strerror(errno));
    std::ostringstream text;
    text << in.rdbuf();
    return ParseConformBaseline(file, text.str());
}

void ApplyBaseline(std::vector<ConformRow>& rows, const ConformBaseline& baseline) {
    for (ConformRow& row : rows) {
        if (!baseline.Lists(row.stage, row.backend)) continue;
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
    std::string csv = "stage,backend,status,rule,worst,tolerance,detail\n";
    char number[64];
    for (const ConformRow& r : rows) {
        csv += CsvField(r.stage) + "," + CsvField(r.backend) + "," + CsvField(r.status) + "," + CsvField(r.rule) + ",";
        std::snprintf(number, sizeof number, "%.9g", r.worst);
        csv += std::string(number) + ",";
        std::snprintf(number, sizeof number, "%.9g", r.tolerance);
        csv += std::string(number) + "," + CsvField(r.detail) + "\n";
    }
    return csv;
}

}  // namespace cb
