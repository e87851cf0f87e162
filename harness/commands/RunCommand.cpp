// `cloudbench run`: runs a scene on each backend, times every stage, writes
// results.json, the last frame of each camera and a top view of the density map.
#include <cstdio>
#include <map>

#include "harness/platform/Isolation.h"
#include "harness/platform/OutputFolder.h"
#include "harness/report/Report.h"
#include "harness/report/html/ReportSections.h"
#include "harness/run/RunTransfer.h"
#include "harness/run/Session.h"
#include "harness/run/Simulation.h"
#include "harness/run/SimulationState.h"

namespace cb {
namespace {

constexpr const char* kHelpHead = R"(usage: cloudbench run [SCENE] [options]

Runs SCENE (a name in scenes/ or a path to a .json file; default: thesis-medium)
on each backend, prints a per-stage timing table (median and spread over the
steps after warm-up, stages in the order a step runs them, "-" for a stage with
no sample), each camera's frame rate, each renderer's time per camera frame
beside the source documents' figures, the whole loop's frame rate (simulation
and frames, wall time), how often each stage ran and skipped, and the cloud
cover, and writes
DIR/results.json, the last frame of each camera (DIR/frame-splat-<camera>-<backend>
.exr and .png) and a top view of the last density map, DIR/topview-<backend>.png.

Options:
  --backend LIST     comma-separated backends (cpu, gl, vk); default: all built.
                     An unavailable backend is reported and the others still run;
                     --backends is the same
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>)
  --set PATH=VALUE   override a scene field by its dotted path, validated like
                     the file: --set ca.seed=42 --set grid.size=[64,64,16]
  --threads N        CPU backend threads (default: all)
  --cpu-isa ISA      CPU kernels' SIMD target: auto (default: the best here), scalar, sse4, avx2, avx512
  --vk-device DEV    Vulkan device: index or part of the name (cloudbench devices)
)";
constexpr const char* kHelpTail = R"(                     (the contexts and layouts: docs/cli.md; cloudbench devices)
  --quiet            no progress lines (on stderr: the step, an estimate of the
                     time left, and a line when a backend ends)
  --timing MODE      how a step is timed (docs/performance.md, "Two ways to time a
                     step"): synchronized (default; the thesis's way: each stage
                     completes before the next, per-stage wall and device times),
                     pipelined (a step, time-sliced a frame, is one batch with one
                     wait; per-stage device times from timestamps inside it), or
                     both (the two alternated in the order S P P S, so that a
                     drift over the run weighs the same on each; reported apart)
  --save-state DIR   save the simulation's state in folder DIR at the end of the
                     run (one backend only; replaced atomically; docs/results.md)
  --save-state-every N  also save it to DIR after every N steps
  --resume DIR       continue the run saved in DIR, on any backend: steps
                     SAVED .. steps-1 (--steps is the total, as without --resume);
                     the scene and --set options must be those it was saved with,
                     steps aside (a bad or mismatched state exits 3)
)";
const std::string kHelp = kHelpHead + GlOptionsHelp() + kHelpTail + IsolationOptionsHelp();

// run's own options (docs/cli.md), besides crash isolation's.
struct RunOptions : OwnOptions {
    // --timing: "synchronized", "pipelined" or "both" (docs/performance.md, "Two ways to time a step").
    std::string timing = "synchronized";
    // --save-state DIR, --save-state-every N (0 = only at the end), --resume DIR (harness/run/SimulationState.h).
    std::string saveState, resumeState;
    uint32_t saveStateEvery = 0;
};

std::vector<OptionSpec> RunOptionSpecs() {
    std::vector<OptionSpec> options = IsolationOptions();
    options.push_back(
        OwnOption<RunOptions>("--timing", true, [](RunOptions& o, const char* v) -> std::optional<std::string> {
            const std::string value = v ? v : "";
            if (value != "synchronized" && value != "pipelined" && value != "both")
                return "--timing: must be synchronized, pipelined or both" +
                       (v ? " (got '" + value + "')" : std::string());
            o.timing = value;
            return std::nullopt;
        }));
    options.push_back(TextOption("--save-state", &RunOptions::saveState, "--save-state needs a folder"));
    options.push_back(TextOption("--resume", &RunOptions::resumeState, "--resume needs a saved state's folder"));
    options.push_back(OwnOption<RunOptions>(
        "--save-state-every", true, [](RunOptions& o, const char* v) -> std::optional<std::string> {
            long long n = 0;
            if (auto why = ParseWholeNumber("--save-state-every", v, 1, UINT32_MAX, n)) return why;
            o.saveStateEvery = uint32_t(n);
            return std::nullopt;
        }));
    return options;
}

// What --save-state and --resume carry into a backend's run.
struct StateOptions {
    std::string sceneHash;                   // SceneSettingsHash of the resolved scene
    const SimulationState* resume = nullptr;  // read and checked before any backend opened
};

// A backend's section of the report: its timing table, the source documents' figures for its
// stages, then its renderers' time per camera frame beside theirs (the comparison `cloudbench
// report` makes).
report::Section RunSection(const Scene& scene, const BackendRun& run) {
    report::Section section = TimingSection(scene, run);
    const nlohmann::json doc = ResultsJson(scene, {run});
    for (const std::string& line : html::StageFigureLines(doc, run.name))
        section.blocks.push_back(report::Paragraph{line});
    for (const std::string& line : html::FrameFigureLines(doc, run.name))
        section.blocks.push_back(report::Paragraph{line});
    return section;
}

// Steps the simulation to the end, then writes the last frame of each camera
// and the top view; whatever fails is recorded in `run` and the rest goes on.
// Each step's record is sent (to the parent, when isolated) as it is done.
// Returns false when an output could not be written.
bool RunBackend(const Session& session, const RunOptions& own, Backend& backend, BackendRun& run,
                std::vector<std::string>& written, const SendMessage& send, const StateOptions& state) {
    const Scene& scene = session.GetScene();
    const std::string& outDir = session.OutDir();
    const CommonOptions& options = session.Options();
    MarkPhase("creating the simulation");
    auto sim = Simulation::Create(scene, backend);
    if (sim && state.resume) {
        MarkPhase("restoring the saved state");
        if (Status s = RestoreSimulationState(**sim, *state.resume); !s)
            sim = std::unexpected(Error{own.resumeState + ": " + s.error().message});
    }
    if (!sim) {
        run.status = "failed";
        run.error = sim.error().message;
        return true;
    }
    bool allWritten = true;
    auto failed = [&](const Error& error) {
        std::fprintf(stderr, "%s\n", error.message.c_str());
        allWritten = false;
    };
    // The state after the steps so far, in --save-state's folder (written whole or not at all).
    auto saveState = [&]() {
        MarkPhase("saving the state");
        if (Status s = SaveSimulationState(**sim, own.saveState, state.sceneHash); !s)
            failed(s.error());
        else if (!options.quiet)
            std::fprintf(stderr, "%s: state saved at step %u\n", own.saveState.c_str(), (*sim)->CurrentStep());
    };
    Progress progress(run.name, scene.steps, options.quiet);
    for (uint32_t t = (*sim)->CurrentStep(); t < scene.steps; ++t) {
        StepRecord record;
        (*sim)->SetTiming(TimingOfStep(own.timing, t));
        if (Status status = (*sim)->Step(record); !status) {
            run.status = "failed";
            run.error = "step " + std::to_string(t) + ": " + status.error().message;
            break;
        }
        send({{"step", transfer::ToJson(record)}});
        run.steps.push_back(record);
        progress.Update(t + 1);
        if (own.saveStateEvery && (t + 1) % own.saveStateEvery == 0 && t + 1 < scene.steps) saveState();
    }
    progress.Finish();
    // A failed step leaves no state to save: the last one saved (if any) stays.
    if (!own.saveState.empty() && run.status == "ok") saveState();
    MarkPhase("writing frames");
    // The last frame of each renderer and camera.
    for (Resource image : kAllResources) {
        if (!IsPerCamera(image) || !(*sim)->Get(image) || !(*sim)->LastRenderedStep()) continue;
        const Stage renderer = *ProducerOf(image, scene.stages);
        for (size_t n = 0; n < scene.render.cameras.size(); ++n) {
            auto rgb = Download<float>(backend, *(*sim)->Get(image, n), &run.downloadMs);
            if (!rgb) {
                failed(rgb.error());
                continue;
            }
            const std::string stem = outDir + "/" + FrameFileStem(renderer, scene.render.cameras[n].name, run.name);
            // An HDR renderer's PNG is tone-mapped as its descriptor says for the scene.
            std::optional<FrameToneMap> toneMap;
            if (const auto map = Describe(renderer).renderer->toneMap) toneMap = map(scene);
            auto paths = WriteFrame(stem, *rgb, scene.render.width, scene.render.height, true, toneMap);
            if (paths)
                written.insert(written.end(), paths->begin(), paths->end());
            else
                failed(paths.error());
        }
    }
    // The density map of the last step, seen from above.
    MarkPhase("writing the top view");
    if (const Buffer* columnSum = (*sim)->ColumnSum(); columnSum && !run.steps.empty()) {
        auto d = Download<float>(backend, *columnSum, &run.downloadMs);
        const std::string png = outDir + "/topview-" + run.name + ".png";
        Status s = d ? WriteTopView(png, *d, scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz)
                     : Status(std::unexpected(d.error()));
        if (s)
            written.push_back(png);
        else
            failed(s.error());
    }
    return allWritten;
}

// One backend's whole run, in its own process when isolated: opens it (so no
// GL, Vulkan or TBB state exists in the parent), runs it, writes its frames.
// Sends {"opened": ...} and each {"step": ...}; returns the rest.
nlohmann::json IsolatedBackendRun(Session& session, const RunOptions& own, const std::string& name,
                                  const SendMessage& send, const StateOptions& state) {
    MarkPhase("opening backend");
    std::vector<OpenedBackend> opened = session.OpenBackends({name}, &session.GetScene());
    OpenedBackend& slot = opened[0];
    BackendRun run;
    run.name = name;
    run.status = slot.backend ? "ok" : std::string(BackendStatusName(slot.status));
    run.error = slot.reason;
    if (slot.backend) run.device = slot.backend->Device();
    nlohmann::json planned = slot.plannedBytes ? nlohmann::json(*slot.plannedBytes) : nlohmann::json(nullptr);
    send({{"opened",
           {{"provenance", transfer::ToJson(session.BackendRecords().back())},
            {"available", slot.backend != nullptr},
            {"status", run.status},
            {"error", run.error},
            {"device", run.device},
            {"planned_bytes", planned}}}});
    std::vector<std::string> written;
    bool allWritten = true;
    if (slot.backend) allWritten = RunBackend(session, own, *slot.backend, run, written, send, state);
    MarkPhase("closing backend");
    slot.backend.reset();
    return {{"status", run.status},
            {"error", run.error},
            {"download_ms", run.downloadMs},
            {"written", written},
            {"all_written", allWritten}};
}

int Run(const CommonOptions& options, const RunOptions& own) {
    auto session = Session::Open(options, "");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    const std::vector<std::string> names = (*session)->RequestedBackends(BuiltBackends());
    // --save-state and --resume: one backend's run; a saved state is read and checked whole before anything else.
    StateOptions state;
    std::optional<SimulationState> resumed;
    if (!own.saveState.empty() || !own.resumeState.empty()) {
        if (names.size() != 1) {
            std::fprintf(stderr, "%s: a saved state is one backend's run: name one with --backend\n",
                         own.saveState.empty() ? "--resume" : "--save-state");
            return kExitUsage;
        }
        state.sceneHash = SceneSettingsHash(SceneWithOverrides((*session)->ScenePath(), options.overrides));
    }
    if (own.saveStateEvery && own.saveState.empty()) {
        std::fprintf(stderr, "--save-state-every: needs --save-state DIR\n");
        return kExitUsage;
    }
    if (!own.resumeState.empty()) {
        auto loaded = ReadSimulationState(own.resumeState, scene, state.sceneHash);
        if (!loaded) {
            std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
            return kExitBadScene;
        }
        resumed = std::move(*loaded);
        state.resume = &*resumed;
    }
    if (!(*session)->MakeOutDir()) return kExitFailed;
    std::printf("scene %s: %ux%ux%u voxels, %u steps (%u warm-up)\n", scene.name.c_str(), scene.grid.size.nx,
                scene.grid.size.ny, scene.grid.size.nz, scene.steps, scene.warmupSteps);

    if (resumed) std::printf("resuming %s at step %u\n", own.resumeState.c_str(), resumed->step);
    std::vector<BackendRun> runs;
    std::map<std::string, nlohmann::json> failures;  // by backend: why its process gave no result
    std::vector<std::string> written;
    bool anyAvailable = false, anyFailed = false;
    // results.json is rewritten (atomically) before the first backend and after each one, so that it always
    // holds every backend finished so far, names the ones still "pending" and says whether the run is
    // "complete"; a run killed part-way leaves what was done, never a previous run's results.
    const std::string resultsPath = (*session)->OutDir() + "/results.json";
    auto writeResults = [&](size_t finished) {
        report::Report timing("Run of " + scene.name);
        for (const BackendRun& run : runs)
            if (run.status != "unavailable" && run.status != "unsupported")
                timing.sections.push_back(RunSection(scene, run));
        nlohmann::json doc = ResultsJson(scene, runs);
        for (const auto& [name, failure] : failures) doc["backends"][name]["failure"] = failure;
        doc["pending"] = nlohmann::json::array();
        for (size_t i = finished; i < names.size(); ++i) doc["pending"].push_back(names[i]);
        doc["complete"] = finished == names.size();
        doc["files"] = WrittenOutputs((*session)->OutDir(), "results.json");  // every output in place so far
        doc["report"] = report::RenderJson(timing);
        Status s = (*session)->WriteJson(resultsPath, doc);
        if (!s) std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return bool(s);
    };
    anyFailed |= !writeResults(0);
    const IsolationSettings isolation = IsolationFrom(options);
    for (size_t i = 0; i < names.size(); ++i) {
        IsolatedOutcome outcome = RunIsolated("backend " + names[i], isolation, [&](const SendMessage& send) {
            return IsolatedBackendRun(**session, own, names[i], send, state);
        });
        // What the backend's process sent before it ended is kept, whatever became of it.
        BackendRun run;
        run.name = names[i];
        bool available = false;
        for (const nlohmann::json& m : outcome.messages) {
            if (m.contains("opened")) {
                const nlohmann::json& o = m["opened"];
                (*session)->AddBackendRecord(transfer::ProvenanceFromJson(o["provenance"]));
                available = o["available"].get<bool>();
                run.status = o["status"].get<std::string>();
                run.error = o["error"].get<std::string>();
                run.device = o["device"].get<std::string>();
                if (!o["planned_bytes"].is_null()) run.plannedBytes = o["planned_bytes"].get<uint64_t>();
            } else if (m.contains("step")) {
                run.steps.push_back(transfer::StepFromJson(m["step"]));
            }
        }
        if (outcome.result) {
            const nlohmann::json& r = *outcome.result;
            run.status = r["status"].get<std::string>();
            run.error = r["error"].get<std::string>();
            run.downloadMs = r["download_ms"].get<std::vector<double>>();
            for (const nlohmann::json& path : r["written"]) written.push_back(path.get<std::string>());
            anyFailed |= !r["all_written"].get<bool>();
        } else {
            const ChildFailure& failure = *outcome.failure;
            if (!available) (*session)->AddBackendRecord({names[i], "unavailable", "", failure.Describe()});
            available = true;  // it was asked for and did not finish: a failure, not "no backend"
            run.status = failure.status;
            run.error = failure.Describe();
            failures[run.name] = failure.Json();
        }
        anyAvailable |= available;
        if (run.status != "ok" && available) {
            anyFailed = true;
            if (outcome.failure)
                std::fprintf(stderr, "backend %s %s\n", run.name.c_str(), run.error.c_str());
            else
                std::fprintf(stderr, "backend %s failed: %s\n", run.name.c_str(), run.error.c_str());
        }
        if (available) std::printf("%s", report::RenderText(RunSection(scene, run)).c_str());
        runs.push_back(std::move(run));
        if (i + 1 < names.size()) anyFailed |= !writeResults(i + 1);
    }
    if (!writeResults(names.size())) return kExitFailed;
    written.insert(written.begin(), resultsPath);
    std::printf("results:");
    for (const std::string& path : written) std::printf(" %s", path.c_str());
    std::printf("\n");
    if (!anyAvailable) return kExitNoBackend;
    return anyFailed ? kExitFailed : kExitOk;
}

const CommandRegistration kRegistration({
    .name = "run",
    .summary = "Run a scene on one or more backends, time every stage, write results.json",
    .help = kHelp,
    .helpOrder = 0,
    .keepsWarmup = true,
    .extraOptions = RunOptionSpecs(),
    .makeOptions = MakeOwnOptions<RunOptions>,
    .run = RunWith(Run),
});

}  // namespace
}  // namespace cb
