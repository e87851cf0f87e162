// `cloudbench run`: runs a scene on each backend, times every stage, writes
// results.json, the last frame of each camera and a top view of the density map.
#include <cstdio>

#include "harness/OutputFolder.h"
#include "harness/Report.h"
#include "harness/Session.h"
#include "harness/Simulation.h"

namespace cb {
namespace {

constexpr const char* kHelpHead = R"(usage: cloudbench run [SCENE] [options]

Runs SCENE (a name in scenes/ or a path to a .json file; default: thesis-medium)
on each backend, prints a per-stage timing table (median and spread over the
steps after warm-up), each camera's frame rate and the cloud cover, and writes
DIR/results.json, the last frame of each camera (DIR/frame-splat-<camera>-<backend>
.exr and .png) and a top view of the last density map, DIR/topview-<backend>.png.

Options:
  --backend LIST     comma-separated backends (cpu, gl, vk); default: all built.
                     An unavailable backend is reported and the others still run.
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>)
  --set PATH=VALUE   override a scene field by its dotted path, validated like
                     the file: --set ca.seed=42 --set grid.size=[64,16,64]
  --threads N        CPU backend threads (default: all)
  --vk-device DEV    Vulkan device: index or part of the name (cloudbench devices)
)";
constexpr const char* kHelpTail = R"(                     (the contexts and layouts: docs/cli.md; cloudbench devices)
  --quiet            no progress lines
)";
const std::string kHelp = kHelpHead + GlOptionsHelp() + kHelpTail;

// Steps the simulation to the end, then writes the last frame of each camera
// and the top view; whatever fails is recorded in `run` and the rest goes on.
// Returns false when an output could not be written.
bool RunBackend(const Session& session, Backend& backend, BackendRun& run, std::vector<std::string>& written) {
    const Scene& scene = session.GetScene();
    const std::string& outDir = session.OutDir();
    auto sim = Simulation::Create(scene, backend);
    if (!sim) {
        run.status = "failed";
        run.error = sim.error().message;
        return true;
    }
    Progress progress(run.name, scene.steps, session.Options().quiet);
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord record;
        if (Status status = (*sim)->Step(record); !status) {
            run.status = "failed";
            run.error = "step " + std::to_string(t) + ": " + status.error().message;
            break;
        }
        run.steps.push_back(record);
        progress.Update(t + 1);
    }
    bool allWritten = true;
    auto failed = [&](const Error& error) {
        std::fprintf(stderr, "%s\n", error.message.c_str());
        allWritten = false;
    };
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
            auto paths = WriteFrame(stem, *rgb, scene.render.width, scene.render.height);
            if (paths)
                written.insert(written.end(), paths->begin(), paths->end());
            else
                failed(paths.error());
        }
    }
    // The density map of the last step, seen from above.
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

int Run(const CommonOptions& options) {
    auto session = Session::Open(options, "");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    if (!(*session)->MakeOutDir()) return kExitFailed;
    std::printf("scene %s: %ux%ux%u voxels, %u steps (%u warm-up)\n", scene.name.c_str(), scene.grid.size.nx,
                scene.grid.size.ny, scene.grid.size.nz, scene.steps, scene.warmupSteps);

    std::vector<OpenedBackend> backends =
        (*session)->OpenBackends((*session)->RequestedBackends(BuiltBackends()), &scene);
    std::vector<BackendRun> runs;
    std::vector<std::string> written;
    bool anyAvailable = false, anyFailed = false;
    // results.json is rewritten (atomically) before the first backend and after each one, so that it always
    // holds every backend finished so far, names the ones still "pending" and says whether the run is
    // "complete"; a run killed part-way leaves what was done, never a previous run's results.
    const std::string resultsPath = (*session)->OutDir() + "/results.json";
    auto writeResults = [&](size_t finished) {
        report::Report timing("Run of " + scene.name);
        for (const BackendRun& run : runs)
            if (run.status == "ok" || run.status == "failed") timing.sections.push_back(TimingSection(scene, run));
        nlohmann::json doc = ResultsJson(scene, runs);
        doc["pending"] = nlohmann::json::array();
        for (size_t i = finished; i < backends.size(); ++i) doc["pending"].push_back(backends[i].name);
        doc["complete"] = finished == backends.size();
        doc["files"] = WrittenOutputs((*session)->OutDir(), "results.json");  // every output in place so far
        doc["report"] = report::RenderJson(timing);
        Status s = (*session)->WriteJson(resultsPath, doc);
        if (!s) std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return bool(s);
    };
    anyFailed |= !writeResults(0);
    for (size_t i = 0; i < backends.size(); ++i) {
        OpenedBackend& opened = backends[i];
        BackendRun run;
        run.name = opened.name;
        run.plannedBytes = opened.plannedBytes;
        if (!opened.backend) {
            run.status = std::string(BackendStatusName(opened.status));
            run.error = opened.reason;
            runs.push_back(std::move(run));
            continue;
        }
        anyAvailable = true;
        run.device = opened.backend->Device();
        anyFailed |= !RunBackend(**session, *opened.backend, run, written);
        opened.backend.reset();  // its memory goes back before the next backend runs
        if (run.status == "failed") {
            anyFailed = true;
            std::fprintf(stderr, "backend %s failed: %s\n", run.name.c_str(), run.error.c_str());
        }
        std::printf("%s", report::RenderText(TimingSection(scene, run)).c_str());
        runs.push_back(std::move(run));
        if (i + 1 < backends.size()) anyFailed |= !writeResults(i + 1);
    }
    if (!writeResults(backends.size())) return kExitFailed;
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
    .run = Run,
});

}  // namespace
}  // namespace cb
