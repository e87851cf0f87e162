#include "harness/accuracy/Accuracy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/stages/shade/Shade.h"
#include "core/stages/shadow/Shadow.h"
#include "harness/platform/Isolation.h"
#include "harness/run/Simulation.h"
#include "registry/Registry.h"

namespace cb {

ErrorStats AbsoluteErrors(std::span<const float> approx, std::span<const float> reference,
                          std::span<const uint8_t> mask) {
    ErrorStats stats;
    std::vector<double> errors;
    errors.reserve(mask.empty() ? approx.size() : 0);
    double sum = 0;
    for (size_t v = 0; v < approx.size() && v < reference.size(); ++v) {
        if (!mask.empty() && !mask[v]) continue;
        const double e = std::fabs(double(approx[v]) - double(reference[v]));
        if (e > stats.max || errors.empty()) {
            stats.max = e;
            stats.worst = v;
        }
        sum += e;
        errors.push_back(e);
    }
    stats.count = errors.size();
    if (errors.empty()) return stats;
    stats.mean = sum / double(errors.size());
    // Nearest rank: the ceil(0.99 n)-th smallest.
    const size_t rank = size_t(std::ceil(0.99 * double(errors.size()))) - 1;
    std::nth_element(errors.begin(), errors.begin() + ptrdiff_t(rank), errors.end());
    stats.p99 = errors[rank];
    return stats;
}

Result<LightingInputs> SimulateLightingInputs(const Scene& scene, int threads) {
    if (!scene.stages.Has(Stage::Smooth) && !scene.stages.Has(Stage::Noise))
        return MakeError(scene.path +
                         ": stages: the reference needs q, so the scene must have \"smooth\" or \"noise\"");
    Scene sim = scene;
    sim.stages = StageSet{};
    for (Stage s : {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Noise, Stage::Density})
        if (scene.stages.Has(s)) sim.stages.Add(s);
    BackendOptions options;
    options.cpuThreads = threads;
    auto cpu = CreateBackend("cpu", options);
    if (!cpu) return std::unexpected(cpu.error());
    auto simulation = Simulation::Create(sim, **cpu);
    if (!simulation) return std::unexpected(simulation.error());
    LightingInputs in;
    in.grid = scene.grid.size;
    in.step = scene.steps - 1;
    auto observe = [&](const Simulation& s) -> Status {
        if (s.CurrentStep() != in.step) return {};
        in.q.resize(s.Q()->Extent().Count());
        CB_TRY(s.GetBackend().Download(*s.Q(), std::as_writable_bytes(std::span(in.q))));
        if (const Buffer* d = s.ColumnSum()) {
            in.D.resize(d->Extent().Count());
            CB_TRY(s.GetBackend().Download(*d, std::as_writable_bytes(std::span(in.D))));
        }
        return {};
    };
    for (uint32_t t = 0; t < scene.steps; ++t) {
        StepRecord record;
        if (Status s = (*simulation)->Step(record, observe); !s)
            return MakeError("step " + std::to_string(t) + ": " + s.error().message);
    }
    return in;
}

ref::ReferenceParams MakeReferenceParams(const Scene& scene, ref::RayStart start) {
    ref::ReferenceParams p;
    p.sun = scene.sun.Direction();
    p.sigma = scene.shade.sigma;
    p.voxelSize = scene.grid.voxelSize;
    p.start = start;
    return p;
}

Result<ReferenceResult> ComputeReference(const Scene& scene, const LightingInputs& in, ref::RayStart start,
                                         int threads) {
    auto tracer = ref::OpticalDepthTracer::Create(in.grid, in.q, threads);
    if (!tracer) return std::unexpected(tracer.error());
    const ref::ReferenceParams p = MakeReferenceParams(scene, start);
    ReferenceResult r;
    r.buildSeconds = (*tracer)->BuildSeconds();
    r.primitives = (*tracer)->Primitives();
    r.T = (*tracer)->Transmittance(p, &r.tStats);
    r.G = (*tracer)->GroundShadow(p, &r.gStats);
    r.cloud.resize(in.q.size());
    for (size_t v = 0; v < in.q.size(); ++v) r.cloud[v] = in.q[v] > 0.0f;
    r.shadowed.resize(r.G.size());
    for (size_t g = 0; g < r.G.size(); ++g) r.shadowed[g] = r.G[g] < 1.0f;
    return r;
}

StageAccuracy MeasureShade(Backend& backend, const Scene& scene, const LightingInputs& in,
                           const ReferenceResult& reference, int repeats, bool keepOutput) {
    if (!backend.Supports(Stage::Shade))
        return NotMeasured("unsupported", backend.Name() + " does not implement shade yet");
    auto q = backend.CreateBuffer(BufferFormat::F32, in.grid);
    auto T = backend.CreateBuffer(BufferFormat::F32, in.grid);
    if (!q || !T) return NotMeasured("failed", (!q ? q.error() : T.error()).message);
    if (Status s = backend.Upload(**q, std::as_bytes(std::span(in.q))); !s)
        return NotMeasured("failed", s.error().message);
    const ShadeParams params = MakeShadeParams(scene);
    MarkPhase("shade", in.step);  // for a crash report, as CallStage marks it
    InjectTestFault(backend.Name(), "shade");
    auto time = TimeRepeated(repeats, [&] { return backend.Shade(params, **q, **T); });
    if (!time) return NotMeasured("failed", "shade: " + time.error().message);
    StageAccuracy a;
    a.timeMs = *time;
    std::vector<float> out(in.grid.Count());
    if (Status s = backend.Download(**T, std::as_writable_bytes(std::span(out))); !s)
        return NotMeasured("failed", s.error().message);
    a.all = AbsoluteErrors(out, reference.T);
    a.subset = AbsoluteErrors(out, reference.T, reference.cloud);
    if (keepOutput) a.output = std::move(out);
    return a;
}

StageAccuracy MeasureShadow(Backend& backend, const Scene& scene, const LightingInputs& in,
                            const ReferenceResult& reference, int repeats) {
    if (!backend.Supports(Stage::Shadow))
        return NotMeasured("unsupported", backend.Name() + " does not implement shadow yet");
    if (in.D.empty()) return NotMeasured("unsupported", "the scene has no density stage, so no D to shadow from");
    const Extent3 columns{in.grid.nx, in.grid.ny, 1};
    auto D = backend.CreateBuffer(BufferFormat::F32, columns);
    auto G = backend.CreateBuffer(BufferFormat::F32, columns);
    if (!D || !G) return NotMeasured("failed", (!D ? D.error() : G.error()).message);
    if (Status s = backend.Upload(**D, std::as_bytes(std::span(in.D))); !s)
        return NotMeasured("failed", s.error().message);
    const ShadowParams params = MakeShadowParams(scene);
    MarkPhase("shadow", in.step);
    InjectTestFault(backend.Name(), "shadow");
    auto time = TimeRepeated(repeats, [&] { return backend.Shadow(params, **D, **G); });
    if (!time) return NotMeasured("failed", "shadow: " + time.error().message);
    StageAccuracy a;
    a.timeMs = *time;
    std::vector<float> out(columns.Count());
    if (Status s = backend.Download(**G, std::as_writable_bytes(std::span(out))); !s)
        return NotMeasured("failed", s.error().message);
    a.all = AbsoluteErrors(out, reference.G);
    a.subset = AbsoluteErrors(out, reference.G, reference.shadowed);
    return a;
}

double SwitchSideBound(const ShadeParams& p, const Extent3& grid, const Vec3& side, const Vec3& tie, int axis,
                       float qMax) {
    if (p.filter == SampleFilter::Nearest) return std::numeric_limits<double>::infinity();
    const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    const uint32_t n[3] = {grid.nx, grid.ny, grid.nz};
    const double f = p.resolution;
    const double slices = std::ceil(double(n[axis]) / f);
    const double M = std::max(0.0, slices - 1);
    // Tap offsets and optical depth per unit q for both directions, with the same axis.
    const double swSide = std::fabs(double(side[axis])), swTie = std::fabs(double(tie[axis]));
    const double delta = std::fabs(side[u] / swSide - tie[u] / swTie) + std::fabs(side[v] / swSide - tie[v] / swTie);
    const double cellSize = double(p.voxelSize) * f;
    const double cSide = p.sigma * cellSize / swSide, cTie = p.sigma * cellSize / swTie;
    const double cMax = std::max(cSide, cTie), dc = std::fabs(cSide - cTie);
    // Slopes of the per-slice factor A(q; c): beer exp(-c q), thesis 1 - (1 - a_r) q,
    // plus gain c q with multiple forward scattering (the clamp only flattens it).
    double Lq = p.attenuation == AttenuationKind::Beer ? cMax : 1.0 - p.thesisAr;
    double Lc = p.attenuation == AttenuationKind::Beer ? 1.0 : 0.0;  // times q
    if (p.scattering) {
        const SliceAttenuation a = MakeSliceAttenuation(p.attenuation, p.sigma, float(cellSize), float(swTie),
                                                        p.thesisAr, true, p.albedo, p.solidAngle, p.phase);
        Lq += a.scatterGain * cMax;
        Lc += a.scatterGain;
    }
    // Rounding per slice: three lerps, exp and a product in float (under 16
    // float ulps of 1), and half a storage quantum when T is stored rounded.
    const double rounding = 16 * std::ldexp(1.0, -24) + 0.5 * StorageQuantum(p.storage);
    return M * (delta * (1 + Lq * qMax) + Lc * qMax * dc + rounding);
}

}  // namespace cb
