// What a stage's call adapter takes and gives (each stage's module, core/stages/<stage>/,
// has one): the buffers of its resources, what it reads from the host, and the
// record of what it measured; and the timing every adapter's backend calls go
// through. The simulation runs the adapters every step, and `conform` runs them
// on another backend with the CPU's inputs (harness/run/StageCall.h).
#pragma once

#include <array>
#include <chrono>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/base/CallgrindRequests.h"
#include "core/base/ProcessCpuTime.h"
#include "core/pipeline/Backend.h"
#include "core/pipeline/ShaftsPass.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/Scene.h"

namespace cb {

// The buffers of one call, by resource (core/pipeline/StageDescriptor.h): inputs are
// `current` (and `previous` for an interpolating renderer); outputs go to
// `current`, or to `next` for a stage that advances the state. Images hold
// one buffer per camera.
struct StageBuffers {
    std::array<std::vector<Buffer*>, kResourceCount> current;
    std::array<Buffer*, kResourceCount> previous{};
    std::array<Buffer*, kResourceCount> next{};

    Buffer* Current(Resource r, size_t n = 0) const {
        const auto& list = current[size_t(r)];
        return n < list.size() ? list[n] : nullptr;
    }
    Buffer* Previous(Resource r) const { return previous[size_t(r)]; }
    Buffer* Next(Resource r) const { return next[size_t(r)]; }
};

// What a stage reads from the host rather than from a resource.
struct StageHostInputs {
    uint32_t step = 0;
    std::span<const RasterEllipsoid> raster;  // region: step t's ellipsoids
    // Renderers: the frame of the step (0 .. frames - 1) and the step's frames (0: render.frames_per_step), which
    // set alpha (RenderSettings::FrameAlpha).
    uint32_t frame = 0;
    uint32_t frames = 0;
    // Region, ca, smooth, density and shade: the share of the stage to compute (time-slicing; core/pipeline/Backend.h).
    SliceRange slices;
    // Pipelined timing: call backend.MarkBatch() before each backend call (StageCallRecord::marks).
    bool markBatch = false;
    // Renderers: the frame's number in the run, the frames drawn before it (a camera's track and the reprojection's
    // order run on it; core/math/Camera.h, core/math/Reprojection.h).
    uint32_t sequence = 0;
    // Renderers: a stamp of what the buffers they read hold. Two calls with the same non-zero stamp read buffers
    // whose contents are unchanged between them (for the same buffers), so a backend may keep what it formed from
    // them; 0: unknown (form anew). Stamps are unique in the process.
    uint64_t inputsStamp = 0;
};

// One rendered image.
struct FrameRecord {
    Stage renderer = Stage::RenderSplat;
    std::string camera;
    uint32_t frame = 0;  // the frame of its step (render.frames_per_step)
    float alpha = 0;     // the interpolation weight it was drawn with
    // Wall time of its call, ms; pipelined (markBatch), the host's recording time.
    double ms = 0;
    bool pipelined = false;          // drawn in a batch (pipelined timing)
    std::optional<double> deviceMs;  // its device time, where the backend measures it
    FrameCounters counters{};  // its renderer's counters (RendererDescriptor::counters names them)
};

// What one call measured and returned besides its buffers.
struct StageCallRecord {
    double ms = 0;                           // wall time of the backend's calls
    double cpuMs = 0;                        // the process's CPU time over them (core/base/ProcessCpuTime.h)
    std::optional<double> deviceMs;          // where the backend measures it (not with markBatch)
    std::optional<uint32_t> coveredColumns;  // density
    std::vector<FrameRecord> frames;         // renderers, one per camera
    // With markBatch: one entry per MarkBatch() the call made, in order: the
    // index in `frames` of the frame it drew, or nullopt for a stage's own call.
    std::vector<std::optional<size_t>> marks;
};

// A stage's call: makes the stage's parameters from the scene, picks its
// buffers and makes the backend call, timed (TimedStage, RenderEachCamera).
// The buffers must hold every resource the stage's descriptor reads and writes in this scene.
using StageAdapter = Status (*)(Backend& backend, const Scene& scene, const StageHostInputs& host,
                                const StageBuffers& buffers, StageCallRecord& record);

// Adds the wall and CPU time from its construction to Stop() to a record. The
// CPU clock is a system call (about 0.8 us here, against 0.03 us for the wall
// clock), so it is read outside the wall-time interval: a 14 us stage's wall
// time would otherwise grow by a tenth.
class CallClock {
  public:
    explicit CallClock(StageCallRecord& record)
        : mRecord(record), mCpuStart(ProcessCpuMs()), mStart(std::chrono::steady_clock::now()) {}
    void Stop() {
        mRecord.ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - mStart).count();
        mRecord.cpuMs += ProcessCpuMs() - mCpuStart;
    }

  private:
    StageCallRecord& mRecord;
    double mCpuStart;
    std::chrono::steady_clock::time_point mStart;
};

// Runs one backend call, adding its wall, CPU and device time to the record.
// Under callgrind the call alone (not the clock reads) is counted as one dump
// named by `label` (core/base/CallgrindRequests.h).
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
    CallClock clock(record);
    counted.Begin();
    Status status = call();
    counted.End();
    clock.Stop();
    if (markBatch) return status;
    if (auto device = backend.LastDeviceMs()) record.deviceMs = record.deviceMs.value_or(0) + *device;
    return status;
}

// One frame per camera: `renderOne(n, frame, timed)` makes camera n's frame
// (buffer n of resource `image`), running its backend call through `timed`
// (host work outside it is not stage time); each frame's time is what `timed`
// measured. With shafts of light, `timed` adds them to the frame after the
// call, in the frame's time (SPEC 18: blended additively after the renderer).
template <typename RenderOne>
Status RenderEachCamera(Stage renderer, Backend& backend, const Scene& sc, const StageHostInputs& host,
                        const StageBuffers& io, Resource image, StageCallRecord& record, RenderOne&& renderOne) {
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
        std::optional<ShaftsFrame> shafts;
        if (sc.lighting.shafts.on)
            shafts = MakeSceneShaftsFrame(
                sc, MakeCameraFrame(sc.render.cameras[n].At(host.sequence), sc.render.width, sc.render.height), step);
        auto timed = [&](auto&& call) {
            std::optional<double> drawnDeviceMs;
            Status status = Timed(backend, record, label, host.markBatch, index, [&]() -> Status {
                Status drawn = call();
                if (!drawn || !shafts) return drawn;
                drawnDeviceMs = backend.LastDeviceMs();
                return backend.AddShafts(*shafts, *io.Current(Resource::ColumnSum), *io.Current(image, n));
            });
            // Timed took the device time of the backend's last call, the shafts'; the renderer's is added here.
            if (drawnDeviceMs && !host.markBatch) record.deviceMs = record.deviceMs.value_or(0) + *drawnDeviceMs;
            return status;
        };
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
inline Buffer* PreviousOrCurrent(const StageBuffers& io, Resource r) {
    return io.Previous(r) ? io.Previous(r) : io.Current(r);
}

// Runs `call` timed as stage `stage`'s one call of this step.
template <typename Fn>
Status TimedStage(Stage stage, Backend& backend, const StageHostInputs& host, StageCallRecord& record, Fn&& call) {
    const std::string backendName = backend.Name();  // the label holds a view of it
    const StageCountLabel label{StageName(stage), backendName, host.step, ""};
    return Timed(backend, record, label, host.markBatch, std::nullopt, call);
}

}  // namespace cb
