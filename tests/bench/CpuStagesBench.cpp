// Google Benchmark programs for the CPU stages on the thesis-sized scenes, and
// the machine figures (memory bandwidth, hash rate) their floors are worked
// out from (docs/performance.md). Each stage runs on a state taken after the
// scene's warm-up, so the numbers are those of a running simulation.
#include <benchmark/benchmark.h>

#include <cstring>
#include <map>
#include <numbers>
#include <numeric>

#include "core/math/Camera.h"
#include "core/math/Random.h"
#include "core/math/Shading.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/pipeline/ShadePlan.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "core/scene/SceneNames.h"
#include "core/stages/render_splat/RenderSplat.h"
#include "core/stages/shade/Shade.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/ShadeSchedule.h"

namespace cb {
namespace {

// A scene's state after warm-up, held in one backend's buffers.
struct WarmState {
    Scene scene;
    std::unique_ptr<cpu::BackendCpu> backend;
    std::unique_ptr<Buffer> hum[2], act[2], cld[2], region, q, D, tiles, bands, T, image;
    std::vector<RasterEllipsoid> raster;
    CaStepParams params;
    double cover = 0;
};

std::unique_ptr<Buffer> Make(Backend& b, BufferFormat f, Extent3 e) { return std::move(*b.CreateBuffer(f, e)); }

ShadeParams MakeShadeParams(const Scene& sc, int resolution) {
    ShadeParams p = cb::MakeShadeParams(sc);
    p.resolution = resolution;
    return p;
}

WarmState& Warm(const std::string& name, int threads) {
    static std::map<std::pair<std::string, int>, std::unique_ptr<WarmState>> cache;
    auto& slot = cache[{name, threads}];
    if (slot) return *slot;
    slot = std::make_unique<WarmState>();
    WarmState& w = *slot;
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + name + ".json");
    if (!scene) {
        std::fprintf(stderr, "%s\n", scene.error().message.c_str());
        std::exit(1);
    }
    w.scene = *scene;
    const Extent3 e = w.scene.grid.size;
    w.backend = std::make_unique<cpu::BackendCpu>(threads);
    Backend& b = *w.backend;
    for (int s = 0; s < 2; ++s) {
        w.hum[s] = Make(b, BufferFormat::Bits, e);
        w.act[s] = Make(b, BufferFormat::Bits, e);
        w.cld[s] = Make(b, BufferFormat::Bits, e);
    }
    w.region = Make(b, BufferFormat::U8, e);
    w.q = Make(b, BufferFormat::F32, e);
    const uint32_t T = w.scene.density.tile, B = w.scene.density.band;
    w.D = Make(b, BufferFormat::F32, {e.nx, e.ny, 1});
    w.tiles = Make(b, BufferFormat::U8, {CeilDiv(e.nx, T), CeilDiv(e.ny, T), 1});
    w.bands = Make(b, BufferFormat::U8, {CeilDiv(e.nx, T), CeilDiv(e.ny, T), CeilDiv(e.nz, B)});
    const CaSettings& ca = w.scene.ca;
    (void)b.CaInitialize({ca.seed, QuantizeProbability(ca.hum0), QuantizeProbability(ca.act0)},
                         {w.hum[0].get(), w.act[0].get(), w.cld[0].get()});
    w.params = {ca.seed, 0, QuantizeProbability(ca.pExt), QuantizeProbability(ca.pHum), QuantizeProbability(ca.pAct), {}, {}, {}};
    EllipsoidList list(w.scene.ellipsoids, e);
    int cur = 0;
    for (uint32_t t = 0; t < w.scene.warmupSteps; ++t) {
        w.raster = list.Raster();
        (void)b.Region(w.raster, *w.region);
        w.params.step = t;
        (void)b.CaStep(w.params, {w.hum[cur].get(), w.act[cur].get(), w.cld[cur].get()}, *w.region,
                       {w.hum[1 - cur].get(), w.act[1 - cur].get(), w.cld[1 - cur].get()});
        cur = 1 - cur;
        list.Update();
    }
    if (cur == 1) {
        std::swap(w.hum[0], w.hum[1]);
        std::swap(w.act[0], w.act[1]);
        std::swap(w.cld[0], w.cld[1]);
    }
    w.raster = list.Raster();
    (void)b.Region(w.raster, *w.region);
    (void)b.Smooth(w.scene.smooth.radius, *w.cld[0], *w.q);
    DensityOutputs out{w.D.get(), w.tiles.get(), w.bands.get(), 0};
    (void)b.Density({T, B, {}}, *w.q, w.cld[0].get(), out);
    w.cover = double(out.coveredColumns) / (double(e.nx) * e.ny);
    w.T = Make(b, BufferFormat::F32, e);
    (void)b.Shade(MakeShadeParams(w.scene, w.scene.shade.resolution), *w.q, *w.T);
    w.image = Make(b, BufferFormat::F32, {3, w.scene.render.width, w.scene.render.height});
    return w;
}

void Label(benchmark::State& state, const WarmState& w) {
    state.counters["voxels"] = double(w.scene.grid.size.Count());
    state.counters["cover"] = w.cover;
    state.counters["threads"] = w.backend->Threads();
}

void BM_Region(benchmark::State& state, const std::string& scene) {
    WarmState& w = Warm(scene, int(state.range(0)));
    for (auto _ : state) (void)w.backend->Region(w.raster, *w.region);
    Label(state, w);
    state.counters["ellipsoids"] = double(w.raster.size());
}

void BM_CaStep(benchmark::State& state, const std::string& scene) {
    WarmState& w = Warm(scene, int(state.range(0)));
    // Always step from the same warm state (index 0) into index 1, so every
    // iteration does the same work.
    for (auto _ : state)
        (void)w.backend->CaStep(w.params, {w.hum[0].get(), w.act[0].get(), w.cld[0].get()}, *w.region,
                                {w.hum[1].get(), w.act[1].get(), w.cld[1].get()});
    Label(state, w);
}

void BM_Smooth(benchmark::State& state, const std::string& scene) {
    WarmState& w = Warm(scene, int(state.range(0)));
    const int radius = int(state.range(1));
    for (auto _ : state) (void)w.backend->Smooth(radius, *w.cld[0], *w.q);
    Label(state, w);
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(w.scene.grid.size.Count()) * 4);
}

void BM_Density(benchmark::State& state, const std::string& scene) {
    WarmState& w = Warm(scene, int(state.range(0)));
    DensityOutputs out{w.D.get(), w.tiles.get(), w.bands.get(), 0};
    const DensityParams params{w.scene.density.tile, w.scene.density.band, {}};
    for (auto _ : state) (void)w.backend->Density(params, *w.q, w.cld[0].get(), out);
    Label(state, w);
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(w.scene.grid.size.Count()) * 4);
}

// Shading at resolution range(1), with the scene's sun (25 degrees: slices along y).
void BM_Shade(benchmark::State& state, const std::string& scene) {
    WarmState& w = Warm(scene, int(state.range(0)));
    const ShadeParams p = MakeShadeParams(w.scene, int(state.range(1)));
    for (auto _ : state) (void)w.backend->Shade(p, *w.q, *w.T);
    Label(state, w);
}

// Shading at f = 1 on range(0) threads with the sun at elevation range(1)
// degrees and azimuth range(2): at azimuth 60, 10 and 25 sweep along y, 60 and
// 90 along z; at azimuth 0, 25 sweeps along x (rows along y, gathered) and 45
// is the x/z tie (slices along z, whole-cell taps: u0 = 1, fu = 0). Counters:
// the schedule's bands, slices per tile and parallelism (work / span, the
// speed-up its tile graph allows on that many cores; docs/performance.md).
void BM_ShadeSun(benchmark::State& state, const std::string& scene) {
    WarmState& w = Warm(scene, int(state.range(0)));
    ShadeParams p = MakeShadeParams(w.scene, 1);
    p.sun = SunDirection(double(state.range(1)) * std::numbers::pi / 180.0,
                         double(state.range(2)) * std::numbers::pi / 180.0);
    for (auto _ : state) (void)w.backend->Shade(p, *w.q, *w.T);
    Label(state, w);
    const ShadePlan plan = MakeShadePlan(p, w.scene.grid.size);
    const cpu::ShadeSchedule s = cpu::MakeShadeSchedule(plan, int(state.range(0)), 0, plan.nw);
    state.counters["bands"] = double(s.bands);
    state.counters["chunks"] = double(s.chunks);
    state.counters["tile_slices"] = double(s.blockSlices);
    state.counters["parallelism"] = s.work / s.span;
}

// Splat rendering of camera range(1) at the scene's 1024x768, with
// range(2) = 0: no culling, 1: view-frustum culling, 2: culling and empty-space skipping
// (the thesis's Tables 8.2, 8.3 and 8.4).
void BM_RenderSplat(benchmark::State& state, const std::string& scene) {
    WarmState& w = Warm(scene, int(state.range(0)));
    const Scene& sc = w.scene;
    const CameraSettings& camera = sc.render.cameras.at(size_t(state.range(1)));
    SplatParams p = cb::MakeSplatParams(sc, camera);
    const SplatOrder order = MakeSplatOrder(p.camera, sc.grid.size, sc.grid.origin, sc.grid.voxelSize);
    p.order = &order;
    p.culling = state.range(2) >= 1;
    p.skipping = state.range(2) >= 2;
    const SplatInputs in{w.q.get(), w.q.get(), w.T.get(), w.tiles.get(), w.tiles.get(), w.bands.get(), w.bands.get()};
    SplatStats stats;
    for (auto _ : state) (void)w.backend->RenderSplat(p, in, *w.image, &stats);
    Label(state, w);
    state.counters["splats"] = double(stats.splats);
    state.counters["visited"] = double(stats.voxelsVisited);
    state.counters["fragments"] = double(stats.fragments);
    state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
    state.SetLabel(camera.name + (state.range(2) == 0 ? " none" : state.range(2) == 1 ? " VFC" : " VFC+ESS"));
}

// ---- Machine figures for the floors ------------------------------------------

// Read bandwidth: an OR-reduction over 64-bit words (the compiler vectorises
// it, so the loop is bound by the loads), per thread. With ->Threads(2) each
// thread reads its own buffer, so the pair measures the two cores together.
void ReadBandwidth(benchmark::State& state, size_t bytes) {
    std::vector<uint64_t> data(bytes / 8, 1);
    for (auto _ : state) {
        uint64_t acc = 0;
        for (uint64_t word : data) acc |= word;
        benchmark::DoNotOptimize(acc);
    }
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(bytes));
}
// 64 MiB per thread: larger than L3, so this is DRAM bandwidth.
void BM_MachineReadDram(benchmark::State& state) { ReadBandwidth(state, size_t(64) << 20); }
// 4 MiB per thread (8 MiB for two, the size of a 256x256x32 float volume): L3.
void BM_MachineReadL3(benchmark::State& state) { ReadBandwidth(state, size_t(4) << 20); }

// Write bandwidth into a 4 MiB buffer per thread.
void BM_MachineWriteL3(benchmark::State& state) {
    std::vector<float> data(size_t(1) << 20);
    float value = 0;
    for (auto _ : state) {
        std::fill(data.begin(), data.end(), value += 1);
        benchmark::ClobberMemory();
    }
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(data.size() * 4));
}

// rand24 draws per second on one core (scalar, as the compiler vectorises it).
void BM_MachineHashRate(benchmark::State& state) {
    std::vector<uint32_t> out(1 << 16);
    uint32_t key = StreamKey(1, 2, 3);
    for (auto _ : state) {
        for (uint32_t v = 0; v < out.size(); ++v) out[v] = Rand24FromKey(key, v);
        benchmark::DoNotOptimize(out.data());
        key++;
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(out.size()));
}

// Ellipsoid evaluations per second with no span overhead: the region stage on
// a 256x256x32 grid under one ellipsoid that covers every voxel, so every row
// is one full-length span. The compute floor of `region` is its evaluation
// count divided by this rate.
void BM_MachineEllipsoidRate(benchmark::State& state) {
    cpu::BackendCpu backend(int(state.threads() > 1 ? 2 : state.range(0)));
    const Extent3 e{256, 256, 32};
    auto region = Make(backend, BufferFormat::U8, e);
    const RasterEllipsoid all{{128.0f, 128.0f, 16.0f}, {1000.0f, 1000.0f, 1000.0f}, 1.0f, 0.0f};
    for (auto _ : state) (void)backend.Region({&all, 1}, *region);
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(e.Count()));
}

// PhaseValue calls per second on one core (SPEC 9): 4096 cosines spread over
// [-1, 1] per iteration, so the Mie table is read across its whole range.
void BM_PhaseValue(benchmark::State& state, PhaseKind kind) {
    std::vector<float> cosines(4096), out(cosines.size());
    for (size_t i = 0; i < cosines.size(); ++i) cosines[i] = std::cos(float(i) * 0.7853f);
    const PhaseParams phase{kind, 0.6f};
    for (auto _ : state) {
        for (size_t i = 0; i < cosines.size(); ++i) out[i] = PhaseValue(phase, cosines[i]);
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(cosines.size()));
}

void Register() {
    const char* scenes[] = {"thesis-low", "thesis-medium", "thesis-high"};
    for (const char* scene : scenes) {
        std::string s = scene;
        benchmark::RegisterBenchmark(("Region/" + s).c_str(), BM_Region, s)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("CaStep/" + s).c_str(), BM_CaStep, s)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("Smooth/" + s).c_str(), BM_Smooth, s)
            ->Args({1, 1})->Args({2, 1})->Args({2, 0})->Args({2, 2})->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("Density/" + s).c_str(), BM_Density, s)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("Shade/" + s).c_str(), BM_Shade, s)
            ->Args({2, 1})->Args({2, 2})->Args({1, 1})->Unit(benchmark::kMillisecond);
        if (s == "thesis-medium")  // the sun sweep (docs/performance.md)
            benchmark::RegisterBenchmark(("ShadeSun/" + s).c_str(), BM_ShadeSun, s)
                ->ArgsProduct({{1, 2, 4, 8, 16}, {10, 25, 60, 90}, {60}})
                ->ArgsProduct({{1, 2, 4, 8, 16}, {25, 45}, {0}})
                ->Unit(benchmark::kMillisecond)->UseRealTime();
        benchmark::RegisterBenchmark(("RenderSplat/" + s).c_str(), BM_RenderSplat, s)
            ->ArgsProduct({{2}, {0, 1}, {0, 1, 2}})->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();
    }
    for (PhaseKind kind : {PhaseKind::HenyeyGreenstein, PhaseKind::CornetteShanks, PhaseKind::Mie})
        benchmark::RegisterBenchmark(("PhaseValue/" + std::string(PhaseKindName(kind))).c_str(), BM_PhaseValue, kind);
    // Small variants for the CTest smoke run.
    std::string small = "ci-small";
    benchmark::RegisterBenchmark("Small/Region", BM_Region, small)->Arg(2);
    benchmark::RegisterBenchmark("Small/CaStep", BM_CaStep, small)->Arg(2);
    benchmark::RegisterBenchmark("Small/Smooth", BM_Smooth, small)->Args({2, 1});
    benchmark::RegisterBenchmark("Small/Density", BM_Density, small)->Arg(2);
    benchmark::RegisterBenchmark("Small/Shade", BM_Shade, small)->Args({2, 1});
    benchmark::RegisterBenchmark("Small/RenderSplat", BM_RenderSplat, small)->Args({2, 0, 2});
    benchmark::RegisterBenchmark("Machine/ReadDram", BM_MachineReadDram)->Threads(1)->Threads(2)->UseRealTime();
    benchmark::RegisterBenchmark("Machine/ReadL3", BM_MachineReadL3)->Threads(1)->Threads(2)->UseRealTime();
    benchmark::RegisterBenchmark("Machine/WriteL3", BM_MachineWriteL3)->Threads(1)->Threads(2)->UseRealTime();
    benchmark::RegisterBenchmark("Machine/HashRate", BM_MachineHashRate)->Threads(1)->Threads(2)->UseRealTime();
    benchmark::RegisterBenchmark("Machine/EllipsoidRate", BM_MachineEllipsoidRate)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
}

}  // namespace
}  // namespace cb

int main(int argc, char** argv) {
    cb::Register();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
