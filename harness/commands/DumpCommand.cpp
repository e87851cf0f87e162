// `cloudbench dump`: every step's canonical stage outputs as NumPy .npy files
// (docs/results.md#dumps), and with --reference the exact references.
#include <algorithm>
#include <cstdio>

#include "core/base/Npy.h"
#include "harness/accuracy/Accuracy.h"
#include "harness/accuracy/Evaluator.h"
#include "harness/report/Report.h"
#include "harness/run/Session.h"
#include "harness/run/Simulation.h"

namespace cb {
namespace {

constexpr const char* kHelpHead = R"(usage: cloudbench dump [SCENE] [options]

Runs SCENE on one backend and writes, for every step t, DIR/step_tttt/ with
  hum.npy act.npy cld.npy  uint8 0/1, the automaton state at step t
  region.npy               uint8, the region volume used for step t -> t+1
  q.npy                    float32, smoothed from cld at step t
  density.npy              float32 D, shape (1, ny, nx)
  tiles.npy bands.npy      uint8 tile and height-band occupancy of step t
  T.npy                    float32, the transmittance of step t
  shadow.npy               float32 ground shadow, shape (1, ny, nx)
  T_ref.npy shadow_ref.npy with --reference: the exact references (Embree) for
                           T and the ground shadow, same shapes
  frame-splat-<camera>.exr step t from each camera (likewise march, layers)
  frame-reference-<camera>.exr  with --reference and a renderer: the exact
                           reference render of the first camera
Volumes are C order with shape (nz, ny, nx). Only enabled stages are written.

Options:
  --backend NAME     the backend to dump (default: cpu); --backends is the same
  --reference        also write T_ref.npy, shadow_ref.npy and the reference
                     render (docs/accuracy.md)
  --vdb              also write each float volume (q, T, T_sky) as an OpenVDB fog
                     volume, <name>.vdb: voxel (i, j, k) at its centre in world
                     units, every value not +0 an active voxel
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/dump)
  --set PATH=VALUE   override a scene field (see cloudbench help run)
  --threads N        CPU backend threads (default: all)
  --cpu-isa ISA      CPU kernels' SIMD target: auto (default: the best here), scalar, sse4, avx2, avx512
  --vk-device DEV    Vulkan device: index or part of the name (cloudbench devices)
)";
constexpr const char* kHelpTail = R"(  --quiet            no progress lines
)";
const std::string kHelp = kHelpHead + GlOptionsHelp() + kHelpTail;

// dump --reference: T_ref.npy (with shade), shadow_ref.npy (with shadow) and, with a renderer, the exact reference
// render of the first camera (frame-reference-<camera>.exr: what `accuracy` measures the renderers against), of the
// simulation's current step, computed from its q.
Status WriteReferenceDump(const Simulation& sim, const std::string& dir, int threads) {
    const Scene& scene = sim.GetScene();
    const bool wantT = scene.stages.Has(Stage::Shade), wantG = scene.stages.Has(Stage::Shadow);
    const bool wantImage = std::ranges::any_of(kAllStages, [&](Stage s) {
        return scene.stages.Has(s) && Describe(s).renderer && !scene.render.cameras.empty();
    });
    if ((!wantT && !wantG && !wantImage) || !sim.Q()) return {};
    auto q = Download<float>(sim.GetBackend(), *sim.Q());
    if (!q) return std::unexpected(q.error());
    const Extent3 e = scene.grid.size;
    auto write = [&](const std::string& path, const uint64_t(&shape)[3], const std::vector<float>& values) {
        return Session::WriteAtomically(path, [&](const Session::TemporaryFile& temp) {
            return WriteNpy(temp.fd, path, NpyType::F32, shape, std::as_bytes(std::span(values)));
        });
    };
    if (wantT || wantG) {
        auto tracer = ref::OpticalDepthTracer::Create(e, *q, threads);
        if (!tracer) return std::unexpected(tracer.error());
        const ref::ReferenceParams p = MakeReferenceParams(scene, ref::RayStart::VoxelExit);
        if (wantT) CB_TRY(write(dir + "/T_ref.npy", {e.nz, e.ny, e.nx}, (*tracer)->Transmittance(p)));
        if (wantG) CB_TRY(write(dir + "/shadow_ref.npy", {1, e.ny, e.nx}, (*tracer)->GroundShadow(p)));
    }
    if (wantImage) {
        const LightingInputs in{e, sim.CurrentStep(), std::move(*q), {}};
        auto image = ComputeImageReference(scene, in, ref::MarchReferenceOptions{}.stepVoxels, threads);
        if (!image) return std::unexpected(image.error());
        const std::string stem = dir + "/frame-reference-" + scene.render.cameras[0].name;
        auto paths = WriteFrame(stem, image->result.image, image->width, image->height, /*png=*/false);
        if (!paths) return std::unexpected(paths.error());
    }
    return {};
}

// Writes every output of the simulation's current step into DIR/step_tttt/ (created, or opened, from the
// output folder's descriptor without following a link: MakeFolder).
// dump's own options (docs/cli.md).
struct DumpOptions : OwnOptions {
    bool reference = false;  // --reference: also the exact (Embree) reference of each step
    bool vdb = false;        // --vdb: also each float volume as an OpenVDB fog volume
};

Status WriteStep(const Simulation& s, const std::string& outDir, const CommonOptions& options, const DumpOptions& own) {
    char folder[32];
    std::snprintf(folder, sizeof folder, "/step_%04u", s.CurrentStep());
    const std::string dir = outDir + folder;
    CB_TRY(MakeFolder(dir));
    // Every resource the enabled stages write: arrays, and each renderer's image per camera as a frame.
    const Scene& scene = s.GetScene();
    for (Resource r : kAllResources) {
        if (!s.Get(r)) continue;
        if (!IsPerCamera(r)) {
            const std::string stem = dir + "/" + std::string(ResourceDumpStem(r));
            CB_TRY(Session::WriteNpy(stem + ".npy", s.GetBackend(), *s.Get(r)));
            // The float volumes of the grid (not the 2-D maps D and G): also as OpenVDB.
            const bool floatVolume = r == Resource::Q || r == Resource::T || r == Resource::TSky;
            if (own.vdb && floatVolume) {
                auto values = Download<float>(s.GetBackend(), *s.Get(r));
                if (!values) return std::unexpected(values.error());
                CB_TRY(WriteVdbVolume(stem + ".vdb", std::string(ResourceDumpStem(r)), *values, scene.grid.size,
                                      scene.grid.origin, scene.grid.voxelSize));
            }
            continue;
        }
        const Stage renderer = *ProducerOf(r, scene.stages);
        for (size_t n = 0; s.Get(r, n); ++n) {
            auto rgb = Download<float>(s.GetBackend(), *s.Get(r, n));
            if (!rgb) return std::unexpected(rgb.error());
            const std::string stem = dir + "/" + FrameFileStem(renderer, scene.render.cameras[n].name);
            auto paths = WriteFrame(stem, *rgb, scene.render.width, scene.render.height, /*png=*/false);
            if (!paths) return std::unexpected(paths.error());
        }
    }
    if (own.reference) CB_TRY(WriteReferenceDump(s, dir, options.cpuThreads));
    return {};
}

int Dump(const CommonOptions& options, const DumpOptions& own) {
    auto session = Session::Open(options, "dump");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    if (options.backends.size() > 1) {
        std::fprintf(stderr, "dump: --backend takes one backend, got %zu\n", options.backends.size());
        return kExitUsage;
    }
    if (!(*session)->MakeOutDir()) return kExitFailed;
    std::vector<OpenedBackend> opened = (*session)->OpenBackends((*session)->RequestedBackends({"cpu"}));
    Backend* backend = opened[0].backend.get();
    if (!backend) return kExitNoBackend;
    const std::string& name = opened[0].name;
    const std::string& outDir = (*session)->OutDir();
    auto sim = Simulation::Create(scene, *backend, /*everyStepOutputs=*/true);
    if (!sim) {
        std::fprintf(stderr, "%s\n", sim.error().message.c_str());
        return kExitFailed;
    }
    auto observe = [&](const Simulation& s) { return WriteStep(s, outDir, options, own); };
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
    const Extent3 g = scene.grid.size;
    std::printf("dumped %u steps of scene %s (%ux%ux%u, backend %s) to %s/step_0000 .. step_%04u\n", scene.steps,
                scene.name.c_str(), g.nx, g.ny, g.nz, name.c_str(), outDir.c_str(), scene.steps - 1);
    return kExitOk;
}

const CommandRegistration kRegistration({
    .name = "dump",
    .summary = "Write each step's canonical stage outputs as NumPy .npy files",
    .help = kHelp,
    .helpOrder = 1,
    .extraOptions = {FlagOption("--reference", &DumpOptions::reference), FlagOption("--vdb", &DumpOptions::vdb)},
    .makeOptions = MakeOwnOptions<DumpOptions>,
    .run = RunWith(Dump),
});

}  // namespace
}  // namespace cb
