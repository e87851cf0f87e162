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
    : mScene(scene), mBackend(backend), mEllipsoids(scene.ellipsoids, scene.grid.size),
      mEveryStepOutputs(everyStepOutputs) {}

bool Simulation::IsOutputStep(uint32_t step) const {
    if (mEveryStepOutputs || !mScene.stages.Has(Stage::RenderSplat)) return true;
    if (step + 1 == mScene.steps) return true;
    const uint32_t every = mScene.render.everySteps;
    return every > 0 && step >= mScene.warmupSteps && (step - mScene.warmupSteps) % every == 0;
}

Result<std::unique_ptr<Simulation>> Simulation::Create(const Scene& scene, Backend& backend, bool everyStepOutputs) {
    for (Stage stage : kAllStages) {
        if (scene.stages.Has(stage) && !backend.Supports(stage))
            return MakeError(backend.Name() + " does not implement stage '" + std::string(StageName(stage)) + "' yet");
    }
    std::unique_ptr<Simulation> sim(new Simulation(scene, backend, everyStepOutputs));
    const Extent3 grid = scene.grid.size;
    auto make = [&](std::unique_ptr<Buffer>& slot, BufferFormat format, Extent3 extent) -> Status {
        auto buffer = backend.CreateBuffer(format, extent);
        if (!buffer) return std::unexpected(buffer.error());
        slot = std::move(*buffer);
        return {};
    };
    const StageSet& stages = scene.stages;
    if (stages.Has(Stage::Region)) CB_TRY(make(sim->mRegion, BufferFormat::U8, grid));
    if (stages.Has(Stage::Ca)) {
        // Two states: step t is read while step t+1 is written.
        for (int s = 0; s < 2; ++s) {
            CB_TRY(make(sim->mHum[s], BufferFormat::Bits, grid));
            CB_TRY(make(sim->mAct[s], BufferFormat::Bits, grid));
            CB_TRY(make(sim->mCld[s], BufferFormat::Bits, grid));
        }
        CaInitParams init{scene.ca.seed, QuantizeProbability(scene.ca.hum0), QuantizeProbability(scene.ca.act0)};
        CB_TRY(backend.CaInitialize(init, {sim->mHum[0].get(), sim->mAct[0].get(), sim->mCld[0].get()}));
        if (scene.ca.HasWind()) {
            for (const SliceShift& s : scene.ca.windShift) {
                sim->mShiftX.push_back(s.sx);
                sim->mShiftY.push_back(s.sy);
            }
        }
    }
    if (stages.Has(Stage::Smooth)) CB_TRY(make(sim->mQ, BufferFormat::F32, grid));
    if (stages.Has(Stage::Density)) {
        const uint32_t T = scene.density.tile, B = scene.density.band;
        const Extent3 tiles{CeilDiv(grid.nx, T), CeilDiv(grid.ny, T), 1};
        CB_TRY(make(sim->mColumnSum, BufferFormat::F32, {grid.nx, grid.ny, 1}));
        CB_TRY(make(sim->mTiles, BufferFormat::U8, tiles));
        CB_TRY(make(sim->mBands, BufferFormat::U8, {tiles.nx, tiles.ny, CeilDiv(grid.nz, B)}));
        if (stages.Has(Stage::RenderSplat) && scene.render.skipping) {
            CB_TRY(make(sim->mTilesPrev, BufferFormat::U8, tiles));
            CB_TRY(make(sim->mBandsPrev, BufferFormat::U8, {tiles.nx, tiles.ny, CeilDiv(grid.nz, B)}));
        }
    }
    if (stages.Has(Stage::Shade)) CB_TRY(make(sim->mT, BufferFormat::F32, grid));
    if (stages.Has(Stage::Shadow)) CB_TRY(make(sim->mShadow, BufferFormat::F32, {grid.nx, grid.ny, 1}));
    if (stages.Has(Stage::RenderSplat)) {
        CB_TRY(make(sim->mQPrev, BufferFormat::F32, grid));
        for (size_t n = 0; n < scene.render.cameras.size(); ++n) {
            sim->mImages.emplace_back();
            CB_TRY(make(sim->mImages.back(), BufferFormat::F32, {3, scene.render.width, scene.render.height}));
        }
    }
    return sim;
}

Status Simulation::Step(StepRecord& record, const Observer& observe) {
    record = StepRecord{};
    record.step = mStep;
    const StageSet& stages = mScene.stages;
    const int cur = mCurrent, next = 1 - mCurrent;

    if (stages.Has(Stage::Region)) {
        mRaster = mEllipsoids.Raster();
        CB_TRY(Timed(record, Stage::Region, mBackend, [&] { return mBackend.Region(mRaster, *mRegion); }));
    }
    // Keep step t-1's q and occupancy for the renderer (the first step has none: it uses its own).
    if (mQPrev && mStep > 0) std::swap(mQ, mQPrev);
    if (mTilesPrev && mStep > 0) {
        std::swap(mTiles, mTilesPrev);
        std::swap(mBands, mBandsPrev);
    }
    if (stages.Has(Stage::Smooth)) {
        CB_TRY(Timed(record, Stage::Smooth, mBackend, [&] { return mBackend.Smooth(mScene.smooth.radius, *mCld[cur], *mQ); }));
        mShadeCurrent = false;
    }
    if (stages.Has(Stage::Density)) {
        DensityOutputs out{mColumnSum.get(), mTiles.get(), mBands.get(), 0};
        DensityParams params{mScene.density.tile, mScene.density.band};
        CB_TRY(Timed(record, Stage::Density, mBackend, [&] { return mBackend.Density(params, *mQ, *mCld[cur], out); }));
        record.coveredColumns = out.coveredColumns;
    }
    if (mStep == 0 && mQPrev) {
        // No previous step yet: interpolate between q_0 and itself.
        std::vector<std::byte> copy(mQ->CanonicalBytes());
        CB_TRY(mBackend.Download(*mQ, copy));
        CB_TRY(mBackend.Upload(*mQPrev, copy));
        if (mTilesPrev) {
            copy.resize(mTiles->CanonicalBytes());
            CB_TRY(mBackend.Download(*mTiles, copy));
            CB_TRY(mBackend.Upload(*mTilesPrev, copy));
            copy.resize(mBands->CanonicalBytes());
            CB_TRY(mBackend.Download(*mBands, copy));
            CB_TRY(mBackend.Upload(*mBandsPrev, copy));
        }
    }
    if (IsOutputStep(mStep)) CB_TRY(RunLighting(record));
    if (observe) CB_TRY(observe(*this));

    if (stages.Has(Stage::Ca)) {
        CaStepParams params;
        params.seed = mScene.ca.seed;
        params.step = mStep;
        params.qExt = QuantizeProbability(mScene.ca.pExt);
        params.qHum = QuantizeProbability(mScene.ca.pHum);
        params.qAct = QuantizeProbability(mScene.ca.pAct);
        params.shiftX = mShiftX;
        params.shiftY = mShiftY;
        CB_TRY(Timed(record, Stage::Ca, mBackend, [&] {
            return mBackend.CaStep(params, {mHum[cur].get(), mAct[cur].get(), mCld[cur].get()}, *mRegion,
                                   {mHum[next].get(), mAct[next].get(), mCld[next].get()});
        }));
        mCurrent = next;
    }
    if (stages.Has(Stage::Region)) {
        auto start = std::chrono::steady_clock::now();
        mEllipsoids.Update();
        record.ellipsoidUpdateMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    ++mStep;
    return {};
}

Status Simulation::RunLighting(StepRecord& record) {
    const Scene& sc = mScene;
    if (sc.stages.Has(Stage::Shade) && !mShadeCurrent) {
        const ShadeParams p = MakeShadeParams(sc);
        CB_TRY(Timed(record, Stage::Shade, mBackend, [&] { return mBackend.Shade(p, *mQ, *mT); }));
        mShadeCurrent = true;
    }
    if (sc.stages.Has(Stage::Shadow)) {
        const ShadowParams p = MakeShadowParams(sc);
        CB_TRY(Timed(record, Stage::Shadow, mBackend, [&] { return mBackend.Shadow(p, *mColumnSum, *mShadow); }));
    }
    if (sc.stages.Has(Stage::RenderSplat)) {
        double total = 0;
        std::optional<double> deviceTotal;
        for (size_t n = 0; n < sc.render.cameras.size(); ++n) {
            SplatParams p = MakeSplatParams(sc, sc.render.cameras[n]);
            // The order is host work shared by all backends, outside the stage time.
            const SplatOrder order = MakeSplatOrder(p.camera, sc.grid.size, sc.grid.origin, sc.grid.voxelSize);
            p.order = &order;
            SplatInputs in{mQPrev.get(), mQ.get(), mT.get(), mTilesPrev.get(), mTiles.get(), mBandsPrev.get(), mBands.get()};
            FrameRecord frame;
            frame.camera = sc.render.cameras[n].name;
            auto start = std::chrono::steady_clock::now();
            Status status = mBackend.RenderSplat(p, in, *mImages[n], &frame.stats);
            frame.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            if (!status) return MakeError("render_splat (" + frame.camera + "): " + status.error().message);
            total += frame.ms;
            if (auto device = mBackend.LastDeviceMs()) deviceTotal = deviceTotal.value_or(0) + *device;
            record.frames.push_back(frame);
        }
        record.stageMs[size_t(Stage::RenderSplat)] = total;
        record.deviceMs[size_t(Stage::RenderSplat)] = deviceTotal;
        mLastRendered = mStep;
    }
    return {};
}

}  // namespace cb
