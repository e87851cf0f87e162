// The page of `cloudbench report` (BuildReport, harness/report/html/HtmlReport.h):
// the verdict and provenance, the conformance matrix, then the parts built in
// HtmlTiming.cpp, HtmlHistory.cpp, HtmlPareto.cpp and HtmlFrames.cpp, and each
// input's own report block.
#include "harness/report/html/HtmlReport.h"

#include <algorithm>
#include <map>

#include "harness/report/html/ReportJson.h"
#include "harness/report/html/ReportSections.h"

namespace cb::html {
namespace {

using report::Cell;
using report::Column;
using report::Section;
using report::Table;

report::KeyValues ProvenanceItems(const json& provenance) {
    report::KeyValues kv;
    const json& git = Obj(provenance, "git");
    const std::string dirty = Str(git, "dirty");
    kv.items.emplace_back("commit", Str(git, "commit", "unknown") + (dirty == "true" ? " (dirty)" : ""));
    const json& build = Obj(provenance, "build");
    kv.items.emplace_back("build", Str(build, "type", "?") + ", " + Str(build, "compiler", "?"));
    kv.items.emplace_back("flags", Str(build, "flags"));
    const json& machine = Obj(provenance, "machine");
    kv.items.emplace_back("machine",
                          Str(machine, "cpu", "?") + ", " + Str(machine, "threads", "?") + " hardware threads");
    kv.items.emplace_back("os", Str(machine, "os"));
    kv.items.emplace_back("date", Str(provenance, "date"));
    std::string backends;
    for (const json& b : Arr(provenance, "backends")) {
        backends += (backends.empty() ? "" : "; ") + Str(b, "name") + " " + Str(b, "status");
        const std::string device = Str(b, "device"), reason = Str(b, "reason");
        if (!device.empty()) backends += " (" + device + ")";
        if (!reason.empty()) backends += ": " + reason;
    }
    kv.items.emplace_back("backends", backends);
    const json& scene = Obj(provenance, "scene");
    std::string overrides;
    for (const json& o : Arr(scene, "overrides"))
        overrides += (overrides.empty() ? "" : ", ") + Str(o, "path") + "=" + Str(o, "value");
    kv.items.emplace_back("scene", Str(scene, "path") + (overrides.empty() ? "" : " with " + overrides));
    std::string commandLine;
    for (const json& arg : Arr(provenance, "command_line"))
        commandLine += (commandLine.empty() ? "" : " ") + (arg.is_string() ? arg.get<std::string>() : arg.dump());
    kv.items.emplace_back("command line", commandLine);
    return kv;
}

// An input's provenance: its own, or for a perf compare file HEAD's (the file has none of its own).
const json& ProvenanceOf(const ReportInput& input) {
    return input.kind == InputKind::Compare ? Obj(Obj(input.doc, "head"), "provenance")
                                            : Obj(input.doc, "provenance");
}

}  // namespace

report::Report BuildReport(const std::vector<ReportInput>& inputs, const std::vector<json>& history,
                           const std::string& historyPath) {
    std::string scenes;
    for (const ReportInput& input : inputs) {
        const json& scene = input.doc.contains("scene") ? input.doc["scene"] : json();
        const std::string name = scene.is_object()   ? Str(scene, "name")
                                 : scene.is_string() ? scene.get<std::string>()
                                                     : "";
        if (!name.empty() && scenes.find(name) == std::string::npos) scenes += (scenes.empty() ? "" : ", ") + name;
    }
    report::Report out("cloudbench report" + (scenes.empty() ? std::string() : ": " + scenes));

    // Verdict: each input's, then the combined code.
    Section verdict{"Verdict", {}};
    std::vector<Verdict> verdicts;
    Table verdictTable(
        {Column("input"), Column("kind"), Column("exit code").Integer(), Column("verdict"), Column("why")});
    for (const ReportInput& input : inputs) {
        const Verdict v = VerdictOf(input);
        verdicts.push_back(v);
        verdictTable.rows.push_back({input.path, std::string(InputKindName(input.kind)), int64_t(v.exitCode),
                                     v.exitCode == 0 ? "pass" : "fail", v.reason});
    }
    const int combined = CombinedExitCode(verdicts);
    verdict.blocks.emplace_back(report::Paragraph{combined == 0
                                                      ? "Verdict: pass (exit code 0)."
                                                      : "Verdict: fail (exit code " + std::to_string(combined) + ")."});
    verdict.blocks.emplace_back(std::move(verdictTable));
    if (!inputs.empty()) {
        // The first input's provenance in short; every input's in full under "Provenance".
        report::KeyValues summary = ProvenanceItems(ProvenanceOf(inputs.front()));
        std::erase_if(summary.items, [](const auto& item) {
            return item.first != "commit" && item.first != "build" && item.first != "machine" && item.first != "date";
        });
        verdict.blocks.emplace_back(std::move(summary));
    }
    out.sections.push_back(std::move(verdict));

    // Conformance: stage x backend, and with conform --matrix one row per case and stage, so that
    // a failure in one case is not hidden by another case's pass.
    for (const ReportInput& input : inputs) {
        if (input.kind != InputKind::Conform) continue;
        const json& results = Arr(input.doc, "results");
        const bool cases = std::ranges::any_of(results, [](const json& r) { return r.contains("case"); });
        std::vector<std::pair<std::string, std::string>> rowKeys;  // (case, stage), in order of appearance
        std::vector<std::string> backends;
        std::map<std::pair<std::pair<std::string, std::string>, std::string>, std::string> status;
        for (const json& r : results) {
            const std::pair<std::string, std::string> key{Str(r, "case"), Str(r, "stage")};
            const std::string backend = Str(r, "backend");
            if (std::ranges::find(rowKeys, key) == rowKeys.end()) rowKeys.push_back(key);
            if (std::ranges::find(backends, backend) == backends.end()) backends.push_back(backend);
            status[{key, backend}] = Str(r, "status");
        }
        std::vector<Column> columns;
        if (cases) columns.push_back(Column("case"));
        columns.push_back(Column("stage"));
        for (const std::string& b : backends) columns.push_back(Column(b));
        Table matrix(columns);
        for (const auto& key : rowKeys) {
            std::vector<Cell> row;
            if (cases) row.push_back(key.first);
            row.push_back(key.second);
            for (const std::string& b : backends) {
                auto it = status.find({key, b});
                row.push_back(it == status.end() ? Cell() : Cell(it->second));
            }
            matrix.rows.push_back(std::move(row));
        }
        out.sections.push_back({"Conformance matrix: " + Str(input.doc, "scene") + " (" + input.path + ")",
                                {report::Paragraph{"Each backend's stages against the CPU's by SPEC's rule, over " +
                                                   Str(input.doc, "steps", "?") +
                                                   " steps; the rule, worst error and place are in the conform "
                                                   "report below."},
                                 std::move(matrix)}});
    }

    // The regression gate: each perf compare file's verdict and table.
    for (const ReportInput& input : inputs)
        if (input.kind == InputKind::Compare)
            out.sections.push_back({"Performance comparison (" + input.path + ")", CompareBlocks(input)});

    // Timing: tables beside the source documents' figures, distributions, frames.
    for (const ReportInput& input : inputs) {
        if (input.kind != InputKind::Results) continue;
        const std::string scene = Str(Obj(input.doc, "scene"), "name");
        Section timing{"Stage times: " + scene + " (" + input.path + ")", {}};
        std::string backends;
        for (const auto& [name, b] : Obj(input.doc, "backends").items())
            backends += (backends.empty() ? "" : "; ") + name + ": " + Str(b, "status") +
                        (Str(b, "device").empty() ? "" : ", " + Str(b, "device")) +
                        (Str(b, "error").empty() ? "" : ", " + Str(b, "error"));
        timing.blocks.emplace_back(report::Paragraph{
            "Median and quartiles of each stage's wall time per call over the steps after warm-up (" +
            Str(Obj(input.doc, "scene"), "steps", "?") + " steps, " +
            Str(Obj(input.doc, "scene"), "warmup_steps", "?") + " warm-up). Backends: " + backends +
            ". A renderer's step draws every camera: its row `per camera frame` divides the step's time by the "
            "frames a step draws (cameras x frames per rendering step), and the source documents' figures, a frame "
            "each, stand beside that row. The source documents' figures were measured on other hardware and scenes "
            "(the thesis's 256x32x256 volume; "
            "Olajos's are whole ray-marched frames; Wang, Ji and Zhang's whole layered frames with the light "
            "precomputed): a sense of scale, not a comparison of methods."});
        timing.blocks.emplace_back(TimingTable(input.doc));
        timing.blocks.emplace_back(TimingBoxes(input));
        out.sections.push_back(std::move(timing));
    }

    if (!historyPath.empty()) out.sections.push_back({"History", HistoryBlocks(history, historyPath)});

    for (const ReportInput& input : inputs)
        if (input.kind == InputKind::Accuracy || input.kind == InputKind::Sweep)
            out.sections.push_back(
                {"Accuracy against time: " + Str(input.doc, "scene") + " (" + input.path + ")", ParetoBlocks(input)});

    for (const ReportInput& input : inputs)
        if (input.kind == InputKind::Results)
            out.sections.push_back(
                {"Frames: " + Str(Obj(input.doc, "scene"), "name") + " (" + input.path + ")", FrameBlocks(input)});

    out.sections.push_back(
        {"The source documents' figures",
         {report::Paragraph{"From docs/seed-timings.json (copied from the source documents' tables), with the "
                            "hardware each was measured on."},
          SeedSources(), SeedTable()}});

    Section provenance{"Provenance", {}};
    for (const ReportInput& input : inputs) {
        if (input.kind == InputKind::Compare) {
            for (const char* side : {"base", "head"}) {
                provenance.blocks.emplace_back(report::Paragraph{input.path + " (perf compare, " +
                                                                 (side[0] == 'b' ? "BASE" : "HEAD") + ": " +
                                                                 Str(Obj(input.doc, side), "label") + ")"});
                provenance.blocks.emplace_back(ProvenanceItems(Obj(Obj(input.doc, side), "provenance")));
            }
            continue;
        }
        provenance.blocks.emplace_back(
            report::Paragraph{input.path + " (" + std::string(InputKindName(input.kind)) + ")"});
        provenance.blocks.emplace_back(ProvenanceItems(Obj(input.doc, "provenance")));
    }
    out.sections.push_back(std::move(provenance));

    // Each input's own tables, as its command printed them; a perf compare file's are its section above.
    for (const ReportInput& input : inputs) {
        if (!input.doc.contains("report") || input.kind == InputKind::Compare) continue;
        const report::Report own = report::ReportFromJson(input.doc["report"]);
        for (const Section& s : own.sections)
            out.sections.push_back(
                {own.title + (s.title.empty() ? "" : ": " + s.title) + " (" + FileName(input.path) + ")", s.blocks});
    }
    return out;
}

}  // namespace cb::html
