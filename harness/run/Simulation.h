// Runs a scene's enabled stages on one backend, one step at a time, scheduled
// by the resources they read and write (core/plan/StageGraph.h): only the
// buffers the enabled stages write are allocated (SPEC 14), every producer
// runs before its readers, and a stage that advances the state (the
// automaton) runs after every reader of that state.
//
// Step t of the splat pipeline, in the resulting order:
//   region   R_t from the ellipsoid list L_t
//   smooth   q_t from cld_t
//   density  D_t, occupancy and cover from q_t (and cld_t)
//   shade    T_t from q_t and s_t   } on output steps only, and only when q (D)
//   shadow   G_t from D_t and s_t   } or the sun's direction s_t changed since it last ran
//   render   render.frames_per_step frames, each one image per camera from
//            q_{t-1}, q_t (interpolated by the frame's alpha), T_t
//   (observer: everything above plus hum_t, act_t, cld_t is readable here)
//   ca       state_t -> state_{t+1} using R_t
//   host     L_{t+1} = update(L_t)
// Output steps: every step when dumping or when the scene does not render;
// otherwise the render steps (render.every_steps).
//
// Time-slicing (render.slices_per_frame = s > 0; SPEC 13, Fizimayer's thesis, section
// 7.1): step t computes its stages once (step 0 all at once, later steps
// during the frames of the step before), then draws its frames, and while
// they are drawn computes step t+1 into a third buffer set (BufferRole::
// Pending; the automaton's `next`): ca, the list update, region, smooth,
// density, shade and shadow, s slices of one stage per frame (one share a
// frame; stages without shares take one frame). The step draws
// max(render.frames_per_step, the frames its shares take) frames. Step t+1
// starts by making the third set current. Every resource the observer sees,
// and every image, is what the unsliced loop gives: only when the work is
// done changes.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"
#include "harness/run/StageCall.h"

namespace cb {

// How a step is timed (docs/performance.md, "Two ways to time a step").
//   Synchronized  the thesis's way: every stage call completes before the next;
//                 each stage has a wall time (and a device time where measured).
//   Pipelined     the step (time-sliced: each frame) is one batch of the backend
//                 (Backend::BeginBatch .. EndBatch): calls are recorded, the device
//                 runs them at its pace and the host waits once, at the end.
//                 A stage's wall time is then only the host's recording time
//                 (StepRecord::hostMs); its device time comes from the batch's
//                 marked intervals.
enum class TimingMode : uint8_t { Synchronized, Pipelined };
// "synchronized", "pipelined".
std::string_view TimingModeName(TimingMode mode);
// The timing of step t under `run --timing choice` ("synchronized", "pipelined"
// or "both"; validated when parsed). "both" alternates the two in the order
// S P P S, repeated: a cost that drifts linearly over the run (clouds that
// grow) weighs the same on each within every four steps, which S P would not.
TimingMode TimingOfStep(std::string_view choice, uint32_t step);

struct StepRecord {
    uint32_t step = 0;
    // How the step was timed.
    TimingMode timing = TimingMode::Synchronized;
    // Wall time of each stage in ms, measured synchronized; empty for stages
    // that did not run, and for stages measured pipelined (see hostMs).
    std::array<std::optional<double>, kStageCount> stageMs{};
    // Pipelined: the host's time recording each stage's calls, ms (the calls
    // return before their work is done, so this is not the stage's time).
    // Exactly one of stageMs and hostMs is set for a stage that ran.
    std::array<std::optional<double>, kStageCount> hostMs{};
    // Synchronized: the process's CPU time over each stage's calls, ms, on all
    // its threads (core/base/ProcessCpuTime.h); set with stageMs.
    std::array<std::optional<double>, kStageCount> cpuMs{};
    // Device time of each stage in ms, where the backend measures it:
    // synchronized, LastDeviceMs() after each call; pipelined, the batch's
    // intervals (Backend::EndBatch) of the stage's calls.
    std::array<std::optional<double>, kStageCount> deviceMs{};
    // Stages that skipped this step because none of their inputs (the sun's
    // direction included) changed since they last ran (skipsUnchangedInputs).
    std::array<bool, kStageCount> skippedUnchanged{};
    double ellipsoidUpdateMs = 0;            // host-side list update
    std::optional<uint32_t> coveredColumns;  // from the density stage
    std::vector<FrameRecord> frames;         // renderers: one per camera and frame of the step
    uint32_t framesRendered = 0;             // frames of this step (render.frames_per_step on render steps, else 0)
    // Wall time of each frame, ms: its renders and, time-sliced, its shares. The
    // step's work outside its frames is charged to frame 0, so they add up to stepMs.
    std::vector<double> frameMs;
    // Time-sliced: what each frame computed, e.g. "ca 4-7" or "region 0-3, ellipsoids" ("" for none).
    std::vector<std::string> frameWork;
    // Wall time of the whole step (stages, frames and host work; not the observer), ms.
    // Pipelined, it includes the wait at the end of each batch.
    double stepMs = 0;
    // What the step asked of the device: the difference of Backend::Submissions()
    // over the step (the observer's reads included), and the batches it opened.
    uint64_t submissions = 0, hostWaits = 0;
    uint32_t batches = 0;

    // Whether the stage ran in this step (measured in either mode).
    bool Ran(Stage stage) const { return stageMs[size_t(stage)] || hostMs[size_t(stage)]; }
};

class Simulation {
  public:
    // Allocates the enabled stages' buffers and computes the initial state.
    // Refuses a backend that lacks an enabled stage, one whose device limits
    // the scene exceeds (CheckDeviceLimits), or one whose available memory
    // the planned buffers and scratch exceed (CheckPlannedBytesFit).
    // everyStepOutputs: shade, shadow and render on every step (for dumps).
    static Result<std::unique_ptr<Simulation>> Create(const Scene& scene, Backend& backend,
                                                      bool everyStepOutputs = false);

    using Observer = std::function<Status(const Simulation&)>;
    // Runs step CurrentStep() and advances to the next, timed as Timing() says.
    // Pipelined: one batch per step (time-sliced: per frame, and one for the
    // work outside frames); MarkBatch() before every backend call of a stage
    // (a renderer's: each camera's frame); an observer ends the batch before it
    // and opens another for the rest of the step. A failed call still ends its
    // batch, and the step reports the call's error.
    Status Step(StepRecord& record, const Observer& observe = {});

    // The timing of the following steps (default: synchronized).
    void SetTiming(TimingMode mode) { mTiming = mode; }
    TimingMode Timing() const { return mTiming; }

    uint32_t CurrentStep() const { return mStep; }
    const Scene& GetScene() const { return mScene; }
    Backend& GetBackend() const { return mBackend; }

    // The current step's buffer of a resource (camera n of a per-camera one);
    // nullptr when no enabled stage writes it.
    const Buffer* Get(Resource resource, size_t n = 0) const;
    // The previous step's value of a resource an interpolating renderer reads;
    // nullptr when none is kept.
    const Buffer* Previous(Resource resource) const;

    const Buffer* Hum() const { return Get(Resource::Hum); }
    const Buffer* Act() const { return Get(Resource::Act); }
    const Buffer* Cld() const { return Get(Resource::Cld); }
    const Buffer* Region() const { return Get(Resource::Region); }
    const Buffer* Q() const { return Get(Resource::Q); }
    const Buffer* ColumnSum() const { return Get(Resource::ColumnSum); }
    const Buffer* Tiles() const { return Get(Resource::Tiles); }
    const Buffer* Bands() const { return Get(Resource::Bands); }
    const Buffer* T() const { return Get(Resource::T); }
    const Buffer* QPrev() const { return Previous(Resource::Q); }
    const Buffer* TilesPrev() const { return Previous(Resource::Tiles); }
    const Buffer* BandsPrev() const { return Previous(Resource::Bands); }
    const Buffer* Shadow() const { return Get(Resource::Shadow); }
    // The splat image of camera `n` (F32, extent (3, width, height)); valid after a render step.
    const Buffer* Image(size_t n) const { return Get(Resource::SplatImage, n); }
    // The step whose images are in Image(); nullopt before the first render.
    std::optional<uint32_t> LastRenderedStep() const { return mLastRendered; }
    // Frames drawn so far (StageHostInputs::sequence of the next frame).
    uint32_t FramesDrawn() const { return mFramesDrawn; }
    bool IsOutputStep(uint32_t step) const;
    // The ellipsoids the current step's region came from.
    const std::vector<RasterEllipsoid>& RasterList() const { return mRaster; }
    // The enabled stages in the order a step runs them.
    const std::vector<Stage>& Schedule() const { return mSchedule; }

  private:
    // Saves and restores the whole state between steps (harness/run/SimulationState.h).
    friend struct SimulationStateAccess;

    // A resource's buffers: this step's (one per camera for images), the next
    // step's for a state-advancing writer, the previous step's where a
    // renderer interpolates; and a count of writes, to skip stages whose
    // inputs did not change.
    struct Slot {
        std::vector<std::unique_ptr<Buffer>> current;
        std::unique_ptr<Buffer> next, previous, pending;
        uint64_t version = 0;
        // Time-sliced: the next step's value is being computed (in `next` or `pending`); committed when it starts.
        bool ahead = false;
        // Not written since the step before (its writer skipped, or this is step 0): the previous step's value is
        // the current one, and `previous` holds nothing a renderer may read.
        bool previousIsCurrent = false;
        Buffer* PreviousValue() const { return previous && previousIsCurrent ? current[0].get() : previous.get(); }
    };
    // One share of the next step's work in a frame; no stage: the ellipsoid list update.
    struct ShareTask {
        std::optional<Stage> stage;
        SliceRange slices;
        uint32_t shareCount = 1;  // the stage's shares at the step it computes (StageDescriptor::shareCount)
    };
    using FrameTasks = std::vector<ShareTask>;

    Simulation(const Scene& scene, Backend& backend, bool everyStepOutputs);
    // Allocates exactly PlanBuffers(scene), so the memory plan prices what is allocated.
    Status Allocate();
    Status InitializeState();
    // Runs one stage on this step's buffers (its writes go to `next` when it advances the state).
    Status RunStage(Stage stage, StepRecord& record, uint32_t frame = 0, uint32_t frames = 0);
    // This step's non-renderer stages that do not advance the state, in schedule order.
    Status RunStepStages(StepRecord& record, bool outputStep);
    // `frames` frames of every renderer; frame f first runs work[f] where there is one.
    Status RenderFrames(StepRecord& record, uint32_t frames, std::span<const FrameTasks> work);
    Status SlicedStep(StepRecord& record, const Observer& observe);
    // Time-sliced: the state advance of step mStep-1 (ca, the list update) that its sliced step left owed.
    Status RunOwedAdvance(StepRecord& record);
    // The next step's work split into frames of `slicesPerFrame` slices; marks its outputs ahead.
    std::vector<FrameTasks> PlanAhead(uint32_t slicesPerFrame);
    // Runs one frame's shares; `describe`, if given, gets what they computed ("smooth 4-7").
    Status RunShares(const FrameTasks& tasks, StepRecord& record, std::string* describe = nullptr);
    // Makes the next step's values current (the start of a time-sliced step).
    void CommitAhead(StepRecord& record);
    // Pipelined timing: one open batch and the owner of each of its marked
    // intervals, in call order (a stage of a record, and its frame for a renderer).
    struct MarkOwner {
        StepRecord* record = nullptr;
        Stage stage = Stage::Region;
        std::optional<size_t> frame;  // index in record->frames
    };
    class BatchScope;
    // Runs `work` inside one batch when the timing is pipelined, else as it is.
    Status Batched(StepRecord& record, const std::function<Status()>& work);
    // Records a call's times in `target`: its marks (pipelined) or its wall time
    // (synchronized); `firstFrame` is where the call's frames start in target.frames.
    void AddCallTimes(Stage stage, const StageCallRecord& call, StepRecord& target, size_t firstFrame);
    bool Pipelined() const { return mTiming == TimingMode::Pipelined; }
    StageBuffers Buffers();
    // Buffers as the next step's stages see them: resources being computed ahead read and write their third set.
    StageBuffers AheadBuffers();
    bool InputsChangedSinceLastRun(Stage stage, uint32_t step) const;
    std::vector<uint64_t> InputVersions(Stage stage, uint32_t step) const;
    Buffer& Out(Resource resource, size_t n = 0);

    const Scene mScene;
    Backend& mBackend;
    const std::vector<Stage> mSchedule;
    EllipsoidList mEllipsoids;
    std::vector<RasterEllipsoid> mRaster;  // the list step t's region was rasterised from
    uint32_t mStep = 0;
    std::array<Slot, kResourceCount> mSlots;
    // Input versions of each stage when it last ran (skipsUnchangedInputs).
    std::array<std::optional<std::vector<uint64_t>>, kStageCount> mInputsAtLastRun;
    const bool mEveryStepOutputs;
    std::optional<uint32_t> mLastRendered;
    uint32_t mFramesDrawn = 0;
    // Per renderer: the input versions its last call read, and their stamp (StageHostInputs::inputsStamp).
    std::array<std::pair<std::vector<uint64_t>, uint64_t>, kStageCount> mRendererInputs;
    std::optional<uint32_t> mLastCoveredColumns;  // the density stage's last cover
    // Time-sliced: the next step's ellipsoids, and what its stages recorded (merged into its record when it starts).
    std::vector<RasterEllipsoid> mRasterAhead;
    StepRecord mAhead;
    // Time-sliced: whether the step before computed this one ahead (else this step computes its stages whole,
    // as step 0 does), and whether it ended without advancing the state (the scene's last step computes no
    // next step: a run resumed from there advances first; harness/run/SimulationState.h).
    bool mAheadComputed = false;
    bool mAdvanceOwed = false;
    TimingMode mTiming = TimingMode::Synchronized;
    bool mBatchOpen = false;
    std::vector<MarkOwner> mMarks;
};

}  // namespace cb
