#include "harness/Simulation.h"

#include <chrono>

#include "core/Random.h"
#include "harness/StageParams.h"

namespace cb {
namespace {

// Runs one stage call and records its wall time.
template <typename Fn>
Status Timed(StepRecord& record, Stage stage, const Backend& backend, Fn&& fn) {
    auto start = std::chrono::steady_clock::now();
    Status status = fn();
    std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
    record.stageMs[size_t(stage)] = elapsed.count();
    record.deviceMs[size_t(stage)] = backend.LastDeviceMs();
    if (!status) return MakeError(std::string(StageName(stage)) + ": " + status.error().message);
    return {};
}

}  // namespace

Simulation::Simulation(const Scene& scene, Backend& backend, bool everyStepOutputs)
    : mScene(scene),
      mBackend(backend),
      mPlan(PlanResources(scene)),
      mSchedule(ScheduleStages(scene.stages)),
      mEllipsoids(scene.ellipsoids, scene.grid.size),
      mEveryStepOutputs(everyStepOutputs) {}

bool Simulation::IsOutputStep(uint32_t step) const {
    if (mEveryStepOutputs || !mScene.stages.Has(Stage::RenderSplat)) return true;
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
    std::unique_ptr<Simulation> sim(new Simulation(scene, backend, everyStepOutputs));
    CB_TRY(sim->Allocate());
    CB_TRY(sim->InitializeState());
    return sim;
}

Status Simulation::Allocate() {
    auto make = [&](std::unique_ptr<Buffer>& slot, Resource r) -> Status {
        auto buffer = mBackend.CreateBuffer(ResourceFormat(r), ResourceExtent(r, mScene));
        if (!buffer) return std::unexpected(buffer.error());
        slot = std::move(*buffer);
        return {};
    };
    for (Resource r : kAllResources) {
        const size_t i = size_t(r);
        if (!mPlan.used[i]) continue;
        Slot& slot = mSlots[i];
        slot.current.resize(IsPerCamera(r) ? mScene.render.cameras.size() : 1);
        for (auto& buffer : slot.current) CB_TRY(make(buffer, r));
        if (mPlan.doubleBuffered[i]) CB_TRY(make(slot.next, r));
        if (mPlan.previous[i]) CB_TRY(make(slot.previous, r));
    }
    return {};
}

Status Simulation::InitializeState() {
    if (!mScene.stages.Has(Stage::Ca)) return {};
    const CaInitParams init = MakeCaInitParams(mScene);
    CB_TRY(mBackend.CaInitialize(init, {&Out(Resource::Hum), &Out(Resource::Act), &Out(Resource::Cld)}));
    if (mScene.ca.HasWind()) {
        for (const SliceShift& s : mScene.ca.windShift) {
            mShiftX.push_back(s.sx);
            mShiftY.push_back(s.sy);
        }
    }
    return {};
}

std::vector<uint64_t> Simulation::InputVersions(Stage stage) const {
    std::vector<uint64_t> versions;
    for (Resource r : Describe(stage).reads) versions.push_back(mSlots[size_t(r)].version);
    return versions;
}

bool Simulation::InputsChangedSinceLastRun(Stage stage) const {
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

Status Simulation::RunStage(Stage stage, StepRecord& record) {
    const Scene& sc = mScene;
    auto timed = [&](auto&& call) { return Timed(record, stage, mBackend, call); };
    switch (stage) {
        case Stage::Region:
            mRaster = mEllipsoids.Raster();
            return timed([&] { return mBackend.Region(mRaster, Out(Resource::Region)); });
        case Stage::Ca: {
            CaStepParams params = MakeCaStepParams(sc, mStep);
            params.shiftX = mShiftX;
            params.shiftY = mShiftY;
            return timed([&] {
                return mBackend.CaStep(params, {&In(Resource::Hum), &In(Resource::Act), &In(Resource::Cld)},
                                       In(Resource::Region),
                                       {&Next(Resource::Hum), &Next(Resource::Act), &Next(Resource::Cld)});
            });
        }
        case Stage::Smooth:
            return timed([&] { return mBackend.Smooth(sc.smooth.radius, In(Resource::Cld), Out(Resource::Q)); });
        case Stage::Density: {
            DensityOutputs out{&Out(Resource::ColumnSum), &Out(Resource::Tiles), &Out(Resource::Bands), 0};
            const DensityParams params = MakeDensityParams(sc);
            CB_TRY(timed([&] { return mBackend.Density(params, In(Resource::Q), Get(Resource::Cld), out); }));
            record.coveredColumns = out.coveredColumns;
            return {};
        }
        case Stage::Shade: {
            const ShadeParams p = MakeShadeParams(sc);
            return timed([&] { return mBackend.Shade(p, In(Resource::Q), Out(Resource::T)); });
        }
        case Stage::Shadow: {
            const ShadowParams p = MakeShadowParams(sc);
            return timed([&] { return mBackend.Shadow(p, In(Resource::ColumnSum), Out(Resource::Shadow)); });
        }
        case Stage::RenderSplat:
            return RenderSplatFrames(record);
        case Stage::Noise: {
            const NoiseParams p{mStep};
            return timed([&] { return mBackend.Noise(p, Out(Resource::Q)); });
        }
        case Stage::RenderMarch:
            break;
    }
    return MakeError("the simulation cannot run stage '" + std::string(StageName(stage)) + "' yet");
}

Status Simulation::RenderSplatFrames(StepRecord& record) {
    const Scene& sc = mScene;
    double total = 0;
    std::optional<double> deviceTotal;
    for (size_t n = 0; n < sc.render.cameras.size(); ++n) {
        SplatParams p = MakeSplatParams(sc, sc.render.cameras[n]);
        // The order is host work shared by all backends, outside the stage time.
        const SplatOrder order = MakeSplatOrder(p.camera, sc.grid.size, sc.grid.origin, sc.grid.voxelSize);
        p.order = &order;
        const SplatInputs in{Previous(Resource::Q),     Get(Resource::Q),     Get(Resource::T),
                             Previous(Resource::Tiles), Get(Resource::Tiles), Previous(Resource::Bands),
                             Get(Resource::Bands)};
        FrameRecord frame;
        frame.camera = sc.render.cameras[n].name;
        auto start = std::chrono::steady_clock::now();
        Status status = mBackend.RenderSplat(p, in, Out(Resource::SplatImage, n), &frame.stats);
        frame.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (!status) return MakeError("render_splat (" + frame.camera + "): " + status.error().message);
        total += frame.ms;
        if (auto device = mBackend.LastDeviceMs()) deviceTotal = deviceTotal.value_or(0) + *device;
        record.frames.push_back(frame);
    }
    record.stageMs[size_t(Stage::RenderSplat)] = total;
    record.deviceMs[size_t(Stage::RenderSplat)] = deviceTotal;
    mLastRendered = mStep;
    return {};
}

}  // namespace cb
