// `cloudbench report`: one self-contained HTML page from the JSON outputs of
// run, conform, accuracy and sweep and a perf history (harness/report/html/).
#include <cstdio>

#include "harness/platform/Command.h"
#include "harness/report/InputFormats.h"
#include "harness/report/html/HtmlRender.h"
#include "harness/report/html/HtmlReport.h"
#include "harness/run/Session.h"

namespace cb {
namespace {

constexpr const char* kHelp = R"(usage: cloudbench report [RESULTS...] [--history FILE] [-o FILE]

Writes one self-contained HTML page (no script, no network; plots as inline
SVG, images embedded) from any of results.json, conform.json, accuracy.json,
sweep.json and `perf compare --json` files (recognised by their "format"; a
folder stands for those of them it holds, a kept interleave `perf compare
--keep DIR` for its verdict, DIR/compare.json) and a perf history (JSON Lines
of cloudbench-perf/1 records): the provenance and the verdict with its exit
code, the regression gate's comparison table with its marks, the stage x backend
conformance matrix, per-stage timing tables beside the source documents'
figures, box plots of the per-step times, history plots, the accuracy Pareto
plots, the rendered frames with their difference images, and each input's own
tables.

  -o, --output FILE   the page to write (default report.html)
  --history FILE      a perf history; lines that are not JSON are skipped
                      with a warning, a record that breaks the format is
                      an error

Exits 0 when the page is written (whatever the verdict it shows), 1 when it
cannot be written, 2 for a bad command line (no input), 3 for an input that
cannot be read or is not a cloudbench output (the message names the file).
)";

// report's own options (docs/cli.md).
struct ReportOptions : OwnOptions {
    std::string history;  // --history FILE
    std::string outFile;  // -o FILE; "" = report.html
};

int Report(const CommonOptions& options, const ReportOptions& own) {
    if (options.arguments.empty() && own.history.empty()) {
        std::fprintf(stderr,
                     "cloudbench: report needs a results, conform, accuracy, sweep or perf compare file, or "
                     "--history\n\n%s",
                     kHelp);
        return kExitUsage;
    }
    std::vector<html::ReportInput> inputs;
    for (const std::string& path : options.arguments) {
        auto read = html::ReadReportInput(path);
        if (!read) {
            std::fprintf(stderr, "%s\n", read.error().message.c_str());
            return kExitBadScene;
        }
        for (html::ReportInput& input : *read) inputs.push_back(std::move(input));
    }
    std::vector<nlohmann::json> history;
    if (!own.history.empty()) {
        auto read = input::ReadHistory(own.history);
        if (!read) {
            std::fprintf(stderr, "%s\n", read.error().message.c_str());
            return kExitBadScene;
        }
        input::PrintWarnings(*read);
        for (input::HistoryRecord& r : read->records) history.push_back(std::move(r.record));
    }
    std::string page;
    try {
        page = html::RenderHtml(html::BuildReport(inputs, history, own.history));
    } catch (const nlohmann::json::exception& e) {
        // A field of the right name and the wrong type in one of the inputs.
        std::fprintf(stderr, "cloudbench: report: an input has an unexpected shape: %s\n", e.what());
        return kExitBadScene;
    }
    const std::string out = own.outFile.empty() ? "report.html" : own.outFile;
    if (Status s = Session::WriteText(out, page); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::printf("report: %s\n", out.c_str());
    return kExitOk;
}

const CommandRegistration kRegistration({
    .name = "report",
    .summary = "Write one HTML page from results, conform, accuracy, sweep, perf compare and history files",
    .help = kHelp,
    .helpOrder = 6,
    .takesScene = false,
    .takesArguments = true,
    .extraOptions = {{"-o",
                      "--output",
                      true,
                      {},
                      [](OwnOptions& own, const char* v) {
                          return StoreText("-o", dynamic_cast<ReportOptions&>(own).outFile, v,
                                           "-o needs a file, e.g. -o report.html");
                      }},
                     TextOption("--history", &ReportOptions::history, "--history needs a file")},
    .makeOptions = MakeOwnOptions<ReportOptions>,
    .run = RunWith(Report),
});

}  // namespace
}  // namespace cb
