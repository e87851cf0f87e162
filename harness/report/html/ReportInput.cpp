// The inputs of `cloudbench report` (harness/report/html/ReportInput.h): reading
// results, conform, accuracy and sweep files or a folder of them, and the
// verdict each records.
#include "harness/report/html/ReportInput.h"

#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <optional>

#include "core/base/ShownText.h"
#include "harness/perf/Compare.h"
#include "harness/report/InputFormats.h"
#include "harness/report/ReportModel.h"
#include "harness/report/html/ReportJson.h"

namespace cb::html {
namespace {

// The report's input at `path` (a file the user named), or, with `folder`, the file `path` names inside the folder
// the user named, read beneath it.
Result<ReportInput> ReadOne(const std::string& path, const std::string& folder = "") {
    static constexpr std::array<std::pair<input::Format, InputKind>, 5> kFormats = {{
        {input::Format::Results, InputKind::Results},
        {input::Format::Conform, InputKind::Conform},
        {input::Format::Accuracy, InputKind::Accuracy},
        {input::Format::Sweep, InputKind::Sweep},
        {input::Format::PerfCompare, InputKind::Compare},
    }};
    static constexpr std::array<input::Format, 5> kAccepted = {input::Format::Results, input::Format::Conform,
                                                               input::Format::Accuracy, input::Format::Sweep,
                                                               input::Format::PerfCompare};
    auto read = folder.empty()
                    ? input::ReadCloudbenchFile(path, kAccepted)
                    : input::ReadCloudbenchFileBeneath(folder, std::filesystem::path(path).filename().string(), kAccepted);
    if (!read) return std::unexpected(read.error());
    ReportInput in{path, InputKind::Results, std::move(read->doc)};
    for (const auto& [format, kind] : kFormats)
        if (format == read->format) in.kind = kind;
    // The report block is read back into the page: check its shape here, where the file can be named.
    if (in.doc.contains("report")) try {
            (void)report::ReportFromJson(in.doc["report"]);
        } catch (const json::exception& e) {
            return MakeError(path + ": /report: not a report block: " + ShownText(e.what(), false, 200));
        }
    return in;
}

bool Finished(const std::string& status) {
    return status == "ok" || status == "unavailable" || status == "unsupported";
}

}  // namespace

std::string_view InputKindName(InputKind kind) {
    switch (kind) {
        case InputKind::Results:
            return "results";
        case InputKind::Conform:
            return "conform";
        case InputKind::Accuracy:
            return "accuracy";
        case InputKind::Sweep:
            return "sweep";
        case InputKind::Compare:
            return "perf compare";
    }
    return "";
}

Result<std::vector<ReportInput>> ReadReportInput(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_directory(path, ec)) {
        auto one = ReadOne(path);
        if (!one) return std::unexpected(one.error());
        return std::vector<ReportInput>{std::move(*one)};
    }
    std::vector<ReportInput> inputs;
    const auto there = [&](const char* name) {
        return std::filesystem::exists(std::filesystem::symlink_status(std::filesystem::path(path) / name, ec));
    };
    if (there(perf::kInterleaveFile) && !there(perf::kKeptVerdictFile))
        return MakeError((std::filesystem::path(path) / perf::kKeptVerdictFile).string() +
                         ": missing: this kept interleave has no verdict (the live perf compare stopped before it); "
                         "`cloudbench perf compare " + path + " --json FILE` judges its runs, and report takes FILE");
    for (const char* name : {"results.json", "conform.json", "accuracy.json", "sweep.json", perf::kKeptVerdictFile}) {
        const std::string file = (std::filesystem::path(path) / name).string();
        // A name that is there in any form (a link, a FIFO) is read, so that ReadOne says what is wrong with it.
        if (!there(name)) continue;
        auto one = ReadOne(file, path);
        if (!one) return std::unexpected(one.error());
        inputs.push_back(std::move(*one));
    }
    if (inputs.empty())
        return MakeError(path + ": no results.json, conform.json, accuracy.json, sweep.json or compare.json in this "
                                "folder");
    return inputs;
}

Verdict VerdictOf(const ReportInput& input) {
    const json& doc = input.doc;
    switch (input.kind) {
        case InputKind::Results: {
            bool anyAvailable = false;
            std::string broken;
            for (const auto& [name, b] : Obj(doc, "backends").items()) {
                const std::string status = Str(b, "status");
                if (!Finished(status)) broken += (broken.empty() ? "" : ", ") + name + " " + status;
                anyAvailable |= status != "unavailable" && status != "unsupported";
            }
            if (!broken.empty()) return {1, "backend " + broken};
            if (doc.contains("complete") && !doc.value("complete", true))
                return {1, "the run did not finish (complete: false)"};
            if (!anyAvailable) return {4, "no backend was available"};
            return {};
        }
        case InputKind::Conform: {
            std::string broken, failed;
            bool compared = false;
            for (const json& r : Arr(doc, "results")) {
                const std::string status = Str(r, "status"), what = Str(r, "stage") + " on " + Str(r, "backend");
                // As conform's exit code (harness/conform/Conform.h ConformExitCode): flaky and expected-fail rows
                // (--flake-reruns, --baseline) are not failures; an unexpected pass is.
                if (status == "fail" || status == "unexpected-pass")
                    failed += (failed.empty() ? "" : ", ") + what + (status == "fail" ? "" : " " + status);
                if (status != "pass" && status != "fail" && status != "skipped" && status != "flaky" &&
                    status != "expected-fail" && status != "unexpected-pass")
                    broken += (broken.empty() ? "" : ", ") + what + " " + status;
                compared |= status != "skipped";
            }
            if (!broken.empty()) return {1, broken};
            if (!failed.empty()) return {5, "failed: " + failed};
            if (!compared) return {4, "nothing was compared"};
            return {};
        }
        case InputKind::Accuracy:
        case InputKind::Sweep: {
            std::string broken, why;
            bool measured = false;
            size_t reasons = 0;
            for (const json& r : Arr(doc, "rows")) {
                const std::string status = Str(r, "status");
                measured |= status == "ok";
                if (!Finished(status))
                    broken +=
                        (broken.empty() ? "" : ", ") + Str(r, "stage") + " on " + Str(r, "backend") + " " + status;
                // Why nothing was measured: the first few distinct reasons.
                const std::string detail = Str(r, "detail");
                if (status != "ok" && !detail.empty() && reasons < 3 && why.find(detail) == std::string::npos) {
                    why += (why.empty() ? ": " : "; ") + Str(r, "stage") + " on " + Str(r, "backend") + " " +
                           status + ": " + detail;
                    ++reasons;
                }
            }
            if (!broken.empty()) return {1, broken};
            if (!measured) return {4, "no row was measured" + why};
            return {};
        }
        case InputKind::Compare: {
            // The exit code perf compare recorded, and why: the regressions, the rows HEAD lacks, the failed runs,
            // the cut.
            Verdict v{int(Number(doc, "exit_code").value_or(0)), ""};
            std::string regressions, missing;
            for (const json& c : Arr(doc, "comparisons")) {
                const std::string name = Str(c, "scene") + "/" + Str(c, "backend") + "/" + Str(c, "stage") +
                                         (Str(c, "metric") == "time" ? "" : " instructions");
                const std::optional<double> ratio = Number(c, "ratio");
                if (c.value("regression", false))
                    regressions += (regressions.empty() ? "" : ", ") + name + " (x" +
                                   (ratio ? Fixed(*ratio, "%.2f") : std::string("?")) + ")";
                if (Str(c, "mark") == "x") missing += (missing.empty() ? "" : ", ") + name;
            }
            const size_t failed = Arr(doc, "failed_runs").size();
            if (!regressions.empty())
                v.reason = "regression: " + regressions;
            else if (!missing.empty())
                v.reason = "HEAD failed or lacks a measurement (x): " + missing;
            else if (failed)
                v.reason = std::to_string(failed) + (failed == 1 ? " run failed" : " runs failed");
            else if (!Str(doc, "cut_short").empty())
                v.reason = Str(doc, "cut_short");
            else if (v.exitCode == 6)
                v.reason = "regression";
            else if (v.exitCode != 0)
                v.reason = "perf compare could not write its output";
            return v;
        }
    }
    return {};
}

int CombinedExitCode(const std::vector<Verdict>& verdicts) {
    for (int code : {1, 5, 6, 4})
        for (const Verdict& v : verdicts)
            if (v.exitCode == code) return code;
    for (const Verdict& v : verdicts)
        if (v.exitCode != 0) return v.exitCode;
    return 0;
}

}  // namespace cb::html
