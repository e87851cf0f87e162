// The exact reference's own speed (docs/accuracy.md): building the Embree scene
// and tracing T_ref (one ray per voxel) and G_ref (one per ground cell), in rays
// per second, on a scene's state at its last step. What exactness costs.
#include <benchmark/benchmark.h>

#include <map>

#include "core/math/Random.h"
#include "core/plan/SceneLoad.h"
#include "harness/accuracy/Accuracy.h"
#include "reference/Trilinear.h"

namespace cb {
namespace {

const LightingInputs& Inputs(const std::string& name, Scene* sceneOut = nullptr) {
    static std::map<std::string, std::pair<Scene, LightingInputs>> cache;
    auto it = cache.find(name);
    if (it == cache.end()) {
        auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + name + ".json", {{"warmup_steps", "0"}});
        if (!scene) {
            std::fprintf(stderr, "%s\n", scene.error().message.c_str());
            std::exit(1);
        }
        auto in = SimulateLightingInputs(*scene, 0);
        if (!in) {
            std::fprintf(stderr, "%s\n", in.error().message.c_str());
            std::exit(1);
        }
        it = cache.emplace(name, std::make_pair(*scene, std::move(*in))).first;
    }
    if (sceneOut) *sceneOut = it->second.first;
    return it->second.second;
}

std::unique_ptr<ref::OpticalDepthTracer> Tracer(const LightingInputs& in, int threads) {
    auto tracer = ref::OpticalDepthTracer::Create(in.grid, in.q, threads);
    if (!tracer) {
        std::fprintf(stderr, "%s\n", tracer.error().message.c_str());
        std::exit(1);
    }
    return std::move(*tracer);
}

void Build(benchmark::State& state, const std::string& scene) {
    const LightingInputs& in = Inputs(scene);
    size_t boxes = 0;
    for (auto _ : state) boxes = Tracer(in, int(state.range(0)))->Primitives();
    state.counters["boxes"] = double(boxes);
}

void Transmittance(benchmark::State& state, const std::string& name) {
    Scene scene;
    const LightingInputs& in = Inputs(name, &scene);
    auto tracer = Tracer(in, int(state.range(0)));
    const ref::ReferenceParams p = MakeReferenceParams(scene, ref::RayStart::VoxelExit);
    for (auto _ : state) benchmark::DoNotOptimize(tracer->Transmittance(p));
    state.counters["rays/s"] =
        benchmark::Counter(double(in.grid.Count()), benchmark::Counter::kIsIterationInvariantRate);
}

void GroundShadow(benchmark::State& state, const std::string& name) {
    Scene scene;
    const LightingInputs& in = Inputs(name, &scene);
    auto tracer = Tracer(in, int(state.range(0)));
    const ref::ReferenceParams p = MakeReferenceParams(scene, ref::RayStart::VoxelExit);
    for (auto _ : state) benchmark::DoNotOptimize(tracer->GroundShadow(p));
    state.counters["rays/s"] =
        benchmark::Counter(double(in.grid.nx) * in.grid.ny, benchmark::Counter::kIsIterationInvariantRate);
}

// Wall time: the tracer runs its own TBB threads. `id` names the benchmark,
// `scene` is the file name in scenes/.
#define CB_REFERENCE_BENCH(id, scene)                                                                            \
    BENCHMARK_CAPTURE(Build, id, scene)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();                   \
    BENCHMARK_CAPTURE(Transmittance, id, scene)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();   \
    BENCHMARK_CAPTURE(GroundShadow, id, scene)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

CB_REFERENCE_BENCH(ci_small, "ci-small")
CB_REFERENCE_BENCH(thesis_low, "thesis-low")
CB_REFERENCE_BENCH(thesis_medium, "thesis-medium")
CB_REFERENCE_BENCH(thesis_high, "thesis-high")

// The trilinear tracer (reference/Trilinear.h) beside the piecewise-constant one
// on one cumulus-like field: 128^3, 40 Gaussian towers (seeded), thresholded
// like Olajos's forming, q in [0, 1]. Sun 25 degrees high at azimuth 60, rays
// from every voxel centre; the point light sits inside the cloud layer.
struct BlobField {
    Extent3 grid{128, 128, 128};
    std::vector<float> q;
};

const BlobField& Blob128() {
    static const BlobField field = [] {
        BlobField f;
        const Extent3 e = f.grid;
        Pcg32 rng(1307);
        struct Bump {
            double x, y, z, r, h;
        };
        std::vector<Bump> bumps;
        for (int b = 0; b < 40; ++b)
            bumps.push_back({rng.Uniform(16, 112), rng.Uniform(16, 112), rng.Uniform(24, 56), rng.Uniform(6, 14),
                             rng.Uniform(1.2, 2.2)});
        std::vector<float> v(e.Count(), 0.0f);
        for (uint32_t k = 0; k < e.nz; ++k)
            for (uint32_t j = 0; j < e.ny; ++j)
                for (uint32_t i = 0; i < e.nx; ++i) {
                    double sum = 0;
                    for (const Bump& b : bumps) {
                        const double dx = i + 0.5 - b.x, dy = j + 0.5 - b.y, dz = (k + 0.5 - b.z) / b.h;
                        sum += std::exp(-(dx * dx + dy * dy + dz * dz) / (2 * b.r * b.r));
                    }
                    v[VoxelIndex(e, i, j, k)] = float(std::clamp((sum - 0.35) / 0.65, 0.0, 1.0));
                }
        f.q = std::move(v);
        return f;
    }();
    return field;
}

std::vector<ref::Point3d> VoxelCentres(const Extent3& e) {
    std::vector<ref::Point3d> points;
    points.reserve(e.Count());
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) points.push_back({i + 0.5, j + 0.5, k + 0.5});
    return points;
}

ref::Point3d BlobSun() {
    constexpr double kDeg = 3.14159265358979323846 / 180.0;
    const Vec3 s = SunDirection(25 * kDeg, 60 * kDeg);
    return {s[0], s[1], s[2]};
}

std::unique_ptr<ref::TrilinearDepthTracer> TriTracer(const BlobField& f, int threads) {
    auto tracer = ref::TrilinearDepthTracer::Create(f.grid, f.q, threads);
    if (!tracer) {
        std::fprintf(stderr, "%s\n", tracer.error().message.c_str());
        std::exit(1);
    }
    return std::move(*tracer);
}

void TriBuild(benchmark::State& state) {
    const BlobField& f = Blob128();
    size_t boxes = 0;
    for (auto _ : state) boxes = TriTracer(f, int(state.range(0)))->Primitives();
    state.counters["boxes"] = double(boxes);
    size_t occupied = 0;
    for (float v : f.q) occupied += v > 0;
    state.counters["occupied"] = double(occupied) / double(f.q.size());
}

void TriSun(benchmark::State& state) {
    const BlobField& f = Blob128();
    auto tracer = TriTracer(f, int(state.range(0)));
    tracer->UsePackets(state.range(1) != 0);
    const std::vector<ref::Point3d> points = VoxelCentres(f.grid);
    for (auto _ : state) benchmark::DoNotOptimize(tracer->TransmittanceToward(points, BlobSun(), 1.0));
    state.counters["rays/s"] = benchmark::Counter(double(points.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void TriPointLight(benchmark::State& state) {
    const BlobField& f = Blob128();
    auto tracer = TriTracer(f, int(state.range(0)));
    tracer->UsePackets(state.range(1) != 0);
    const std::vector<ref::Point3d> points = VoxelCentres(f.grid);
    for (auto _ : state) benchmark::DoNotOptimize(tracer->TransmittanceToPoint(points, {64.0, 64.0, 40.0}, 1.0));
    state.counters["rays/s"] = benchmark::Counter(double(points.size()), benchmark::Counter::kIsIterationInvariantRate);
}

// The piecewise-constant tracer on the same field and sun.
void ConstantSun(benchmark::State& state) {
    const BlobField& f = Blob128();
    auto tracer = ref::OpticalDepthTracer::Create(f.grid, f.q, int(state.range(0)));
    if (!tracer) std::exit(1);
    ref::ReferenceParams p;
    const ref::Point3d s = BlobSun();
    p.sun = {float(s[0]), float(s[1]), float(s[2])};
    p.start = ref::RayStart::VoxelCentre;
    for (auto _ : state) benchmark::DoNotOptimize((*tracer)->Transmittance(p));
    state.counters["rays/s"] = benchmark::Counter(double(f.q.size()), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["boxes"] = double((*tracer)->Primitives());
}

// Wall time, and the CPU time of the whole process (every thread).
BENCHMARK(TriBuild)
    ->Name("Trilinear/build/blob128")
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
// Arguments: threads, packets (1: 16-ray packets, 0: single rays).
BENCHMARK(TriSun)
    ->Name("Trilinear/sun/blob128")
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(TriPointLight)
    ->Name("Trilinear/point/blob128")
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK(ConstantSun)
    ->Name("Constant/sun/blob128")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();

}  // namespace
}  // namespace cb

BENCHMARK_MAIN();
