// cloudbench: cross-backend validation and benchmark harness for the cloud
// pipeline of SPEC.md. Command-line front end; docs/cli.md describes it.
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

#include "harness/Commands.h"

namespace {

constexpr const char* kMainHelp = R"(usage: cloudbench <command> [options]

Commands:
  run      Run a scene on one or more backends, time every stage, write results.json
  dump     Write each step's canonical stage outputs as NumPy .npy files
  conform  Check every backend's stages against the CPU on a scene
  devices  List the backends of this build and the Vulkan devices
  accuracy Measure every shade and shadow option against the exact (Embree) reference
  sweep    Vary scene fields over a cartesian product: time and error, Pareto front, plot
  help   Show help for a command: cloudbench help run

Exit codes: 0 success, 1 a stage failed or an output could not be written,
2 bad command line, 3 bad scene file or --set value, 4 no requested backend
available, 5 a conformance check failed.
)";

constexpr const char* kRunHelp = R"(usage: cloudbench run [SCENE] [options]

Runs SCENE (a name in scenes/ or a path to a .json file; default: thesis-medium)
on each backend, prints a per-stage timing table (median and spread over the
steps after warm-up), each camera's frame rate and the cloud cover, and writes
DIR/results.json, the last frame of each camera (DIR/frame-<camera>-<backend>
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
  --gl-context CTX   OpenGL context: osmesa (default, llvmpipe) or egl (GPU or surfaceless)
  --gl-ca-layout L   OpenGL automaton layout: packed (default; R32UI, 32 voxels a texel)
                     or rgba8 (the thesis's: one RGBA8 texel a voxel, a channel a bit)
  --quiet            no progress lines
)";

constexpr const char* kDumpHelp = R"(usage: cloudbench dump [SCENE] [options]

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
  frame.exr                step t from the first camera (frame-<camera>.exr: others)
Volumes are C order with shape (nz, ny, nx). Only enabled stages are written.

Options:
  --backend NAME     the backend to dump (default: cpu)
  --reference        also write T_ref.npy and shadow_ref.npy (docs/accuracy.md)
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/dump)
  --set PATH=VALUE   override a scene field (see cloudbench help run)
  --threads N        CPU backend threads (default: all)
  --vk-device DEV    Vulkan device: index or part of the name (cloudbench devices)
  --gl-context CTX   OpenGL context: osmesa (default) or egl
  --gl-ca-layout L   OpenGL automaton layout: packed (default) or rgba8
  --quiet            no progress lines
)";

constexpr const char* kConformHelp = R"(usage: cloudbench conform [SCENE] [options]

Runs SCENE on the CPU and, at every step, feeds each other backend's stages
the CPU's inputs of that step (stage-isolated conformance), comparing by
SPEC's rule for the stage: region |dR| <= 1 on all but 0.5 % of voxels;
ca, smooth, density bit-exact; shade |dT| <= 1e-5 (one storage quantum for
fp16/unorm8); shadow |dG| <= 1e-5. Prints stage x backend with the result,
the rule and the worst error with where it is, writes DIR/conform.json, and
exits 5 if any check fails. Stages a backend lacks are listed as skipped.

Options:
  --backend LIST     backends to check (default: all built; cpu is the reference)
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/conform)
  --set PATH=VALUE   override a scene field (see cloudbench help run)
  --vk-device DEV    Vulkan device: index or part of the name
  --gl-context CTX   OpenGL context: osmesa (default) or egl
  --gl-ca-layout L   OpenGL automaton layout: packed (default) or rgba8
)";

constexpr const char* kAccuracyHelp = R"(usage: cloudbench accuracy [SCENE] [options]

Simulates SCENE on the CPU to its last step, computes the exact references
T_ref (every voxel, from the point where the ray toward the sun leaves the
voxel) and G_ref (every ground cell) with Embree, and measures the shade and
shadow stages of every backend against them: the scene's settings, then each
option changed one at a time (shade: attenuation, filter, resolution, storage,
scattering; shadow: form). Prints per option and backend the median time with
quartiles and the max, mean and 99th-percentile |error| over all voxels and
over the voxels in cloud (q > 0) or ground cells under cloud (G_ref < 1), the
reference's own speed in rays per second, and writes DIR/accuracy.json and
DIR/accuracy.md.

Options:
  --backend LIST     backends to measure (default: all built); unavailable ones
                     are reported, and a stage a backend lacks is listed as unsupported
  --repeat N         timed calls per measurement, after one warm-up (default 5)
  --switches         also cross the principal axis's 45-degree switches: error on
                     each side (1e-6 rad, 1e-3 rad, 1 degree) and the jump in T
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/accuracy)
  --set PATH=VALUE   override a scene field (see cloudbench help run)
  --threads N        CPU backend and reference threads (default: all)
  --vk-device DEV    Vulkan device: index or part of the name
  --gl-context CTX   OpenGL context: osmesa (default) or egl
  --quiet            no progress lines
)";

constexpr const char* kSweepHelp = R"(usage: cloudbench sweep [SCENE] --vary PATH=V1,V2,... [--vary ...] [options]

Runs the cartesian product of the --vary values (dotted scene paths, as for
--set; a value may be JSON, e.g. --vary grid.size=[32,32,8],[64,64,16]). At
each point: the CPU simulates the scene to its last step, the Embree
reference is computed for that q and sun, and every backend's shade and
shadow stages are timed (median of --repeat calls, with quartiles) and
compared with it. Marks the Pareto front (no other point as fast and as
accurate) per stage and writes DIR/sweep.json, DIR/sweep.md and DIR/sweep.png
(error against time, one series per backend; needs python3 with matplotlib,
otherwise the plot is skipped with a message).

Options:
  --vary PATH=V1,... a field and its values; repeat for more fields
  --backend LIST     backends to measure (default: all built)
  --metric M         error for the Pareto front: max (default), mean or p99
  --repeat N         timed calls per point, after one warm-up (default 5)
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/sweep)
  --set PATH=VALUE   override a scene field for every point
  --threads N        CPU backend and reference threads (default: all)
  --vk-device DEV    Vulkan device: index or part of the name
  --gl-context CTX   OpenGL context: osmesa (default) or egl
  --quiet            no progress lines
)";

int Usage(const char* message, const char* help) {
    std::fprintf(stderr, "cloudbench: %s\n\n%s", message, help);
    return cb::kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fputs(kMainHelp, stderr);
        return cb::kExitUsage;
    }
    const std::string_view command = argv[1];
    if (command == "--help" || command == "-h") {
        std::fputs(kMainHelp, stdout);
        return cb::kExitOk;
    }
    if (command == "help") {
        std::string_view topic = argc > 2 ? argv[2] : "";
        std::fputs(topic == "run"        ? kRunHelp
                   : topic == "dump"     ? kDumpHelp
                   : topic == "conform"  ? kConformHelp
                   : topic == "accuracy" ? kAccuracyHelp
                   : topic == "sweep"    ? kSweepHelp
                                         : kMainHelp,
                   stdout);
        return cb::kExitOk;
    }
    if (command == "devices") return cb::DevicesCommand();
    const char* help = command == "run"       ? kRunHelp
                       : command == "dump"    ? kDumpHelp
                       : command == "conform" ? kConformHelp
                       : command == "accuracy" ? kAccuracyHelp
                       : command == "sweep"   ? kSweepHelp
                                              : nullptr;
    if (!help) return Usage(("unknown command '" + std::string(command) + "'").c_str(), kMainHelp);

    cb::CommonOptions options;
    // A dump has no statistics, so no warm-up to keep below --steps.
    if (command != "run") options.overrides.push_back({"warmup_steps", "0"});
    const bool measures = command == "accuracy" || command == "sweep";
    bool sceneGiven = false;
    for (int n = 2; n < argc; ++n) {
        const std::string_view arg = argv[n];
        auto value = [&]() -> const char* { return n + 1 < argc ? argv[++n] : nullptr; };
        if (arg == "--help" || arg == "-h") {
            std::fputs(help, stdout);
            return cb::kExitOk;
        } else if (arg == "--backend" || arg == "--backends") {
            const char* v = value();
            if (!v) return Usage("--backend needs a list, e.g. --backend cpu", help);
            std::string list = v;
            for (size_t start = 0; start <= list.size();) {
                size_t comma = list.find(',', start);
                if (comma == std::string::npos) comma = list.size();
                if (comma > start) options.backends.push_back(list.substr(start, comma - start));
                start = comma + 1;
            }
        } else if (arg == "--steps") {
            const char* v = value();
            if (!v) return Usage("--steps needs a number", help);
            options.overrides.push_back({"steps", v});
        } else if (arg == "--out") {
            const char* v = value();
            if (!v) return Usage("--out needs a folder", help);
            options.outDir = v;
        } else if (arg == "--set") {
            const char* v = value();
            const char* eq = v ? std::strchr(v, '=') : nullptr;
            if (!eq || eq == v) return Usage("--set needs PATH=VALUE, e.g. --set ca.seed=42", help);
            options.overrides.push_back({std::string(v, eq), std::string(eq + 1)});
        } else if (arg == "--threads") {
            const char* v = value();
            char* end = nullptr;
            long threads = v ? std::strtol(v, &end, 10) : -1;
            if (!v || *end != '\0' || threads < 1 || threads > 1024) return Usage("--threads needs a number from 1", help);
            options.cpuThreads = int(threads);
        } else if (arg == "--gl-context") {
            const char* v = value();
            if (!v || (std::string_view(v) != "osmesa" && std::string_view(v) != "egl"))
                return Usage("--gl-context needs osmesa or egl", help);
            options.glContext = v;
        } else if (arg == "--gl-ca-layout") {
            const char* v = value();
            if (!v || (std::string_view(v) != "packed" && std::string_view(v) != "rgba8"))
                return Usage("--gl-ca-layout needs packed or rgba8", help);
            options.glCaLayout = v;
        } else if (arg == "--vk-device") {
            const char* v = value();
            if (!v) return Usage("--vk-device needs an index or a name", help);
            options.vkDevice = v;
        } else if (arg == "--quiet") {
            options.quiet = true;
        } else if (arg == "--reference" && command == "dump") {
            options.reference = true;
        } else if (arg == "--switches" && command == "accuracy") {
            options.switches = true;
        } else if (arg == "--vary" && command == "sweep") {
            const char* v = value();
            if (!v) return Usage("--vary needs PATH=V1,V2,..., e.g. --vary shade.resolution=1,2,4", help);
            options.vary.push_back(v);
        } else if (arg == "--metric" && command == "sweep") {
            const char* v = value();
            if (!v) return Usage("--metric needs max, mean or p99", help);
            options.metric = v;
        } else if (arg == "--repeat" && measures) {
            const char* v = value();
            char* end = nullptr;
            long repeats = v ? std::strtol(v, &end, 10) : -1;
            if (!v || *end != '\0' || repeats < 1 || repeats > 10000) return Usage("--repeat needs a number from 1", help);
            options.repeats = int(repeats);
        } else if (arg.starts_with("-")) {
            return Usage(("unknown option '" + std::string(arg) + "'").c_str(), help);
        } else if (!sceneGiven) {
            options.scene = std::string(arg);
            sceneGiven = true;
        } else {
            return Usage(("unexpected argument '" + std::string(arg) + "' (one scene at a time)").c_str(), help);
        }
    }
    if (command == "conform") return cb::ConformCommand(options);
    if (command == "accuracy") return cb::AccuracyCommand(options);
    if (command == "sweep") return cb::SweepCommand(options);
    return command == "run" ? cb::RunCommand(options) : cb::DumpCommand(options);
}
