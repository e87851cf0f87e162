#include "harness/Simulation.h"

#include <algorithm>
#include <bit>
#include <chrono>

#include "core/MemoryPlan.h"
#include "harness/StageParams.h"

namespace cb {

Simulation::Simulation(const Scene& scene, Backend& backend, bool everyStepOutputs)
    : mScene(scene),
      mBackend(backend),
      mSchedule(ScheduleStages(scene.stages)),
      mEllipsoids(scene.ellipsoids, scene.grid.size),
      mEveryStepOutputs(everyStepOutputs) {}

bool Simulation::IsOutputStep(uint32_t step) const {
    bool renders = false;
    for (Stage stage : mSchedule) renders |= Describe(stage).renderer;
    if (mEveryStepOutputs || !renders) return true;
    if (step + 1 == mScene.steps) return true;
    const uint32_t every = mScene.render.everySteps;
    return every > 0 && step >= mScene.warmupSteps && (step - mScene.warmupSteps) % every == 0;
}

const Buffer* Simulation::Get(Resource resource, size_t n) const {
    const Slot& slot = mSlots[size_t(resource)];
    return n < slot.current.size() ? slot.current[n].get() : nullptr;
}

const Buffer* Simulation::Previous(Resource resource) const { return mSlots[size_t(resource)].previous.get(); }

Buffer& Simulation::Out(Resource resource, size_t n) { return *mSlots[size_t(resource)].current.at(n); }

Result<std::unique_ptr<Simulation>> Simulation::Create(const Scene& scene, Backend& backend, bool everyStepOutputs) {
    for (Stage stage : kAllStages) {
        if (scene.stages.Has(stage) && !backend.Supports(stage))
            return MakeError(backend.Name() + " does not implement stage '" + std::string(StageName(stage)) + "' yet");
    }
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

std::vector<uint64_t> Simulation::InputVersions(Stage stage) const {
    std::vector<uint64_t> versions;
    const StageDescriptor& d = Describe(stage);
    for (Resource r : d.reads) versions.push_back(mSlots[size_t(r)].version);
    for (Resource r : d.optionalReads) versions.push_back(mSlots[size_t(r)].version);  // 0 when never written
    if (d.readsSun) {
        // The sun's direction at this step as the stage receives it (single precision): a stage re-runs when it
        // differs in any bit from the direction of its last run, and only then.
        const Vec3 s = mScene.sun.DirectionAt(mStep);
        for (float c : s) versions.push_back(std::bit_cast<uint32_t>(c));
    }
    return versions;
}

bool Simulation::InputsChangedSinceLastRun(Stage stage) const {
    if (const StageDescriptor& d = Describe(stage); d.dependsOnStep && d.dependsOnStep(mScene)) return true;
    const auto& last = mInputsAtLastRun[size_t(stage)];
    return !last || *last != InputVersions(stage);
}

Status Simulation::Step(StepRecord& record, const Observer& observe) {
    const auto stepStart = std::chrono::steady_clock::now();
    double observerMs = 0;
    record = StepRecord{};
    record.step = mStep;
    const bool outputStep = IsOutputStep(mStep);

    for (Stage stage : mSchedule) {
        const StageDescriptor& d = Describe(stage);
        if (d.advancesState || (d.outputStepsOnly && !outputStep)) continue;
        if (d.skipsUnchangedInputs && !InputsChangedSinceLastRun(stage)) {
            record.skippedUnchanged[size_t(stage)] = true;
            continue;
        }
        // Keep step t-1's values for the renderer before they are overwritten.
        for (Resource r : d.writes) {
            Slot& slot = mSlots[size_t(r)];
            if (slot.previous && mStep > 0) std::swap(slot.current[0], slot.previous);
        }
        if (d.renderer) {
            // The frames between steps t-1 and t (seed 000 section 6.3): one per alpha of render.frames_per_step.
            const uint32_t frames = std::max(mScene.render.framesPerStep, 1u);
            for (uint32_t f = 0; f < frames; ++f) CB_TRY(RunStage(stage, record, f));
            record.framesRendered = frames;
        } else {
            CB_TRY(RunStage(stage, record));
        }
        mInputsAtLastRun[size_t(stage)] = InputVersions(stage);
        for (Resource r : d.writes) {
            Slot& slot = mSlots[size_t(r)];
            ++slot.version;
            if (slot.previous && mStep == 0) {
                // No previous step yet: interpolate between step 0 and itself.
                std::vector<std::byte> copy(slot.previous->CanonicalBytes());
                CB_TRY(mBackend.Download(*slot.current[0], copy));
                CB_TRY(mBackend.Upload(*slot.previous, copy));
            }
        }
    }
    // A density stage that skipped (q unchanged) left the cover as it was.
    if (!record.coveredColumns) record.coveredColumns = mLastCoveredColumns;
    if (observe) {
        const auto start = std::chrono::steady_clock::now();
        CB_TRY(observe(*this));
        observerMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }

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
        record.ellipsoidUpdateMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    ++mStep;
    record.stepMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - stepStart).count() - observerMs;
    return {};
}

StageBuffers Simulation::Buffers() {
    StageBuffers buffers;
    for (Resource r : kAllResources) {
        Slot& slot = mSlots[size_t(r)];
        for (auto& b : slot.current) buffers.current[size_t(r)].push_back(b.get());
        buffers.previous[size_t(r)] = slot.previous.get();
        buffers.next[size_t(r)] = slot.next.get();
    }
    return buffers;
}

Status Simulation::RunStage(Stage stage, StepRecord& record, uint32_t frame) {
    if (stage == Stage::Region) mRaster = mEllipsoids.Raster();
    StageCallRecord call;
    CB_TRY(CallStage(stage, mBackend, mScene, {mStep, mRaster, frame}, Buffers(), call));
    // A renderer's time in a step is the sum over its frames.
    auto add = [](std::optional<double>& total, const std::optional<double>& part) {
        if (part) total = total.value_or(0) + *part;
    };
    if (frame == 0) record.stageMs[size_t(stage)].reset(), record.deviceMs[size_t(stage)].reset();
    add(record.stageMs[size_t(stage)], call.ms);
    add(record.deviceMs[size_t(stage)], call.deviceMs);
    if (call.coveredColumns) record.coveredColumns = mLastCoveredColumns = call.coveredColumns;
    for (FrameRecord& drawn : call.frames) record.frames.push_back(std::move(drawn));
    if (Describe(stage).renderer) mLastRendered = mStep;
    return {};
}

}  // namespace cb
