#include "harness/Commands.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/Npy.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/VulkanContext.h"
#endif
#include "harness/Conform.h"
#include "harness/Report.h"
#include "harness/Simulation.h"

namespace cb {
namespace fs = std::filesystem;

std::string ResolveScenePath(const std::string& nameOrPath) {
    const std::string& name = nameOrPath.empty() ? std::string(kDefaultScene) : nameOrPath;
    if (name.find('/') != std::string::npos || name.ends_with(".json")) return name;
    const char* env = std::getenv("CLOUDBENCH_SCENES");
    fs::path dir = env ? fs::path(env) : fs::path(CLOUDBENCH_SCENES_DIR);
    return (dir / (name + ".json")).string();
}

Status MakeOutDir(const std::string& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) return MakeError(dir + ": cannot create the output folder: " + ec.message());
    return {};
}

namespace {

Result<Scene> Load(const CommonOptions& options) {
    return LoadScene(ResolveScenePath(options.scene), options.overrides);
}

// Reads a buffer back in canonical form; adds the time it took to `timesMs` when given.
template <typename T>
Result<std::vector<T>> DownloadAll(Backend& backend, const Buffer& buffer, std::vector<double>* timesMs = nullptr) {
    std::vector<T> data(buffer.CanonicalBytes() / sizeof(T));
    const auto start = std::chrono::steady_clock::now();
    CB_TRY(backend.Download(buffer, std::as_writable_bytes(std::span(data))));
    if (timesMs)
        timesMs->push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    return data;
}

// Progress on stderr: a self-rewriting line on a terminal, a line per 10 % otherwise.
class Progress {
  public:
    Progress(std::string label, uint32_t total, bool quiet)
        : mLabel(std::move(label)), mTotal(total), mQuiet(quiet), mTty(isatty(STDERR_FILENO)) {}
    void Update(uint32_t done) {
        if (mQuiet || mTotal < 20) return;
        if (mTty) {
            std::fprintf(stderr, "\r%s: step %u/%u", mLabel.c_str(), done, mTotal);
            if (done == mTotal) std::fprintf(stderr, "\n");
        } else if (done * 10 / mTotal != (done - 1) * 10 / mTotal) {
            std::fprintf(stderr, "%s: step %u/%u\n", mLabel.c_str(), done, mTotal);
        }
    }

  private:
    std::string mLabel;
    uint32_t mTotal;
    bool mQuiet, mTty;
};

}  // namespace

int RunCommand(const CommonOptions& options) {
    Result<Scene> loaded = Load(options);
    if (!loaded) {
        std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
        return kExitBadScene;
    }
    const Scene& scene = *loaded;
    const std::string outDir = options.outDir.empty() ? "out/" + scene.name : options.outDir;
    if (Status s = MakeOutDir(outDir); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    std::vector<std::string> names = options.backends.empty() ? BuiltBackends() : options.backends;
    std::printf("scene %s: %ux%ux%u voxels, %u steps (%u warm-up)\n", scene.name.c_str(), scene.grid.size.nx,
                scene.grid.size.ny, scene.grid.size.nz, scene.steps, scene.warmupSteps);

    std::vector<BackendRun> runs;
    std::vector<std::string> written;
    bool anyAvailable = false, anyFailed = false;
    for (const std::string& name : names) {
        BackendRun run;
        run.name = name;
        auto backend = CreateBackend(name, options.Backend());
        if (!backend) {
            run.status = "unavailable";
            run.error = backend.error().message;
            std::fprintf(stderr, "backend %s unavailable: %s\n", name.c_str(), run.error.c_str());
            runs.push_back(std::move(run));
            continue;
        }
        run.device = (*backend)->Device();
        // A backend that lacks one of the scene's stages is skipped, not failed.
        std::string missing;
        for (Stage stage : kAllStages)
            if (scene.stages.Has(stage) && !(*backend)->Supports(stage))
                missing += (missing.empty() ? "" : ", ") + std::string(StageName(stage));
        if (!missing.empty()) {
            run.status = "unsupported";
            run.error = name + " does not implement " + missing + " yet";
            std::fprintf(stderr, "backend %s skipped: %s\n", name.c_str(), run.error.c_str());
            runs.push_back(std::move(run));
            continue;
        }
        anyAvailable = true;
        auto sim = Simulation::Create(scene, **backend);
        Progress progress(name, scene.steps, options.quiet);
        if (!sim) {
            run.status = "failed";
            run.error = sim.error().message;
        } else {
            for (uint32_t t = 0; t < scene.steps; ++t) {
                StepRecord record;
                Status status = (*sim)->Step(record);
                if (!status) {
                    run.status = "failed";
                    run.error = "step " + std::to_string(t) + ": " + status.error().message;
                    break;
                }
                run.steps.push_back(record);
                progress.Update(t + 1);
            }
            // The last frame of each camera.
            if (auto rendered = (*sim)->LastRenderedStep()) {
                for (size_t n = 0; n < scene.render.cameras.size(); ++n) {
                    auto rgb = DownloadAll<float>(**backend, *(*sim)->Image(n), &run.downloadMs);
                    if (!rgb) {
                        std::fprintf(stderr, "%s\n", rgb.error().message.c_str());
                        anyFailed = true;
                        continue;
                    }
                    auto paths = WriteFrame(outDir + "/frame-" + scene.render.cameras[n].name + "-" + name, *rgb,
                                            scene.render.width, scene.render.height);
                    if (paths) written.insert(written.end(), paths->begin(), paths->end());
                    else std::fprintf(stderr, "%s\n", paths.error().message.c_str()), anyFailed = true;
                }
            }
            // The density map of the last step, seen from above.
            if (const Buffer* columnSum = (*sim)->ColumnSum(); columnSum && !run.steps.empty()) {
                auto d = DownloadAll<float>(**backend, *columnSum, &run.downloadMs);
                std::string png = outDir + "/topview-" + name + ".png";
                Status s = d ? WriteTopView(png, *d, scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz)
                             : Status(std::unexpected(d.error()));
                if (s) written.push_back(png);
                else std::fprintf(stderr, "%s\n", s.error().message.c_str()), anyFailed = true;
            }
        }
        if (run.status == "failed") {
            anyFailed = true;
            std::fprintf(stderr, "backend %s failed: %s\n", name.c_str(), run.error.c_str());
        }
        std::printf("%s", TimingTable(scene, run).c_str());
        runs.push_back(std::move(run));
    }

    const std::string resultsPath = outDir + "/results.json";
    std::ofstream results(resultsPath);
    results << ResultsJson(scene, runs).dump(1) << "\n";
    if (!results) {
        std::fprintf(stderr, "%s: cannot write the results\n", resultsPath.c_str());
        return kExitFailed;
    }
    written.insert(written.begin(), resultsPath);
    std::printf("results:");
    for (const std::string& path : written) std::printf(" %s", path.c_str());
    std::printf("\n");
    if (!anyAvailable) return kExitNoBackend;
    return anyFailed ? kExitFailed : kExitOk;
}

int DumpCommand(const CommonOptions& options) {
    Result<Scene> loaded = Load(options);
    if (!loaded) {
        std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
        return kExitBadScene;
    }
    const Scene& scene = *loaded;
    if (options.backends.size() > 1) {
        std::fprintf(stderr, "dump: --backend takes one backend, got %zu\n", options.backends.size());
        return kExitUsage;
    }
    const std::string name = options.backends.empty() ? "cpu" : options.backends[0];
    const std::string outDir = options.outDir.empty() ? "out/" + scene.name + "/dump" : options.outDir;
    auto backend = CreateBackend(name, options.Backend());
    if (!backend) {
        std::fprintf(stderr, "backend %s unavailable: %s\n", name.c_str(), backend.error().message.c_str());
        return kExitNoBackend;
    }
    auto sim = Simulation::Create(scene, **backend, /*everyStepOutputs=*/true);
    if (!sim) {
        std::fprintf(stderr, "%s\n", sim.error().message.c_str());
        return kExitFailed;
    }
    const Extent3 g = scene.grid.size;

    // Writes one buffer of the current step as <dir>/<file>.npy, shaped (nz, ny, nx).
    auto write = [&](const std::string& dir, const char* file, const Buffer* buffer) -> Status {
        if (!buffer) return {};
        std::vector<std::byte> data(buffer->CanonicalBytes());
        CB_TRY((*backend)->Download(*buffer, data));
        const Extent3 e = buffer->Extent();
        const uint64_t shape[3] = {e.nz, e.ny, e.nx};
        NpyType type = buffer->Format() == BufferFormat::F32 ? NpyType::F32 : NpyType::U8;
        return WriteNpy(dir + "/" + file, type, shape, data);
    };
    auto observe = [&](const Simulation& s) -> Status {
        char folder[32];
        std::snprintf(folder, sizeof folder, "/step_%04u", s.CurrentStep());
        const std::string dir = outDir + folder;
        CB_TRY(MakeOutDir(dir));
        CB_TRY(write(dir, "hum.npy", s.Hum()));
        CB_TRY(write(dir, "act.npy", s.Act()));
        CB_TRY(write(dir, "cld.npy", s.Cld()));
        CB_TRY(write(dir, "region.npy", s.Region()));
        CB_TRY(write(dir, "q.npy", s.Q()));
        CB_TRY(write(dir, "density.npy", s.ColumnSum()));
        CB_TRY(write(dir, "tiles.npy", s.Tiles()));
        CB_TRY(write(dir, "bands.npy", s.Bands()));
        CB_TRY(write(dir, "T.npy", s.T()));
        CB_TRY(write(dir, "shadow.npy", s.Shadow()));
        if (options.reference) CB_TRY(WriteReferenceDump(s, dir, options.cpuThreads));
        // frame.exr is the first camera; the others are frame-<camera>.exr.
        for (size_t n = 0; s.Image(n); ++n) {
            auto rgb = DownloadAll<float>(s.GetBackend(), *s.Image(n));
            if (!rgb) return std::unexpected(rgb.error());
            const std::string stem = dir + (n == 0 ? "/frame" : "/frame-" + scene.render.cameras[n].name);
            auto paths = WriteFrame(stem, *rgb, scene.render.width, scene.render.height, /*png=*/false);
            if (!paths) return std::unexpected(paths.error());
        }
        return {};
    };
    Progress progress("dump " + name, scene.steps, options.quiet);
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord record;
        if (Status s = (*sim)->Step(record, observe); !s) {
            std::fprintf(stderr, "dump stopped at step %u: %s (steps before it are in %s)\n", t,
                         s.error().message.c_str(), outDir.c_str());
            return kExitFailed;
        }
        progress.Update(t + 1);
    }
    std::printf("dumped %u steps of scene %s (%ux%ux%u, backend %s) to %s/step_0000 .. step_%04u\n", scene.steps,
                scene.name.c_str(), g.nx, g.ny, g.nz, name.c_str(), outDir.c_str(), scene.steps - 1);
    return kExitOk;
}

int ConformCommand(const CommonOptions& options) {
    Result<Scene> loaded = Load(options);
    if (!loaded) {
        std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
        return kExitBadScene;
    }
    const Scene& scene = *loaded;
    const std::string outDir = options.outDir.empty() ? "out/" + scene.name + "/conform" : options.outDir;
    if (Status s = MakeOutDir(outDir); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    const std::vector<std::string> names = options.backends.empty() ? BuiltBackends() : options.backends;
    std::printf("conformance of scene %s (%ux%ux%u, %u steps) against the cpu backend\n", scene.name.c_str(),
                scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz, scene.steps);
    auto rows = RunConformance(scene, names, options.Backend());
    if (!rows) {
        std::fprintf(stderr, "conform: %s\n", rows.error().message.c_str());
        return kExitFailed;
    }
    std::printf("%s", ConformTable(*rows).c_str());
    const std::string path = outDir + "/conform.json";
    std::ofstream json(path);
    json << ConformJson(scene, *rows).dump(1) << "\n";
    std::printf("results: %s\n", path.c_str());
    bool failed = false, compared = false;
    for (const ConformRow& r : *rows) {
        failed |= r.status == "fail";
        compared |= r.status != "skipped";
    }
    if (failed) return kExitNonConformant;
    return compared ? kExitOk : kExitNoBackend;
}

int DevicesCommand() {
    std::printf("backends in this build:");
    for (const std::string& name : BuiltBackends()) std::printf(" %s", name.c_str());
    std::printf("\n");
#if CLOUDBENCH_HAVE_VK
    auto devices = vk::ListDevices();
    if (!devices) {
        std::printf("vk: %s\n", devices.error().message.c_str());
        return kExitNoBackend;
    }
    std::printf("Vulkan devices (--vk-device INDEX or a part of the name):\n");
    for (const vk::DeviceInfo& d : *devices)
        std::printf("  %u  %s (%s, Vulkan %u.%u)\n", d.index, d.name.c_str(), d.type.c_str(), VK_API_VERSION_MAJOR(d.apiVersion),
                    VK_API_VERSION_MINOR(d.apiVersion));
#else
    std::printf("vk: not built in this build\n");
#endif
    return kExitOk;
}

}  // namespace cb
