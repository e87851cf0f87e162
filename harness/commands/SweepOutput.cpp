// The output half of `cloudbench sweep` (harness/commands/SweepOutput.h).
#include "harness/commands/SweepOutput.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "core/base/InstallLayout.h"
#include "harness/accuracy/SweepFields.h"
#include "harness/platform/Command.h"
#include "harness/run/Session.h"

extern char** environ;

namespace cb {

using nlohmann::json;

namespace {

// What became of the plot.
enum class PlotOutcome {
    Plotted,
    NotPromised,  // no python3 with matplotlib: the JSON and the table stand without it (a note says so)
    Failed,       // the plotter ran and failed: sweep.png is missing, and the command exits 1
};

// Runs `argv` (argv[0] a path, or a name looked up on the PATH) with `fd` as its descriptor 3 and its standard
// error captured; returns the exit status (128 + the signal that killed it) and
// what it printed on standard error (the last 64 KiB).
Result<std::pair<int, std::string>> RunCaptured(const std::vector<std::string>& argv, int fd) {
    auto cannot = [&](int error) { return MakeError(argv[0] + ": cannot run: " + std::strerror(error)); };
    int pipeFds[2];
    if (pipe2(pipeFds, O_CLOEXEC) != 0) return cannot(errno);
    // Never 3 itself, so that dup2 onto 3 clears close-on-exec.
    const int high = fcntl(fd, F_DUPFD_CLOEXEC, 10);
    if (high < 0) {
        const int error = errno;
        close(pipeFds[0]);
        close(pipeFds[1]);
        return cannot(error);
    }
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, pipeFds[1], STDERR_FILENO);
    posix_spawn_file_actions_adddup2(&actions, high, 3);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    pid_t pid = 0;
    const int spawned = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(high);
    close(pipeFds[1]);
    if (spawned != 0) {
        close(pipeFds[0]);
        return cannot(spawned);
    }
    std::string captured;
    char chunk[4096];
    for (;;) {
        const ssize_t n = read(pipeFds[0], chunk, sizeof chunk);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        captured.append(chunk, size_t(n));
        if (captured.size() > 65536) captured.erase(0, captured.size() - 65536);
    }
    close(pipeFds[0]);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return MakeError(argv[0] + ": cannot wait: " + std::strerror(errno));
    return std::pair(WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status), captured);
}

// Plots sweep.json into `pngPath` with tools/plot_sweep.py (matplotlib).
// The plotter is given the temporary file as descriptor 3 and writes it by the
// name /proc/self/fd/3, which no link in the folder can redirect
// (Session::TemporaryFile); it prints one line on failure ("plot_sweep.py:
// REASON"), which becomes this error: "DIR/sweep.png: cannot write: <reason>".
PlotOutcome Plot(const std::string& jsonPath, const std::string& mdPath, const std::string& pngPath) {
    // Debian's python3-matplotlib is for /usr/bin/python3, which another python3
    // on the PATH (a virtual environment, pyenv) may hide: the first that has it.
    std::string python;
    for (const char* candidate : {"/usr/bin/python3", "python3"})
        if (std::system((std::string(candidate) + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) == 0) {
            python = candidate;
            break;
        }
    if (python.empty()) {
        std::fprintf(stderr,
                     "sweep: no plot: python3 with matplotlib was not found (apt-get install "
                     "python3-matplotlib); %s and %s are written\n",
                     jsonPath.c_str(), mdPath.c_str());
        return PlotOutcome::NotPromised;
    }
    const std::string script = ToolsFolder() + "/plot_sweep.py";
    const Status plotted = Session::WriteAtomically(pngPath, [&](const Session::TemporaryFile& temp) -> Status {
        auto ran = RunCaptured({python, script, jsonPath, "/proc/self/fd/3", pngPath}, temp.fd);
        if (!ran) return MakeError(pngPath + ": cannot write: " + ran.error().message);
        const auto& [status, captured] = *ran;
        // Everything but the plotter's last line (warnings) is passed on; the last line is its reason.
        std::string_view text(captured);
        while (!text.empty() && text.back() == '\n') text.remove_suffix(1);
        const size_t lastBreak = text.rfind('\n');
        std::string_view last = lastBreak == std::string_view::npos ? text : text.substr(lastBreak + 1);
        const std::string_view before = lastBreak == std::string_view::npos ? "" : text.substr(0, lastBreak + 1);
        if (status == 0) {
            std::fputs(captured.c_str(), stderr);
            return {};
        }
        std::fwrite(before.data(), 1, before.size(), stderr);
        constexpr std::string_view kPrefix = "plot_sweep.py: ";
        if (last.starts_with(kPrefix)) last.remove_prefix(kPrefix.size());
        // The plotter names the file it was told to show, with the reason: "DIR/sweep.png: cannot write: ...".
        if (last.starts_with(pngPath + ": ")) return MakeError(std::string(last));
        if (!last.empty()) return MakeError(pngPath + ": cannot write: plot_sweep.py: " + std::string(last));
        return MakeError(pngPath + ": cannot write: plot_sweep.py " +
                         (status > 128 ? "was killed by signal " + std::to_string(status - 128)
                                       : "exited " + std::to_string(status)));
    });
    if (plotted) return PlotOutcome::Plotted;
    std::fprintf(stderr, "%s\nsweep: %s and %s are written, %s is not\n", plotted.error().message.c_str(),
                 jsonPath.c_str(), mdPath.c_str(), pngPath.c_str());
    return PlotOutcome::Failed;
}

}  // namespace

int WriteSweepOutputs(json doc, const std::string& sceneName, const std::string& metric,
                      const std::vector<SweepAxis>& axes, const std::vector<Stage>& stages,
                      const std::vector<Row>& rows, const std::string& outDir, const SweepJsonWriter& writeJson) {
    doc["vary"] = json::array();
    doc["rows"] = json::array();
    for (const SweepAxis& a : axes) doc["vary"].push_back({{"path", a.path}, {"values", a.values}});
    report::Report report("Sweep of " + sceneName);
    const std::string error = metric == "psnr" ? "PSNR (higher is better)" : metric + " |error| over all elements";
    report.sections.push_back(
        {"",
         {report::Paragraph{"Pareto front (*) on median time and " + error +
                            ", per stage; *= marks a front row tied with another (the same error, overlapping q1-q3 "
                            "times). A row lists the varied fields its stage reads; it stands for any value "
                            "of the others."}}});
    for (Stage stage : stages) {
        report::Table table;
        for (const SweepAxis& a : axes) table.columns.emplace_back(a.path);
        for (report::Column& c : ErrorColumns({}, stage)) table.columns.push_back(std::move(c));
        table.columns.insert(table.columns.begin() + ptrdiff_t(axes.size()) + 1, report::Column("pareto"));
        for (const Row& r : rows) {
            if (r.stage != stage) continue;
            Row shown = r;
            shown.settings = SettingsRead(r.stage, r.settings);
            doc["rows"].push_back(RowJson(shown));
            doc["rows"].back()["pareto"] = r.pareto;
            doc["rows"].back()["pareto_tie"] = r.paretoTie;
            std::vector<report::Cell> cells;
            for (const SweepAxis& a : axes) {
                auto it = std::ranges::find(shown.settings, a.path, &SceneOverride::path);
                cells.push_back(it != shown.settings.end() ? it->value : "any");
            }
            for (report::Cell& cell : RowCells(r)) cells.push_back(std::move(cell));
            cells.insert(cells.begin() + ptrdiff_t(axes.size()) + 1, r.paretoTie ? "*=" : r.pareto ? "*" : "");
            table.rows.push_back(std::move(cells));
        }
        if (table.rows.empty()) continue;
        report::Section section{std::string(StageName(stage)), {std::move(table)}};
        std::printf("\n%s", report::RenderText(section).c_str());
        report.sections.push_back(std::move(section));
    }
    doc["report"] = report::RenderJson(report);

    const std::string jsonPath = outDir + "/sweep.json", mdPath = outDir + "/sweep.md", pngPath = outDir + "/sweep.png";
    if (Status s = writeJson(jsonPath, doc); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    // Nothing to plot without a measured row (an empty shard, or every backend unavailable).
    const bool measured = std::ranges::any_of(rows, [](const Row& r) { return r.result.status == "ok"; });
    const PlotOutcome plot = measured ? Plot(jsonPath, mdPath, pngPath) : PlotOutcome::NotPromised;
    const bool plotted = plot == PlotOutcome::Plotted;
    if (plotted) report.sections.push_back({"Plot", {report::Image{"sweep.png", "error against time"}}});
    if (Status s = Session::WriteText(mdPath, report::RenderMarkdown(report)); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::printf("results: %s %s%s\n", jsonPath.c_str(), mdPath.c_str(), plotted ? (" " + pngPath).c_str() : "");
    // A plot that python3 with matplotlib was found to make, and did not, is a missing output.
    return plot == PlotOutcome::Failed ? kExitFailed : kExitOk;
}

}  // namespace cb
