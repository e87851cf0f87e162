#include "harness/run/Simulation.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstdio>

#include "core/plan/MemoryPlan.h"
#include "core/stages/ca/Ca.h"

namespace cb {

Simulation::Simulation(const Scene& scene, Backend& backend, bool everyStepOutputs)
    : mScene(scene),
      mBackend(backend),
      mSchedule(ScheduleStages(scene.stages)),
      mEllipsoids(scene.ellipsoids, scene.grid.size),
      mEveryStepOutputs(everyStepOutputs) {}

bool Simulation::IsOutputStep(uint32_t step) const {
    if (mEveryStepOutputs || !RunsARenderer(mScene.stages)) return true;
    if (step + 1 == mScene.steps) return true;
    const uint32_t every = mScene.render.everySteps;
    return every > 0 && step >= mScene.warmupSteps && (step - mScene.warmupSteps) % every == 0;
}

const Buffer* Simulation::Get(Resource resource, size_t n) const {
    const Slot& slot = mSlots[size_t(resource)];
    return n < slot.current.size() ? slot.current[n].get() : nullptr;
}

const Buffer* Simulation::Previous(Resource resource) const { return mSlots[size_t(resource)].PreviousValue(); }

Buffer& Simulation::Out(Resource resource, size_t n) { return *mSlots[size_t(resource)].current.at(n); }

Result<std::unique_ptr<Simulation>> Simulation::Create(const Scene& scene, Backend& backend, bool everyStepOutputs) {
    for (Stage stage : kAllStages) {
        if (scene.stages.Has(stage) && !backend.Supports(stage))
            return MakeError(backend.Name() + " does not implement stage '" + std::string(StageName(stage)) + "' yet");
    }
    CB_TRY(CheckDeviceLimits(scene, backend));
    CB_TRY(CheckPlannedBytesFit(scene, backend));
    std::unique_ptr<Simulation> sim(new Simulation(scene, backend, everyStepOutputs));
    CB_TRY(sim->Allocate());
    CB_TRY(sim->InitializeState());
    return sim;
}

Status Simulation::Allocate() {
    for (const PlannedBuffer& planned : PlanBuffers(mScene)) {
        auto buffer = mBackend.CreateBuffer(planned.format, planned.extent);
        if (!buffer) return std::unexpected(buffer.error());
        Slot& slot = mSlots[size_t(planned.resource)];
        switch (planned.role) {
            case BufferRole::Current:
                if (slot.current.size() <= planned.camera) slot.current.resize(planned.camera + 1);
                slot.current[planned.camera] = std::move(*buffer);
                break;
            case BufferRole::Next:
                slot.next = std::move(*buffer);
                break;
            case BufferRole::Previous:
                slot.previous = std::move(*buffer);
                break;
            case BufferRole::Pending:
                slot.pending = std::move(*buffer);
                break;
        }
    }
    return {};
}

Status Simulation::InitializeState() {
    if (!mScene.stages.Has(Stage::Ca)) return {};
    const CaInitParams init = MakeCaInitParams(mScene);
    CB_TRY(mBackend.CaInitialize(init, {&Out(Resource::Hum), &Out(Resource::Act), &Out(Resource::Cld)}));
    return {};
}

std::vector<uint64_t> Simulation::InputVersions(Stage stage, uint32_t step) const {
    std::vector<uint64_t> versions;
    const StageDescriptor& d = Describe(stage);
    for (Resource r : d.reads) versions.push_back(mSlots[size_t(r)].version);
    for (Resource r : d.optionalReads) versions.push_back(mSlots[size_t(r)].version);  // 0 when never written
    if (d.sunAt) {
        // The sun's direction at the step as the stage receives it (single precision): a stage re-runs when it
        // differs in any bit from the direction of its last run, and only then.
        const Vec3 s = d.sunAt(mScene, step);
        for (float c : s) versions.push_back(std::bit_cast<uint32_t>(c));
    }
    return versions;
}

bool Simulation::InputsChangedSinceLastRun(Stage stage, uint32_t step) const {
    if (const StageDescriptor& d = Describe(stage); d.dependsOnStep && d.dependsOnStep(mScene)) return true;
    const auto& last = mInputsAtLastRun[size_t(stage)];
    return !last || *last != InputVersions(stage, step);
}

namespace {

// Stamps unique in the process, so that no two simulations (nor one simulation's two input states) share one.
uint64_t NewInputsStamp() {
    static std::atomic<uint64_t> next{1};
    return next.fetch_add(1, std::memory_order_relaxed);
}

double MsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The step's submissions and host waits: the backend's counts since `before`.
void CountSubmissions(const SubmissionCounts& before, const SubmissionCounts& after, StepRecord& record) {
    record.submissions = after.submissions - before.submissions;
    record.hostWaits = after.hostWaits - before.hostWaits;
}

// Charges the step's time outside its frames to frame 0 (StepRecord::frameMs).
void ChargeRestToFirstFrame(StepRecord& record) {
    if (record.frameMs.empty()) return;
    double frames = 0;
    for (double ms : record.frameMs) frames += ms;
    record.frameMs[0] += std::max(0.0, record.stepMs - frames);
}

}  // namespace

TimingMode TimingOfStep(std::string_view choice, uint32_t step) {
    if (choice == "pipelined") return TimingMode::Pipelined;
    if (choice == "both") return step % 4 == 1 || step % 4 == 2 ? TimingMode::Pipelined : TimingMode::Synchronized;
    return TimingMode::Synchronized;
}

std::string_view TimingModeName(TimingMode mode) {
    return mode == TimingMode::Pipelined ? "pipelined" : "synchronized";
}

// An open batch: Close() ends it and gives each marked interval's device time
// to its owner; a scope left without Close() (a failed call, an exception)
// still ends the batch, and drops its times.
class Simulation::BatchScope {
  public:
    explicit BatchScope(Simulation& sim) : mSim(sim) {}
    ~BatchScope() {
        if (!mOpen) return;
        (void)mSim.mBackend.EndBatch();
        (void)mSim.mBackend.TakeDeferredResults();
        mSim.mMarks.clear();
        mSim.mBatchOpen = false;
    }
    BatchScope(const BatchScope&) = delete;
    BatchScope& operator=(const BatchScope&) = delete;

    Status Open(StepRecord& record) {
        if (mSim.mBatchOpen) return MakeError("the harness opened a batch inside a batch");
        CB_TRY(mSim.mBackend.BeginBatch());
        mOpen = mSim.mBatchOpen = true;
        ++record.batches;
        return {};
    }

    Status Close() {
        mOpen = mSim.mBatchOpen = false;
        std::vector<MarkOwner> marks = std::move(mSim.mMarks);
        mSim.mMarks.clear();
        auto times = mSim.mBackend.EndBatch();
        if (!times) return MakeError("ending a batch: " + times.error().message);
        CB_TRY(DeliverDeferredResults(marks));
        if (times->empty()) return {};  // no device clock
        // One time per MarkBatch(); a backend may also report the (empty) interval before the first mark.
        size_t first = 0;
        if (times->size() == marks.size() + 1) first = 1;
        if (times->size() - first != marks.size())
            return MakeError(mSim.mBackend.Name() + ": a batch of " + std::to_string(marks.size()) +
                             " marked calls returned " + std::to_string(times->size()) + " device times");
        for (size_t i = 0; i < marks.size(); ++i) {
            const MarkOwner& owner = marks[i];
            const double ms = (*times)[first + i];
            std::optional<double>& total = owner.record->deviceMs[size_t(owner.stage)];
            total = total.value_or(0) + ms;
            if (owner.frame && *owner.frame < owner.record->frames.size())
                owner.record->frames[*owner.frame].deviceMs = ms;
        }
        return {};
    }

  private:
    // The host results the backend deferred to the batch's end, to the records
    // their calls wrote: a cover adds to its record's (the calls left it as the
    // record had it; shares add up), splat counters replace their frame's.
    Status DeliverDeferredResults(const std::vector<MarkOwner>& marks) {
        for (const DeferredHostResult& result : mSim.mBackend.TakeDeferredResults()) {
            if (result.mark == 0 || result.mark > marks.size())
                return MakeError(mSim.mBackend.Name() + ": a deferred result names mark " +
                                 std::to_string(result.mark) + " of a batch of " + std::to_string(marks.size()));
            const MarkOwner& owner = marks[result.mark - 1];
            if (result.coveredColumns) {
                std::optional<uint32_t>& cover = owner.record->coveredColumns;
                cover = cover.value_or(0) + *result.coveredColumns;
                if (owner.record != &mSim.mAhead) mSim.mLastCoveredColumns = cover;
            }
            if (result.frameCounters && owner.frame && *owner.frame < owner.record->frames.size())
                owner.record->frames[*owner.frame].counters = *result.frameCounters;
        }
        return {};
    }

    Simulation& mSim;
    bool mOpen = false;
};

Status Simulation::Batched(StepRecord& record, const std::function<Status()>& work) {
    if (!Pipelined() || mBatchOpen) return work();
    BatchScope batch(*this);
    CB_TRY(batch.Open(record));
    CB_TRY(work());  // on failure the scope ends the batch
    return batch.Close();
}

void Simulation::AddCallTimes(Stage stage, const StageCallRecord& call, StepRecord& target, size_t firstFrame) {
    // A stage's (a renderer's: over its frames) time in a step is the sum over its calls.
    std::optional<double>& wall = Pipelined() ? target.hostMs[size_t(stage)] : target.stageMs[size_t(stage)];
    wall = wall.value_or(0) + call.ms;
    if (!Pipelined()) target.cpuMs[size_t(stage)] = target.cpuMs[size_t(stage)].value_or(0) + call.cpuMs;
    if (call.deviceMs) target.deviceMs[size_t(stage)] = target.deviceMs[size_t(stage)].value_or(0) + *call.deviceMs;
    for (const std::optional<size_t>& frame : call.marks) {
        std::optional<size_t> index;
        if (frame) index = firstFrame + *frame;
        mMarks.push_back({&target, stage, index});
    }
}

Status Simulation::RunStepStages(StepRecord& record, bool outputStep) {
    for (Stage stage : mSchedule) {
        const StageDescriptor& d = Describe(stage);
        if (d.advancesState || d.renderer || (d.outputStepsOnly && !outputStep)) continue;
        if (d.skipsUnchangedInputs && !InputsChangedSinceLastRun(stage, mStep)) {
            record.skippedUnchanged[size_t(stage)] = true;
            // Unchanged since step t-1: the renderer interpolates the current value with itself.
            for (Resource r : d.writes) mSlots[size_t(r)].previousIsCurrent = true;
            continue;
        }
        // Keep step t-1's values for the renderer before they are overwritten.
        for (Resource r : d.writes) {
            Slot& slot = mSlots[size_t(r)];
            if (slot.previous && mStep > 0) std::swap(slot.current[0], slot.previous);
            // No previous step yet: step 0 is interpolated with itself.
            slot.previousIsCurrent = mStep == 0;
        }
        CB_TRY(RunStage(stage, record));
        mInputsAtLastRun[size_t(stage)] = InputVersions(stage, mStep);
        for (Resource r : d.writes) ++mSlots[size_t(r)].version;
    }
    // A density stage that skipped (q unchanged) left the cover as it was.
    if (!record.coveredColumns) record.coveredColumns = mLastCoveredColumns;
    return {};
}

Status Simulation::RenderFrames(StepRecord& record, uint32_t frames, std::span<const FrameTasks> work) {
    for (uint32_t f = 0; f < frames; ++f) {
        const auto start = std::chrono::steady_clock::now();
        if (!work.empty()) record.frameWork.emplace_back();
        // Time-sliced and pipelined, each frame is one batch (in an unsliced step the step's batch is open).
        CB_TRY(Batched(record, [&]() -> Status {
            if (f < work.size()) CB_TRY(RunShares(work[f], record, &record.frameWork.back()));
            for (Stage stage : mSchedule)
                if (Describe(stage).renderer) CB_TRY(RunStage(stage, record, f, frames));
            return {};
        }));
        record.frameMs.push_back(MsSince(start));
        ++mFramesDrawn;
    }
    record.framesRendered = frames;
    return {};
}

Status Simulation::Step(StepRecord& record, const Observer& observe) {
    if (mScene.render.slicesPerFrame > 0) return SlicedStep(record, observe);
    const auto stepStart = std::chrono::steady_clock::now();
    const SubmissionCounts countsBefore = mBackend.Submissions();
    double observerMs = 0;
    record = StepRecord{};
    record.step = mStep;
    record.timing = mTiming;
    const bool outputStep = IsOutputStep(mStep);
    // Everything up to the observer: the stages, then the frames between steps t-1 and t (Fizimayer's thesis,
    // section 6.3), one per alpha of render.frames_per_step.
    auto beforeObserver = [&]() -> Status {
        CB_TRY(RunStepStages(record, outputStep));
        if (outputStep && RunsARenderer(mScene.stages)) CB_TRY(RenderFrames(record, std::max(mScene.render.framesPerStep, 1u), {}));
        return {};
    };
    // The state advances, and the host updates the ellipsoid list (inside the batch: it overlaps the device's work).
    auto afterObserver = [&]() -> Status {
        for (Stage stage : mSchedule) {
            const StageDescriptor& d = Describe(stage);
            if (!d.advancesState) continue;
            CB_TRY(RunStage(stage, record));
            for (Resource r : d.writes) {
                Slot& slot = mSlots[size_t(r)];
                std::swap(slot.current[0], slot.next);
                ++slot.version;
            }
        }
        if (mScene.stages.Has(Stage::Region)) {
            auto start = std::chrono::steady_clock::now();
            mEllipsoids.Update();
            record.ellipsoidUpdateMs = MsSince(start);
        }
        return {};
    };
    if (observe) {
        // The observer reads complete buffers: the batch ends before it and another holds the rest of the step.
        CB_TRY(Batched(record, beforeObserver));
        const auto start = std::chrono::steady_clock::now();
        CB_TRY(observe(*this));
        observerMs = MsSince(start);
        CB_TRY(Batched(record, afterObserver));
    } else {
        CB_TRY(Batched(record, [&]() -> Status {
            CB_TRY(beforeObserver());
            return afterObserver();
        }));
    }
    ++mStep;
    record.stepMs = MsSince(stepStart) - observerMs;
    ChargeRestToFirstFrame(record);
    CountSubmissions(countsBefore, mBackend.Submissions(), record);
    return {};
}

Status Simulation::SlicedStep(StepRecord& record, const Observer& observe) {
    const auto stepStart = std::chrono::steady_clock::now();
    const SubmissionCounts countsBefore = mBackend.Submissions();
    double observerMs = 0;
    record = StepRecord{};
    record.step = mStep;
    record.timing = mTiming;
    const bool outputStep = IsOutputStep(mStep);
    if (!mAheadComputed) {
        // Nothing was computed ahead of the first step, nor of the first step of a run resumed after the
        // last step of another (pipelined: one batch, before the frames'). That one first advances the state.
        CB_TRY(Batched(record, [&]() -> Status {
            if (mAdvanceOwed) CB_TRY(RunOwedAdvance(record));
            return RunStepStages(record, outputStep);
        }));
    } else {
        CommitAhead(record);
    }
    bool renders = false;
    for (Stage stage : mSchedule) renders |= Describe(stage).renderer && outputStep;
    // A step without frames (warm-up, or not a render step) computes the next one whole.
    std::vector<FrameTasks> work;
    mAheadComputed = mStep + 1 < mScene.steps;
    mAdvanceOwed = !mAheadComputed;
    if (mAheadComputed) work = PlanAhead(renders ? mScene.render.slicesPerFrame : UINT32_MAX);
    if (renders) {
        const uint32_t frames = std::max<uint32_t>(std::max(mScene.render.framesPerStep, 1u), uint32_t(work.size()));
        CB_TRY(RenderFrames(record, frames, work));
    } else if (!work.empty()) {
        // No frames to measure: the next step's work is one batch.
        CB_TRY(Batched(record, [&]() -> Status {
            for (const FrameTasks& tasks : work) CB_TRY(RunShares(tasks, record));
            return {};
        }));
    }
    if (observe) {
        const auto start = std::chrono::steady_clock::now();
        CB_TRY(observe(*this));
        observerMs = MsSince(start);
    }
    ++mStep;
    record.stepMs = MsSince(stepStart) - observerMs;
    ChargeRestToFirstFrame(record);
    CountSubmissions(countsBefore, mBackend.Submissions(), record);
    return {};
}

Status Simulation::RunOwedAdvance(StepRecord& record) {
    // What an unsliced step mStep-1 does after its observer: state_{t} -> state_{t+1} from R_{t}, then the list.
    for (Stage stage : mSchedule) {
        const StageDescriptor& d = Describe(stage);
        if (!d.advancesState) continue;
        StageCallRecord call;
        StageHostInputs host{mStep - 1, mRaster, 0, 0, {}, mBatchOpen};
        CB_TRY(CallStage(stage, mBackend, mScene, host, Buffers(), call));
        AddCallTimes(stage, call, record, record.frames.size());
        for (Resource r : d.writes) {
            Slot& slot = mSlots[size_t(r)];
            std::swap(slot.current[0], slot.next);
            ++slot.version;
        }
    }
    if (mScene.stages.Has(Stage::Region)) {
        const auto start = std::chrono::steady_clock::now();
        mEllipsoids.Update();
        record.ellipsoidUpdateMs += MsSince(start);
    }
    mAdvanceOwed = false;
    return {};
}

std::vector<Simulation::FrameTasks> Simulation::PlanAhead(uint32_t slicesPerFrame) {
    const uint32_t next = mStep + 1;
    std::vector<FrameTasks> frames;
    // One frame per share of `slicesPerFrame` slices; `first` (the list update) joins the stage's first frame.
    auto addShares = [&](Stage stage, uint32_t step, std::optional<ShareTask> first) {
        const StageDescriptor& d = Describe(stage);
        const uint32_t count = d.shareCount ? d.shareCount(mScene, step) : 1;
        const uint32_t size = d.shareCount ? slicesPerFrame : 1;
        for (uint32_t b = 0; b < count; b += std::min(size, count - b)) {
            FrameTasks tasks;
            if (b == 0 && first) tasks.push_back(*first);
            tasks.push_back({stage, d.shareCount ? SliceRange{b, b + std::min(size, count - b)} : SliceRange{}, count});
            frames.push_back(std::move(tasks));
        }
    };
    auto markAhead = [&](const StageDescriptor& d) {
        for (Resource r : d.writes) {
            mSlots[size_t(r)].ahead = true;
            ++mSlots[size_t(r)].version;
        }
    };
    // The state advances first (state_t -> state_t+1 from R_t), as at the end of an unsliced step.
    for (Stage stage : mSchedule)
        if (Describe(stage).advancesState) {
            addShares(stage, mStep, std::nullopt);
            markAhead(Describe(stage));
        }
    // Then step t+1's stages, each decided as an unsliced step t+1 would: versions count the writes planned so far.
    std::optional<ShareTask> listUpdate;
    if (mScene.stages.Has(Stage::Region)) listUpdate = ShareTask{};
    for (Stage stage : mSchedule) {
        const StageDescriptor& d = Describe(stage);
        if (d.advancesState || d.renderer || (d.outputStepsOnly && !IsOutputStep(next))) continue;
        if (d.skipsUnchangedInputs && !InputsChangedSinceLastRun(stage, next)) {
            mAhead.skippedUnchanged[size_t(stage)] = true;
            continue;
        }
        mInputsAtLastRun[size_t(stage)] = InputVersions(stage, next);
        markAhead(d);
        addShares(stage, next, stage == Stage::Region ? listUpdate : std::nullopt);
    }
    return frames;
}

Status Simulation::RunShares(const FrameTasks& tasks, StepRecord& record, std::string* describe) {
    for (const ShareTask& task : tasks) {
        if (!task.stage) {
            const auto start = std::chrono::steady_clock::now();
            mEllipsoids.Update();
            mRasterAhead = mEllipsoids.Raster();
            record.ellipsoidUpdateMs += MsSince(start);
            if (describe) *describe += (describe->empty() ? "" : ", ") + std::string("ellipsoid list");
            continue;
        }
        const Stage stage = *task.stage;
        const bool advances = Describe(stage).advancesState;
        // The automaton's share of step t is step t's work; the rest computes step t+1.
        const uint32_t step = advances ? mStep : mStep + 1;
        StageHostInputs host{step, mRasterAhead, 0, 0, task.slices, mBatchOpen};
        StageCallRecord call;
        CB_TRY(CallStage(stage, mBackend, mScene, host, advances ? Buffers() : AheadBuffers(), call));
        StepRecord& target = advances ? record : mAhead;
        AddCallTimes(stage, call, target, target.frames.size());
        // The shares of density count the covered columns of their rows of tiles.
        if (call.coveredColumns) target.coveredColumns = target.coveredColumns.value_or(0) + *call.coveredColumns;
        if (!describe) continue;
        char range[40] = "";
        if (!task.slices.IsWhole(task.shareCount))
            std::snprintf(range, sizeof range, " %u-%u", task.slices.begin, task.slices.End(task.shareCount) - 1);
        *describe += (describe->empty() ? "" : ", ") + std::string(StageName(stage)) + range;
    }
    return {};
}

void Simulation::CommitAhead(StepRecord& record) {
    for (Slot& slot : mSlots) {
        if (!slot.ahead) {
            // Not computed for this step (its writer skipped): unchanged since the step before.
            slot.previousIsCurrent = true;
            continue;
        }
        slot.ahead = false;
        slot.previousIsCurrent = false;
        if (slot.next) {
            std::swap(slot.current[0], slot.next);
        } else if (slot.previous) {  // previous <- current <- pending
            std::swap(slot.previous, slot.current[0]);
            std::swap(slot.current[0], slot.pending);
        } else {
            std::swap(slot.current[0], slot.pending);
        }
    }
    if (mScene.stages.Has(Stage::Region)) mRaster = mRasterAhead;
    record.stageMs = mAhead.stageMs;
    record.hostMs = mAhead.hostMs;
    record.cpuMs = mAhead.cpuMs;
    record.deviceMs = mAhead.deviceMs;
    record.skippedUnchanged = mAhead.skippedUnchanged;
    if (mAhead.coveredColumns) mLastCoveredColumns = mAhead.coveredColumns;
    record.coveredColumns = mLastCoveredColumns;
    mAhead = StepRecord{};
}

StageBuffers Simulation::Buffers() {
    StageBuffers buffers;
    for (Resource r : kAllResources) {
        Slot& slot = mSlots[size_t(r)];
        for (auto& b : slot.current) buffers.current[size_t(r)].push_back(b.get());
        buffers.previous[size_t(r)] = slot.PreviousValue();
        buffers.next[size_t(r)] = slot.next.get();
    }
    return buffers;
}

StageBuffers Simulation::AheadBuffers() {
    StageBuffers buffers = Buffers();
    for (Resource r : kAllResources) {
        Slot& slot = mSlots[size_t(r)];
        if (!slot.ahead || IsPerCamera(r)) continue;
        buffers.current[size_t(r)] = {slot.next ? slot.next.get() : slot.pending.get()};
    }
    return buffers;
}

Status Simulation::RunStage(Stage stage, StepRecord& record, uint32_t frame, uint32_t frames) {
    if (stage == Stage::Region) mRaster = mEllipsoids.Raster();
    StageCallRecord call;
    StageHostInputs host{mStep, mRaster, frame, frames, {}, mBatchOpen, mFramesDrawn};
    if (Describe(stage).renderer) {
        // A new stamp whenever a buffer it reads was written (or planned to be) since its last call.
        auto& [versions, stamp] = mRendererInputs[size_t(stage)];
        std::vector<uint64_t> now = InputVersions(stage, mStep);
        if (stamp == 0 || now != versions) versions = std::move(now), stamp = NewInputsStamp();
        host.inputsStamp = stamp;
    }
    CB_TRY(CallStage(stage, mBackend, mScene, host, Buffers(), call));
    AddCallTimes(stage, call, record, record.frames.size());
    if (call.coveredColumns) record.coveredColumns = mLastCoveredColumns = call.coveredColumns;
    for (FrameRecord& drawn : call.frames) record.frames.push_back(std::move(drawn));
    if (Describe(stage).renderer) mLastRendered = mStep;
    return {};
}

}  // namespace cb
