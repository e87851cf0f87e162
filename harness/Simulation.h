// Runs a scene's enabled stages on one backend, one step at a time. Only the
// buffers of enabled stages are allocated (SPEC 14).
//
// Step t, in order:
//   region   R_t from the ellipsoid list L_t
//   smooth   q_t from cld_t
//   density  D_t, occupancy and cover from q_t and cld_t
//   shade    T_t from q_t           } on output steps only, and shade only when
//   shadow   G_t from D_t           } q changed since it last ran
//   render   one image per camera from q_{t-1}, q_t (interpolated by alpha), T_t
//   (observer: everything above plus hum_t, act_t, cld_t is readable here)
//   ca       state_t -> state_{t+1} using R_t
//   host     L_{t+1} = update(L_t)
// Output steps: every step when dumping or when the scene does not render;
// otherwise the render steps (render.every_steps).
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <optional>

#include "core/Backend.h"
#include "core/Ellipsoids.h"
#include "core/Scene.h"

namespace cb {


// One rendered image.
struct FrameRecord {
    std::string camera;
    double ms = 0;
    SplatStats stats;
};

struct StepRecord {
    uint32_t step = 0;
    // Wall time of each stage in ms; empty for stages that did not run.
    std::array<std::optional<double>, kStageCount> stageMs{};
    // Device time of each stage in ms, where the backend measures it.
    std::array<std::optional<double>, kStageCount> deviceMs{};
    double ellipsoidUpdateMs = 0;           // host-side list update
    std::optional<uint32_t> coveredColumns;  // from the density stage
    std::vector<FrameRecord> frames;         // render_splat, one per camera
};

class Simulation {
  public:
    // Allocates the enabled stages' buffers and computes the initial state.
    // everyStepOutputs: shade, shadow and render on every step (for dumps).
    static Result<std::unique_ptr<Simulation>> Create(const Scene& scene, Backend& backend,
                                                      bool everyStepOutputs = false);

    using Observer = std::function<Status(const Simulation&)>;
    // Runs step CurrentStep() and advances to the next.
    Status Step(StepRecord& record, const Observer& observe = {});

    uint32_t CurrentStep() const { return mStep; }
    const Scene& GetScene() const { return mScene; }
    Backend& GetBackend() const { return mBackend; }

    // Buffers of the current step; nullptr when their stage is not enabled.
    const Buffer* Hum() const { return mHum[mCurrent].get(); }
    const Buffer* Act() const { return mAct[mCurrent].get(); }
    const Buffer* Cld() const { return mCld[mCurrent].get(); }
    const Buffer* Region() const { return mRegion.get(); }
    const Buffer* Q() const { return mQ.get(); }
    const Buffer* ColumnSum() const { return mColumnSum.get(); }
    const Buffer* Tiles() const { return mTiles.get(); }
    const Buffer* Bands() const { return mBands.get(); }
    const Buffer* T() const { return mT.get(); }
    // The previous step's q and band occupancy (render_splat only).
    const Buffer* QPrev() const { return mQPrev.get(); }
    const Buffer* TilesPrev() const { return mTilesPrev.get(); }
    const Buffer* BandsPrev() const { return mBandsPrev.get(); }
    const Buffer* Shadow() const { return mShadow.get(); }
    // The image of camera `n` (F32, extent (3, width, height)); valid after a render step.
    const Buffer* Image(size_t n) const { return n < mImages.size() ? mImages[n].get() : nullptr; }
    // The step whose images are in Image(); nullopt before the first render.
    std::optional<uint32_t> LastRenderedStep() const { return mLastRendered; }
    bool IsOutputStep(uint32_t step) const;
    // The ellipsoids the current step's region came from.
    const std::vector<RasterEllipsoid>& RasterList() const { return mRaster; }

  private:
    Simulation(const Scene& scene, Backend& backend, bool everyStepOutputs);
    Status RunLighting(StepRecord& record);

    const Scene mScene;
    Backend& mBackend;
    EllipsoidList mEllipsoids;
    std::vector<RasterEllipsoid> mRaster;  // the list step t's region was rasterised from
    uint32_t mStep = 0;
    int mCurrent = 0;  // which of the two automaton states is step t
    std::vector<int32_t> mShiftX, mShiftY;

    std::unique_ptr<Buffer> mHum[2], mAct[2], mCld[2];
    std::unique_ptr<Buffer> mRegion, mQ, mColumnSum, mTiles, mBands;
    // Previous step's q and occupancy, for interpolation and skipping (render only).
    std::unique_ptr<Buffer> mQPrev, mTilesPrev, mBandsPrev;
    std::unique_ptr<Buffer> mT, mShadow;
    std::vector<std::unique_ptr<Buffer>> mImages;
    const bool mEveryStepOutputs;
    bool mShadeCurrent = false;  // T matches the current q
    std::optional<uint32_t> mLastRendered;
};

}  // namespace cb
