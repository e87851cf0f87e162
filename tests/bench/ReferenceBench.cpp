// The exact reference's own speed (docs/accuracy.md): building the Embree scene
// and tracing T_ref (one ray per voxel) and G_ref (one per ground cell), in rays
// per second, on a scene's state at its last step. What exactness costs.
#include <benchmark/benchmark.h>

#include <map>

#include "harness/Accuracy.h"

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

}  // namespace
}  // namespace cb

BENCHMARK_MAIN();
