#include "harness/run/StageCall.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "harness/platform/CallgrindRequests.h"
#include "harness/platform/Isolation.h"
#include "harness/run/StageParams.h"

namespace cb {
namespace {

// Runs one backend call, adding its wall and device time to the record.
// Under callgrind the call alone (not the clock reads) is counted as one dump
// named by `label` (harness/platform/CallgrindRequests.h).
// With host.markBatch (pipelined timing) it first starts the batch's next
// interval, owned by `frame` (an index in record.frames, or the stage), and
// takes no device time: LastDeviceMs() means nothing in a batch.
template <typename Fn>
Status Timed(Backend& backend, StageCallRecord& record, const StageCountLabel& label, bool markBatch,
             std::optional<size_t> frame, Fn&& call) {
    const CallgrindStageBracket counted(label);
    if (markBatch) {
        backend.MarkBatch();
        record.marks.push_back(frame);
    }
    const auto start = std::chrono::steady_clock::now();
    counted.Begin();
    Status status = call();
    counted.End();
    record.ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (markBatch) return status;
    if (auto device = backend.LastDeviceMs()) record.deviceMs = record.deviceMs.value_or(0) + *device;
    return status;
}

// One frame per camera: `renderOne(n, frame, timed)` makes camera n's frame,
// running its backend call through `timed` (host work outside it is not
// stage time); each frame's time is what `timed` measured.
template <typename RenderOne>
Status RenderEachCamera(Stage renderer, Backend& backend, const Scene& sc, const StageHostInputs& host,
                        StageCallRecord& record, RenderOne&& renderOne) {
    const uint32_t step = host.step;
    const std::string backendName = backend.Name();
    for (size_t n = 0; n < sc.render.cameras.size(); ++n) {
        FrameRecord frame;
        frame.renderer = renderer;
        frame.camera = sc.render.cameras[n].name;
        frame.frame = host.frame;
        frame.alpha = sc.render.FrameAlpha(host.frame, host.frames);
        frame.pipelined = host.markBatch;
        const double before = record.ms;
        const std::optional<double> deviceBefore = record.deviceMs;
        const StageCountLabel label{StageName(renderer), backendName, step, frame.camera};
        const size_t index = record.frames.size();
        auto timed = [&](auto&& call) { return Timed(backend, record, label, host.markBatch, index, call); };
        Status status = renderOne(n, frame, timed);
        frame.ms = record.ms - before;
        if (record.deviceMs) frame.deviceMs = *record.deviceMs - deviceBefore.value_or(0);
        if (!status)
            return MakeError(std::string(StageName(renderer)) + " (" + frame.camera + "): " + status.error().message);
        record.frames.push_back(frame);
    }
    return {};
}

// Without a previous step (step 0, or no history kept) a renderer interpolates a step with itself.
Buffer* PreviousOrCurrent(const StageBuffers& io, Resource r) {
    return io.Previous(r) ? io.Previous(r) : io.Current(r);
}

// One adapter per stage: makes the stage's parameters from the scene, picks
// its buffers and makes the backend call. kStageCalls expands CB_STAGES, so a
// stage without its adapter does not compile.
using StageAdapter = Status (*)(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                                StageCallRecord& record);

// Runs `call` timed as stage `stage`'s one call of this step.
template <typename Fn>
Status TimedStage(Stage stage, Backend& backend, const StageHostInputs& host, StageCallRecord& record, Fn&& call) {
    const std::string backendName = backend.Name();  // the label holds a view of it
    const StageCountLabel label{StageName(stage), backendName, host.step, ""};
    return Timed(backend, record, label, host.markBatch, std::nullopt, call);
}

Status CallRegion(Backend& backend, const Scene&, const StageHostInputs& host, const StageBuffers& io,
                  StageCallRecord& record) {
    return TimedStage(Stage::Region, backend, host, record,
                      [&] { return backend.Region(host.raster, *io.Current(Resource::Region), host.slices); });
}

Status CallCa(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
              StageCallRecord& record) {
    CaStepParams params = MakeCaStepParams(sc, host.step);
    std::vector<int32_t> shiftX, shiftY;
    if (sc.ca.HasWind())
        for (const SliceShift& s : sc.ca.windShift) shiftX.push_back(s.sx), shiftY.push_back(s.sy);
    params.shiftX = shiftX;
    params.shiftY = shiftY;
    params.slices = host.slices;
    const ConstCaFields in{io.Current(Resource::Hum), io.Current(Resource::Act), io.Current(Resource::Cld)};
    const CaFields out{io.Next(Resource::Hum), io.Next(Resource::Act), io.Next(Resource::Cld)};
    return TimedStage(Stage::Ca, backend, host, record,
                      [&] { return backend.CaStep(params, in, *io.Current(Resource::Region), out); });
}

Status CallSmooth(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                  StageCallRecord& record) {
    return TimedStage(Stage::Smooth, backend, host, record, [&] {
        return backend.Smooth(sc.smooth.radius, *io.Current(Resource::Cld), *io.Current(Resource::Q), host.slices);
    });
}

Status CallDensity(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                   StageCallRecord& record) {
    DensityOutputs out{io.Current(Resource::ColumnSum), io.Current(Resource::Tiles), io.Current(Resource::Bands), 0};
    DensityParams params = MakeDensityParams(sc);
    params.slices = host.slices;
    CB_TRY(TimedStage(Stage::Density, backend, host, record, [&] {
        return backend.Density(params, *io.Current(Resource::Q), io.Current(Resource::Cld), out);
    }));
    record.coveredColumns = out.coveredColumns;
    return {};
}

Status CallShade(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                 StageCallRecord& record) {
    ShadeParams p = MakeShadeParams(sc, host.step);
    p.slices = host.slices;
    return TimedStage(Stage::Shade, backend, host, record,
                      [&] { return backend.Shade(p, *io.Current(Resource::Q), *io.Current(Resource::T)); });
}

Status CallShadow(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                  StageCallRecord& record) {
    const ShadowParams p = MakeShadowParams(sc, host.step);
    return TimedStage(Stage::Shadow, backend, host, record, [&] {
        return backend.Shadow(p, *io.Current(Resource::ColumnSum), *io.Current(Resource::Shadow));
    });
}

Status CallRenderSplat(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                       StageCallRecord& record) {
    return RenderEachCamera(
        Stage::RenderSplat, backend, sc, host, record, [&](size_t n, FrameRecord& frame, auto timed) {
            SplatParams p = MakeSplatParams(sc, sc.render.cameras[n], host.step, host.frame, host.frames);
            // The order is host work shared by all backends, outside the stage time.
            const SplatOrder order = MakeSplatOrder(p.camera, sc.grid.size, sc.grid.origin, sc.grid.voxelSize);
            p.order = &order;
            SplatInputs in{
                PreviousOrCurrent(io, Resource::Q), io.Current(Resource::Q),     io.Current(Resource::T),
                io.Previous(Resource::Tiles),       io.Current(Resource::Tiles), io.Previous(Resource::Bands),
                io.Current(Resource::Bands)};
            in.G = p.ground.on ? io.Current(Resource::Shadow) : nullptr;  // the ground only
            return timed(
                [&] { return backend.RenderSplat(p, in, *io.Current(Resource::SplatImage, n), &frame.stats); });
        });
}

Status CallRenderMarch(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                       StageCallRecord& record) {
    return RenderEachCamera(
        Stage::RenderMarch, backend, sc, host, record, [&](size_t n, FrameRecord& frame, auto timed) {
            const MarchParams p = MakeMarchParams(sc, sc.render.cameras[n], host.step, host.frame, host.frames);
            // T only where shade runs (the light source "shade").
            MarchInputs in{PreviousOrCurrent(io, Resource::Q), io.Current(Resource::Q), io.Current(Resource::T)};
            in.G = p.ground.on ? io.Current(Resource::Shadow) : nullptr;  // the ground only
            return timed(
                [&] { return backend.RenderMarch(p, in, *io.Current(Resource::MarchImage, n), &frame.march); });
        });
}

Status CallNoise(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                 StageCallRecord& record) {
    const NoiseParams p = MakeNoiseParams(sc, host.step);
    return TimedStage(Stage::Noise, backend, host, record, [&] { return backend.Noise(p, *io.Current(Resource::Q)); });
}

// Indexed by Stage, in CB_STAGES order.
constexpr StageAdapter kStageCalls[] = {
#define CB_STAGE_CALL(name, text, spec, splat) &Call##name,
    CB_STAGES(CB_STAGE_CALL)
#undef CB_STAGE_CALL
};
static_assert(std::size(kStageCalls) == kStageCount, "one adapter per stage");

Status Call(Stage stage, Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
            StageCallRecord& record) {
    return kStageCalls[size_t(stage)](backend, sc, host, io, record);
}

// The test-only slowdown switch, CLOUDBENCH_TEST_SLOWDOWN=<stage>:<factor>
// (docs/cli.md): the named stage's time becomes `factor` times its own, by
// spinning for (factor - 1) times the call's time after it, inside the timed
// record. It exists so that the performance gate's tests can plant a known
// regression; nothing else reads it.
struct Slowdown {
    std::string stage;
    double factor = 1;
};

const std::optional<Slowdown>& TestSlowdown() {
    static const std::optional<Slowdown> slowdown = []() -> std::optional<Slowdown> {
        const char* value = std::getenv("CLOUDBENCH_TEST_SLOWDOWN");
        if (!value || !*value) return std::nullopt;
        const std::string text = value;
        const size_t colon = text.find(':');
        char* end = nullptr;
        const double factor = colon == std::string::npos ? 0 : std::strtod(text.c_str() + colon + 1, &end);
        if (colon == std::string::npos || colon == 0 || end == text.c_str() + colon + 1 || *end != '\0' ||
            !(factor >= 1 && factor <= 1000)) {
            std::fprintf(stderr,
                         "CLOUDBENCH_TEST_SLOWDOWN: ignored, expected <stage>:<factor> with factor in [1, 1000]\n");
            return std::nullopt;
        }
        return Slowdown{text.substr(0, colon), factor};
    }();
    return slowdown;
}

void SpinFor(double ms) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double, std::milli>(ms);
    while (std::chrono::steady_clock::now() < until) {
    }
}

}  // namespace

Status CallStage(Stage stage, Backend& backend, const Scene& scene, const StageHostInputs& host,
                 const StageBuffers& buffers, StageCallRecord& record) {
    // Where a crash happens, for the parent of an isolated backend (harness/platform/Isolation.h).
    MarkPhase(StageName(stage), host.step);
    InjectTestFault(backend.Name(), StageName(stage));
    const double before = record.ms;
    Status status = Call(stage, backend, scene, host, buffers, record);
    if (const auto& slowdown = TestSlowdown(); slowdown && slowdown->stage == StageName(stage)) {
        const auto start = std::chrono::steady_clock::now();
        SpinFor((slowdown->factor - 1) * (record.ms - before));
        record.ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    if (!status && !Describe(stage).renderer)
        return MakeError(std::string(StageName(stage)) + ": " + status.error().message);
    return status;
}

}  // namespace cb
