#include "harness/Simulation.h"

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
    for (Resource r : Describe(stage).reads) versions.push_back(mSlots[size_t(r)].version);
    return versions;
}

bool Simulation::InputsChangedSinceLastRun(Stage stage) const {
    if (const StageDescriptor& d = Describe(stage); d.dependsOnStep && d.dependsOnStep(mScene)) return true;
    const auto& last = mInputsAtLastRun[size_t(stage)];
    return !last || *last != InputVersions(stage);
}

Status Simulation::Step(StepRecord& record, const Observer& observe) {
    record = StepRecord{};
    record.step = mStep;
    const bool outputStep = IsOutputStep(mStep);

    for (Stage stage : mSchedule) {
        const StageDescriptor& d = Describe(stage);
        if (d.advancesState || (d.outputStepsOnly && !outputStep)) continue;
        if (d.skipsUnchangedInputs && !InputsChangedSinceLastRun(stage)) continue;
        // Keep step t-1's values for the renderer before they are overwritten.
        for (Resource r : d.writes) {
            Slot& slot = mSlots[size_t(r)];
            if (slot.previous && mStep > 0) std::swap(slot.current[0], slot.previous);
        }
        CB_TRY(RunStage(stage, record));
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
    if (observe) CB_TRY(observe(*this));

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

Status Simulation::RunStage(Stage stage, StepRecord& record) {
    if (stage == Stage::Region) mRaster = mEllipsoids.Raster();
    StageCallRecord call;
    CB_TRY(CallStage(stage, mBackend, mScene, {mStep, mRaster}, Buffers(), call));
    record.stageMs[size_t(stage)] = call.ms;
    record.deviceMs[size_t(stage)] = call.deviceMs;
    if (call.coveredColumns) record.coveredColumns = call.coveredColumns;
    for (FrameRecord& frame : call.frames) record.frames.push_back(std::move(frame));
    if (Describe(stage).renderer) mLastRendered = mStep;
    return {};
}

}  // namespace cb
