// Pipelined timing (core/pipeline/Backend.h, "Pipelined timing") on every GPU
// backend (PipelinedGpu, over test::GpuTestBackends()): a step's stage calls
// recorded in one batch give the bytes and host values of the same calls made
// one by one (a host value comes back from its call or, deferred, after
// EndBatch with its call's mark, never both); the batch submits once and waits
// once, plus one of each per Download; EndBatch gives a device time per
// interval; batches do not nest. Then what only Vulkan does (PipelinedVk): an
// Upload in a batch is ordered with the recorded calls, a batch outgrows its
// timestamps, a scratch slot grows under recorded work. The Khronos validation
// layer is on (BackendTest) and must stay silent. What only gl does:
// PipelinedGLTest.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/math/Camera.h"
#include "core/math/Random.h"
#include "core/math/Splat.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"
#include "tests/BackendTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

constexpr Extent3 kPipeGrid{40, 36, 12};
constexpr uint32_t kPipeTile = 8, kPipeBand = 4;

std::vector<float> PipeQ(const Extent3& e, uint32_t seed) {
    Pcg32 rng(seed);
    std::vector<float> q(e.Count());
    for (size_t v = 0; v < q.size(); ++v) q[v] = (v / 53) % 3 == 0 ? float(rng.Below(65)) / 64.0f : 0.0f;
    return q;
}

SubmissionCounts operator-(const SubmissionCounts& a, const SubmissionCounts& b) {
    return {a.submissions - b.submissions, a.hostWaits - b.hostWaits};
}

class PipelinedGpu : public test::BackendTest {
  protected:
    void SetUp() override {
        test::BackendTest::SetUp();
        if (IsSkipped() || HasFatalFailure()) return;
        Backend& b = *mBackend;
        const Extent3 e = kPipeGrid, plane{e.nx, e.ny, 1};
        const Extent3 tiles{CeilDiv(e.nx, kPipeTile), CeilDiv(e.ny, kPipeTile), 1};
        const Extent3 bands{tiles.nx, tiles.ny, CeilDiv(e.nz, kPipeBand)};
        mEllipsoids = test::RandomEllipsoids(e, 5);
        mHum = test::MakeFilled(b, BufferFormat::Bits, e, test::RandomBits(e, 1, 2));
        mAct = test::MakeFilled(b, BufferFormat::Bits, e, test::RandomBits(e, 2, 3));
        mCld = test::MakeFilled(b, BufferFormat::Bits, e, test::RandomBits(e, 3, 3));
        mQPrev = test::MakeFilled(b, BufferFormat::F32, e, PipeQ(e, 4));
        mTilesPrev = test::MakeBuffer(b, BufferFormat::U8, tiles);
        mBandsPrev = test::MakeBuffer(b, BufferFormat::U8, bands);
        auto dPrev = test::MakeBuffer(b, BufferFormat::F32, plane);
        DensityOutputs prev{dPrev.get(), mTilesPrev.get(), mBandsPrev.get()};
        ASSERT_TRUE(b.Density({kPipeTile, kPipeBand, {}}, *mQPrev, nullptr, prev).has_value());
        mRegion = test::MakeBuffer(b, BufferFormat::U8, e);
        mHum1 = test::MakeBuffer(b, BufferFormat::Bits, e);
        mAct1 = test::MakeBuffer(b, BufferFormat::Bits, e);
        mCld1 = test::MakeBuffer(b, BufferFormat::Bits, e);
        mQ = test::MakeBuffer(b, BufferFormat::F32, e);
        mT = test::MakeBuffer(b, BufferFormat::F32, e);
        mD = test::MakeBuffer(b, BufferFormat::F32, plane);
        mTiles = test::MakeBuffer(b, BufferFormat::U8, tiles);
        mBands = test::MakeBuffer(b, BufferFormat::U8, bands);
        mG = test::MakeBuffer(b, BufferFormat::F32, plane);
        const std::vector<float> halves(plane.Count(), 0.5f);
        ASSERT_TRUE(b.Upload(*mD, std::as_bytes(std::span(halves))).has_value());
        mImage = test::MakeBuffer(b, BufferFormat::F32, {3, kW, kH});
        const float h = 50;
        CameraSettings camera;
        camera.eye = {-e.nx * h / 2.0, -e.ny * h / 2.0, e.nz * h * 1.5};
        camera.target = {e.nx * h / 2.0, e.ny * h / 2.0, e.nz * h / 2.0};
        mSplat.camera = MakeCameraFrame(camera, kW, kH);
        mOrder = MakeSplatOrder(mSplat.camera, e, {0, 0, 0}, h);
        mSplat.order = &mOrder;
        mSplat.voxelSize = h;
        mSplat.splatDiameter = 1.5f * h;
        mSplat.sun = SunDirection(0.5, 0.8);
        mSplat.background = {0.4f, 0.5f, 0.8f};
        mSplat.tile = kPipeTile;
        mSplat.band = kPipeBand;
        mSplat.ground = {true, {0.4f, 0.35f, 0.3f}};
    }

    std::vector<Buffer*> Outputs() {
        return {mRegion.get(), mHum1.get(),  mAct1.get(),  mCld1.get(), mQ.get(),    mT.get(),
                mD.get(),      mTiles.get(), mBands.get(), mG.get(),    mImage.get()};
    }
    // Every output filled with a pattern no stage writes in full (0xA5 bytes; 1 bits).
    void Pattern() {
        for (Buffer* out : Outputs()) {
            std::vector<std::byte> bytes(out->CanonicalBytes(),
                                         std::byte(out->Format() == BufferFormat::Bits ? 1 : 0xA5));
            ASSERT_TRUE(mBackend->Upload(*out, bytes).has_value());
        }
    }
    std::vector<std::vector<std::byte>> Read() {
        std::vector<std::vector<std::byte>> bytes;
        for (Buffer* out : Outputs()) bytes.push_back(test::Read<std::byte>(*mBackend, *out));
        return bytes;
    }

    ShadeParams Shade() const {
        ShadeParams p;
        p.sun = SunDirection(0.6, 0.4);
        p.sigma = 0.01f;
        return p;
    }
    ShadowParams Shadow() const {
        ShadowParams p;
        p.sun = SunDirection(0.6, 0.4);
        p.nz = kPipeGrid.nz;
        return p;
    }

    // One step: region, ca, smooth, shade, [density], shadow, [render_splat],
    // with MarkBatch before each call after the first. Failures are test failures.
    void Step(bool density, bool render, uint32_t* cover = nullptr, SplatStats* stats = nullptr) {
        Backend& b = *mBackend;
        auto ok = [](const Status& s, const char* what) {
            EXPECT_TRUE(s.has_value()) << what << ": " << (s ? "" : s.error().message);
        };
        ok(b.Region(mEllipsoids, *mRegion), "region");
        b.MarkBatch();
        CaStepParams ca;
        ca.seed = 7, ca.step = 2;
        ca.qExt = 0x10000000u, ca.qHum = 0x30000000u, ca.qAct = 0x40000000u;
        ok(b.CaStep(ca, {mHum.get(), mAct.get(), mCld.get()}, *mRegion, {mHum1.get(), mAct1.get(), mCld1.get()}), "ca");
        b.MarkBatch();
        ok(b.Smooth(1, *mCld1, *mQ), "smooth");
        b.MarkBatch();
        ok(b.Shade(Shade(), *mQ, *mT), "shade");
        if (density) {
            b.MarkBatch();
            DensityOutputs out{mD.get(), mTiles.get(), mBands.get()};
            ok(b.Density({kPipeTile, kPipeBand, {}}, *mQ, mCld1.get(), out), "density");
            if (cover) *cover = out.coveredColumns;
        }
        b.MarkBatch();
        ok(b.Shadow(Shadow(), *mD, *mG), "shadow");
        if (render) {
            b.MarkBatch();
            SplatInputs in{mQPrev.get(), mQ.get(),         mT.get(),     mTilesPrev.get(),
                           mTiles.get(), mBandsPrev.get(), mBands.get(), mG.get()};
            ok(b.RenderSplat(mSplat, in, *mImage, stats), "render_splat");
        }
    }

    static constexpr uint32_t kW = 48, kH = 36;
    std::vector<RasterEllipsoid> mEllipsoids;
    std::unique_ptr<Buffer> mHum, mAct, mCld, mQPrev, mTilesPrev, mBandsPrev;
    std::unique_ptr<Buffer> mRegion, mHum1, mAct1, mCld1, mQ, mT, mD, mTiles, mBands, mG, mImage;
    SplatParams mSplat;
    SplatOrder mOrder;
};

TEST_P(PipelinedGpu, ABatchGivesTheBytesAndHostValuesOfTheCallsOneByOne) {
    ASSERT_NO_FATAL_FAILURE(Pattern());
    const auto pattern = Read();
    uint32_t cover[2] = {};
    SplatStats stats[2];
    Step(true, true, &cover[0], &stats[0]);
    const auto expected = Read();
    ASSERT_NO_FATAL_FAILURE(Pattern());
    ASSERT_TRUE(mBackend->BeginBatch().has_value());
    Step(true, true, &cover[1], &stats[1]);
    auto ms = mBackend->EndBatch();
    ASSERT_TRUE(ms.has_value()) << ms.error().message;
    // One device time per interval: region, ca, smooth, shade, density, shadow, render_splat (or none
    // on a device without timestamps).
    if (!ms->empty()) {
        EXPECT_EQ(ms->size(), 7u);
    }
    const auto got = Read();
    for (size_t n = 0; n < expected.size(); ++n) {
        // Every stage wrote its output: the comparison below proves something.
        EXPECT_NE(expected[n], pattern[n]) << "output " << n << " was not written one by one";
        size_t differ = 0;
        for (size_t k = 0; k < got[n].size(); ++k) differ += got[n][k] != expected[n][k];
        EXPECT_EQ(differ, 0u) << "output " << n << ": " << differ << " of " << got[n].size() << " bytes differ";
    }
    ASSERT_GT(cover[0], 0u);
    ASSERT_GT(stats[0].splats, 0u);
    // Density's cover (after 4 marks) and render_splat's stats (after 6) come back from the call or,
    // deferred, after EndBatch with the call's mark; a deferred value leaves the caller's as it was.
    const std::vector<DeferredHostResult> deferred = mBackend->TakeDeferredResults();
    EXPECT_TRUE(mBackend->TakeDeferredResults().empty()) << "each result once";
    ASSERT_LE(deferred.size(), 2u);
    std::optional<uint32_t> batchedCover = cover[1];
    std::optional<FrameCounters> batchedStats = ToFrameCounters(stats[1], kSplatCounters);
    for (const DeferredHostResult& d : deferred) {
        EXPECT_NE(d.coveredColumns.has_value(), d.frameCounters.has_value()) << "one value per deferred result";
        if (d.coveredColumns) {
            EXPECT_EQ(d.mark, 4u);
            EXPECT_EQ(cover[1], 0u) << "the cover came from the call and again deferred";
            batchedCover = d.coveredColumns;
        }
        if (d.frameCounters) {
            EXPECT_EQ(d.mark, 6u);
            EXPECT_EQ(stats[1].splats, 0u) << "the stats came from the call and again deferred";
            batchedStats = d.frameCounters;
        }
    }
    EXPECT_EQ(batchedCover, std::optional<uint32_t>(cover[0]));
    EXPECT_EQ(*batchedStats, ToFrameCounters(stats[0], kSplatCounters)) << "splats, voxels visited, fragments";
}

TEST_P(PipelinedGpu, OneSubmissionAndOneWaitPerBatchAndOneMorePerDownload) {
    // Outside a batch every call submits and waits: region, ca, smooth, shade and shadow at least
    // once each (an upload may add its own).
    SubmissionCounts before = mBackend->Submissions();
    Step(false, false);
    SubmissionCounts d = mBackend->Submissions() - before;
    EXPECT_GE(d.submissions, 5u);
    EXPECT_EQ(d.hostWaits, d.submissions);

    // A batch of calls that need no host value: one of each.
    before = mBackend->Submissions();
    ASSERT_TRUE(mBackend->BeginBatch().has_value());
    Step(false, false);
    EXPECT_EQ((mBackend->Submissions() - before).submissions, 0u) << "nothing is submitted before EndBatch";
    ASSERT_TRUE(mBackend->EndBatch().has_value());
    d = mBackend->Submissions() - before;
    EXPECT_EQ(d.submissions, 1u);
    EXPECT_EQ(d.hostWaits, 1u);

    // An upload in a batch is recorded; a Download submits and waits once more, and sees the work
    // before it.
    const auto q = test::Read<float>(*mBackend, *mQ);
    before = mBackend->Submissions();
    ASSERT_TRUE(mBackend->BeginBatch().has_value());
    const auto otherCld = test::RandomBits(kPipeGrid, 9, 2);
    ASSERT_TRUE(mBackend->Upload(*mCld, std::as_bytes(std::span(otherCld))).has_value());
    Step(false, false);
    EXPECT_NE(test::Read<float>(*mBackend, *mQ), q) << "the download did not see the upload's step";
    Step(false, false);
    ASSERT_TRUE(mBackend->EndBatch().has_value());
    d = mBackend->Submissions() - before;
    EXPECT_EQ(d.submissions, 2u);
    EXPECT_EQ(d.hostWaits, 2u);

    // Density's cover is read after EndBatch's wait: still one of each.
    before = mBackend->Submissions();
    ASSERT_TRUE(mBackend->BeginBatch().has_value());
    Step(true, false);
    ASSERT_TRUE(mBackend->EndBatch().has_value());
    d = mBackend->Submissions() - before;
    EXPECT_EQ(d.submissions, 1u);
    EXPECT_EQ(d.hostWaits, 1u);
    EXPECT_EQ(mBackend->TakeDeferredResults().size(), 1u);
}

TEST_P(PipelinedGpu, EndBatchGivesADeviceTimePerIntervalAndBatchesDoNotNest) {
    ASSERT_TRUE(mBackend->BeginBatch().has_value());
    Step(false, false);  // 5 calls, 4 marks
    mBackend->MarkBatch();
    mBackend->MarkBatch();  // two intervals with nothing in them
    auto ms = mBackend->EndBatch();
    ASSERT_TRUE(ms.has_value()) << ms.error().message;
    if (ms->empty()) GTEST_SKIP() << "this device has no timestamps";
    ASSERT_EQ(ms->size(), 7u);
    double calls = 0;
    for (size_t n = 0; n < 5; ++n) {
        EXPECT_TRUE(std::isfinite((*ms)[n]) && (*ms)[n] >= 0.0) << "interval " << n << ": " << (*ms)[n];
        calls += (*ms)[n];
    }
    EXPECT_GT(calls, 0.0);
    EXPECT_EQ((*ms)[5], 0.0);
    EXPECT_EQ((*ms)[6], 0.0);
    // Outside a batch MarkBatch does nothing and EndBatch is an error; batches do not nest; an empty
    // batch is one interval of nothing.
    mBackend->MarkBatch();
    EXPECT_FALSE(mBackend->EndBatch().has_value());
    ASSERT_TRUE(mBackend->BeginBatch().has_value());
    EXPECT_FALSE(mBackend->BeginBatch().has_value()) << "batches do not nest";
    auto empty = mBackend->EndBatch();
    ASSERT_TRUE(empty.has_value()) << empty.error().message;
    EXPECT_EQ(*empty, std::vector<double>{0.0});
}

INSTANTIATE_TEST_SUITE_P(Gpu, PipelinedGpu, ::testing::ValuesIn(test::GpuTestBackends()),
                         [](const auto& info) { return info.param; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(PipelinedGpu);

// ---- What only Vulkan does ----

class PipelinedVk : public PipelinedGpu {};

TEST_P(PipelinedVk, OneByOneRegionUploadsItsListsAndEveryOtherCallSubmitsOnce) {
    SubmissionCounts before = mBackend->Submissions();
    ASSERT_TRUE(mBackend->Smooth(1, *mCld, *mQ).has_value());
    SubmissionCounts d = mBackend->Submissions() - before;
    EXPECT_EQ(d.submissions, 1u);
    EXPECT_EQ(d.hostWaits, 1u);
    // Region uploads the ellipsoids when they change and its two tile lists
    // each call: 4 then 3 there, 1 for ca, smooth, shade and shadow each.
    for (uint64_t expected : {8u, 7u}) {
        before = mBackend->Submissions();
        Step(false, false);
        d = mBackend->Submissions() - before;
        EXPECT_EQ(d.submissions, expected);
        EXPECT_EQ(d.hostWaits, expected);
    }
}

TEST_P(PipelinedVk, AnUploadInABatchIsSeenByLaterCallsOnly) {
    const auto before = test::RandomBits(kPipeGrid, 11, 3), after = test::RandomBits(kPipeGrid, 12, 2);
    auto cld = test::MakeFilled(*mBackend, BufferFormat::Bits, kPipeGrid, before);
    auto q1 = test::MakeBuffer(*mBackend, BufferFormat::F32, kPipeGrid);
    auto q2 = test::MakeBuffer(*mBackend, BufferFormat::F32, kPipeGrid);
    // The expected q of each field, one call at a time.
    ASSERT_TRUE(mBackend->Smooth(1, *cld, *q1).has_value());
    const auto expectedBefore = test::Read<float>(*mBackend, *q1);
    ASSERT_TRUE(mBackend->Upload(*cld, std::as_bytes(std::span(after))).has_value());
    ASSERT_TRUE(mBackend->Smooth(1, *cld, *q1).has_value());
    const auto expectedAfter = test::Read<float>(*mBackend, *q1);
    ASSERT_NE(expectedBefore, expectedAfter) << "the two fields must smooth differently";

    // Two uploads into cld in one batch, each read by the call after it: bytes
    // staged in memory the first copy still reads would reach both calls.
    const auto neither = test::RandomBits(kPipeGrid, 13, 4);
    ASSERT_TRUE(mBackend->Upload(*cld, std::as_bytes(std::span(neither))).has_value());
    ASSERT_TRUE(mBackend->BeginBatch().has_value());
    ASSERT_TRUE(mBackend->Upload(*cld, std::as_bytes(std::span(before))).has_value());
    ASSERT_TRUE(mBackend->Smooth(1, *cld, *q1).has_value());
    ASSERT_TRUE(mBackend->Upload(*cld, std::as_bytes(std::span(after))).has_value());
    ASSERT_TRUE(mBackend->Smooth(1, *cld, *q2).has_value());
    ASSERT_TRUE(mBackend->EndBatch().has_value());
    EXPECT_EQ(test::Read<float>(*mBackend, *q1), expectedBefore) << "the first call saw the later upload";
    EXPECT_EQ(test::Read<float>(*mBackend, *q2), expectedAfter) << "the second call did not see the upload";
}

TEST_P(PipelinedVk, ManyCallsInABatchRunOutOfTimestampsAndSubmitOnce) {
    // More calls than one submission's timestamp pairs (1024): the batch submits
    // once on the way, and every call still runs.
    const SubmissionCounts before = mBackend->Submissions();
    ASSERT_TRUE(mBackend->BeginBatch().has_value());
    for (int n = 0; n < 1100; ++n) ASSERT_TRUE(mBackend->Shadow(Shadow(), *mD, *mG).has_value());
    auto ms = mBackend->EndBatch();
    ASSERT_TRUE(ms.has_value()) << ms.error().message;
    const SubmissionCounts d = mBackend->Submissions() - before;
    EXPECT_EQ(d.submissions, 2u);
    EXPECT_EQ(d.hostWaits, 2u);
    if (!ms->empty()) {
        ASSERT_EQ(ms->size(), 1u);
        EXPECT_GT((*ms)[0], 0.0);
    }
}

TEST_P(PipelinedVk, AScratchSlotThatGrowsInABatchKeepsTheOldOneForTheCallsBefore) {
    // The second region call lists far more ellipsoids per tile, so its scratch
    // slots (the ellipsoids, the tile entries) grow while the first call's
    // recorded dispatch still reads the smaller ones.
    const std::vector<RasterEllipsoid> few(mEllipsoids.begin(), mEllipsoids.begin() + 1);
    std::vector<RasterEllipsoid> many;
    for (int n = 0; n < 8; ++n) many.insert(many.end(), mEllipsoids.begin(), mEllipsoids.end());
    auto r1 = test::MakeBuffer(*mBackend, BufferFormat::U8, kPipeGrid);
    auto r2 = test::MakeBuffer(*mBackend, BufferFormat::U8, kPipeGrid);
    ASSERT_TRUE(mBackend->Region(few, *r1).has_value());
    const auto expectedFew = test::Read<uint8_t>(*mBackend, *r1);
    ASSERT_TRUE(mBackend->Region(many, *r2).has_value());
    const auto expectedMany = test::Read<uint8_t>(*mBackend, *r2);
    ASSERT_NE(expectedFew, expectedMany);
    // Shrink the slots back to the small list's size: a fresh backend.
    auto fresh = test::MakeTestBackend("vk");
    ASSERT_TRUE(fresh.has_value());
    Backend& b = **fresh;
    auto s1 = test::MakeBuffer(b, BufferFormat::U8, kPipeGrid);
    auto s2 = test::MakeBuffer(b, BufferFormat::U8, kPipeGrid);
    ASSERT_TRUE(b.BeginBatch().has_value());
    ASSERT_TRUE(b.Region(few, *s1).has_value());
    ASSERT_TRUE(b.Region(many, *s2).has_value());
    ASSERT_TRUE(b.EndBatch().has_value());
    EXPECT_EQ(test::Read<uint8_t>(b, *s1), expectedFew);
    EXPECT_EQ(test::Read<uint8_t>(b, *s2), expectedMany);
    test::ExpectNoValidationMessages(&b);
}

// ---- Numbers, not a test: thesis-medium (every step rendered), steps in
// alternation one by one and batched (one batch per step, MarkBatch before each
// stage call). Per stage: submissions, host waits, wall and device ms, medians
// and spread over the steps. Run by hand:
//   cloudbench_tests --gtest_also_run_disabled_tests --gtest_filter='*DISABLED_ThesisMediumNumbers*'
// (PIPELINED_VK_STEPS sets the steps per mode, 8 by default.)

// Forwards every call to `inner` and, per stage, counts submissions, host waits
// and the wall time of the call, and marks a batch interval before each call.
class PipeCountingBackend final : public Backend {
  public:
    explicit PipeCountingBackend(Backend& inner) : mInner(inner) {}
    struct Call {
        Stage stage;
        SubmissionCounts counts;
        double wallMs = 0;
        std::optional<double> deviceMs;
    };
    std::vector<Call> calls;  // this step's, in order

    std::string Name() const override { return mInner.Name(); }
    std::string Device() const override { return mInner.Device(); }
    bool Supports(Stage stage) const override { return mInner.Supports(stage); }
    std::optional<double> LastDeviceMs() const override { return mInner.LastDeviceMs(); }
    Status BeginBatch() override { return mInner.BeginBatch(); }
    void MarkBatch() override { mInner.MarkBatch(); }
    Result<std::vector<double>> EndBatch() override { return mInner.EndBatch(); }
    SubmissionCounts Submissions() const override { return mInner.Submissions(); }
    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override {
        return mInner.CreateBuffer(format, extent);
    }
    Status Upload(Buffer& buffer, std::span<const std::byte> canonical) override {
        return mInner.Upload(buffer, canonical);
    }
    Status Download(const Buffer& buffer, std::span<std::byte> canonical) override {
        return mInner.Download(buffer, canonical);
    }
    uint64_t BufferBytes(BufferFormat format, const Extent3& extent) const override {
        return mInner.BufferBytes(format, extent);
    }
    uint64_t ScratchBytes(const Scene& scene) const override { return mInner.ScratchBytes(scene); }
    std::optional<uint64_t> AvailableBytes() const override { return mInner.AvailableBytes(); }

    Status Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region, SliceRange slices) override {
        return Count(Stage::Region, [&] { return mInner.Region(ellipsoids, region, slices); });
    }
    Status CaInitialize(const CaInitParams& params, CaFields out) override {
        return Count(Stage::Ca, [&] { return mInner.CaInitialize(params, out); });
    }
    Status CaStep(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) override {
        return Count(Stage::Ca, [&] { return mInner.CaStep(params, in, region, out); });
    }
    Status Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices) override {
        return Count(Stage::Smooth, [&] { return mInner.Smooth(radius, cld, q, slices); });
    }
    Status Density(const DensityParams& params, const Buffer& q, const Buffer* cld, DensityOutputs& out) override {
        return Count(Stage::Density, [&] { return mInner.Density(params, q, cld, out); });
    }
    Status Shade(const ShadeParams& params, const Buffer& q, Buffer& T) override {
        return Count(Stage::Shade, [&] { return mInner.Shade(params, q, T); });
    }
    Status Shadow(const ShadowParams& params, const Buffer& columnSum, Buffer& G) override {
        return Count(Stage::Shadow, [&] { return mInner.Shadow(params, columnSum, G); });
    }
    Status RenderSplat(const SplatParams& params, const SplatInputs& in, Buffer& image, SplatStats* stats) override {
        return Count(Stage::RenderSplat, [&] { return mInner.RenderSplat(params, in, image, stats); });
    }

  private:
    template <typename Fn>
    Status Count(Stage stage, Fn&& fn) {
        mInner.MarkBatch();
        const SubmissionCounts before = mInner.Submissions();
        const auto t0 = std::chrono::steady_clock::now();
        Status s = fn();
        const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        calls.push_back({stage, mInner.Submissions() - before, wall, mInner.LastDeviceMs()});
        return s;
    }
    Backend& mInner;
};

std::string PipeSpread(std::vector<double> v) {
    if (v.empty()) return "-";
    std::sort(v.begin(), v.end());
    char text[96];
    std::snprintf(text, sizeof text, "%.3f [%.3f..%.3f]", v[v.size() / 2], v.front(), v.back());
    return text;
}

TEST_P(PipelinedVk, DISABLED_ThesisMediumNumbers) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/thesis-medium.json",
                           {{"render.every_steps", "1"}, {"warmup_steps", "0"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    // Without the validation layer: it costs host time per call.
    auto plain = CreateBackend("vk", {});
    ASSERT_TRUE(plain.has_value()) << plain.error().message;
    PipeCountingBackend counting(**plain);
    auto sim = Simulation::Create(*scene, counting);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    const char* env = std::getenv("PIPELINED_VK_STEPS");
    const int steps = env ? std::atoi(env) : 8;
    // Per mode (0 one by one, 1 batched), per stage: the samples of each quantity.
    struct Samples {
        std::vector<double> submissions, waits, wall, device;
    };
    std::map<Stage, Samples> perStage[2];
    Samples perStep[2];
    std::vector<double> gaps[2];  // per step: wall minus device, ms
    for (int n = 0; n < 2 * steps + 2; ++n) {
        const int mode = n % 2;
        counting.calls.clear();
        const SubmissionCounts before = counting.Submissions();
        StepRecord record;
        const auto t0 = std::chrono::steady_clock::now();
        if (mode == 1) {
            ASSERT_TRUE(counting.BeginBatch().has_value());
        }
        ASSERT_TRUE((*sim)->Step(record).has_value());
        std::vector<double> intervals;
        if (mode == 1) {
            auto ms = counting.EndBatch();
            ASSERT_TRUE(ms.has_value()) << ms.error().message;
            intervals = *ms;
        }
        const double stepWall =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        if (n < 2) continue;  // one warm-up step per mode
        const SubmissionCounts d = counting.Submissions() - before;
        perStep[mode].submissions.push_back(double(d.submissions));
        perStep[mode].waits.push_back(double(d.hostWaits));
        perStep[mode].wall.push_back(stepWall);
        std::map<Stage, std::array<double, 4>> sums;
        double deviceTotal = 0;
        for (size_t c = 0; c < counting.calls.size(); ++c) {
            const auto& call = counting.calls[c];
            // Batched: interval c + 1 is the call's (interval 0 is what came before the first call).
            const double device =
                mode == 1 ? (c + 1 < intervals.size() ? intervals[c + 1] : 0.0) : call.deviceMs.value_or(0.0);
            auto& s = sums[call.stage];
            s[0] += double(call.counts.submissions), s[1] += double(call.counts.hostWaits), s[2] += call.wallMs;
            s[3] += device;
            deviceTotal += device;
        }
        for (const auto& [stage, s] : sums) {
            Samples& out = perStage[mode][stage];
            out.submissions.push_back(s[0]), out.waits.push_back(s[1]), out.wall.push_back(s[2]);
            out.device.push_back(s[3]);
        }
        perStep[mode].device.push_back(deviceTotal);
        gaps[mode].push_back(stepWall - deviceTotal);
    }
    // The cost of one host round trip with nothing else to wait for: a 4-byte read back.
    auto word = counting.CreateBuffer(BufferFormat::U8, {4, 1, 1});
    ASSERT_TRUE(word.has_value());
    std::vector<double> roundTrips;
    for (int n = 0; n < 200; ++n) {
        std::array<std::byte, 4> bytes{};
        const auto t0 = std::chrono::steady_clock::now();
        ASSERT_TRUE(counting.Download(**word, bytes).has_value());
        roundTrips.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf("thesis-medium on %s, %d steps per mode, alternating; median [min..max]\n", counting.Device().c_str(),
                steps);
    std::printf("one submit + wait + 4-byte read back: %s ms\n", PipeSpread(roundTrips).c_str());
    for (int mode = 0; mode < 2; ++mode) {
        std::printf("%s:\n", mode ? "batched (one batch per step)" : "one by one");
        for (const auto& [stage, s] : perStage[mode])
            std::printf("  %-12s submissions %s waits %s wall ms %s device ms %s\n",
                        std::string(StageName(stage)).c_str(), PipeSpread(s.submissions).c_str(),
                        PipeSpread(s.waits).c_str(), PipeSpread(s.wall).c_str(), PipeSpread(s.device).c_str());
        const Samples& s = perStep[mode];
        std::printf("  %-12s submissions %s waits %s wall ms %s device ms %s\n", "step",
                    PipeSpread(s.submissions).c_str(), PipeSpread(s.waits).c_str(), PipeSpread(s.wall).c_str(),
                    PipeSpread(s.device).c_str());
        std::printf("  step wall minus device ms %s\n", PipeSpread(gaps[mode]).c_str());
    }
}

// On vk alone; skipped (BackendTest) where this build or machine has none.
INSTANTIATE_TEST_SUITE_P(Vk, PipelinedVk, ::testing::Values(std::string("vk")),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace cb
