#include "harness/Simulation.h"

#include <chrono>

#include "core/Random.h"

namespace cb {
namespace {

// Runs one stage call and records its wall time.
template <typename Fn>
Status Timed(StepRecord& record, Stage stage, Fn&& fn) {
    auto start = std::chrono::steady_clock::now();
    Status status = fn();
    std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
    record.stageMs[size_t(stage)] = elapsed.count();
    if (!status) return MakeError(std::string(StageName(stage)) + ": " + status.error().message);
    return {};
}

}  // namespace

Simulation::Simulation(const Scene& scene, Backend& backend)
    : mScene(scene), mBackend(backend), mEllipsoids(scene.ellipsoids, scene.grid.size) {}

Result<std::unique_ptr<Simulation>> Simulation::Create(const Scene& scene, Backend& backend) {
    for (Stage stage : kAllStages) {
        if (scene.stages.Has(stage) && !backend.Supports(stage))
            return MakeError(backend.Name() + " does not implement stage '" + std::string(StageName(stage)) + "' yet");
    }
    std::unique_ptr<Simulation> sim(new Simulation(scene, backend));
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
    }
    return sim;
}

Status Simulation::Step(StepRecord& record, const Observer& observe) {
    record = StepRecord{};
    record.step = mStep;
    const StageSet& stages = mScene.stages;
    const int cur = mCurrent, next = 1 - mCurrent;

    if (stages.Has(Stage::Region)) {
        std::vector<RasterEllipsoid> raster = mEllipsoids.Raster();
        CB_TRY(Timed(record, Stage::Region, [&] { return mBackend.Region(raster, *mRegion); }));
    }
    if (stages.Has(Stage::Smooth)) {
        CB_TRY(Timed(record, Stage::Smooth, [&] { return mBackend.Smooth(mScene.smooth.radius, *mCld[cur], *mQ); }));
    }
    if (stages.Has(Stage::Density)) {
        DensityOutputs out{mColumnSum.get(), mTiles.get(), mBands.get(), 0};
        DensityParams params{mScene.density.tile, mScene.density.band};
        CB_TRY(Timed(record, Stage::Density, [&] { return mBackend.Density(params, *mQ, *mCld[cur], out); }));
        record.coveredColumns = out.coveredColumns;
    }
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
        CB_TRY(Timed(record, Stage::Ca, [&] {
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

}  // namespace cb
