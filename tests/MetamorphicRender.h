// Helpers of the metamorphic renderer tests (MetamorphicRenderTest.cpp,
// MetamorphicRenderOriginTest.cpp): a scene of both steps, rendering it with
// render_splat or render_march on a backend, and the fixture that compares
// a renderer's images with culling and skipping on and off.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/math/Camera.h"
#include "core/math/Random.h"
#include "core/math/Splat.h"
#include "core/pipeline/Backend.h"
#include "tests/BackendTestUtil.h"
#include "tests/TestUtil.h"
#if CLOUDBENCH_HAVE_GL
#include "impl_gl/BackendGL.h"
#endif

namespace cb {
namespace {

// A scene of both steps' q, T and (non-empty: ground on) G on a grid of voxel
// size h whose corner (0, 0, 0) sits at `origin`.
struct MetaScene {
    Extent3 grid{16, 16, 8};
    std::vector<float> qPrev, qCur, T, G;
    std::array<float, 3> origin{0, 0, 0};
    float h = 1;
    uint32_t tile = 4, band = 2;
    float splatDiameter = 1.5f, alpha = 0.5f;
};

constexpr Vec3 kMetaBackground{0.4f, 0.6f, 0.9f};

struct MetaImage {
    std::vector<float> rgb;
    SplatStats splat;  // not read in a batch
};

// The splat renderer's parameters of scene s seen by `camera` (culling and skipping on).
SplatParams MetaSplatParams(const MetaScene& s, const CameraFrame& camera) {
    SplatParams p;
    p.camera = camera;
    p.sun = SunDirection(0.7, 0.5);
    p.light.sunRadiance = {1.0f, 0.9f, 0.8f};
    p.light.ambient = {0.2f, 0.25f, 0.3f};
    p.background = kMetaBackground;
    p.light.phase = {PhaseKind::HenyeyGreenstein, 0.5f};
    p.qMin = 0.3f;
    p.splatDiameter = s.splatDiameter;
    p.opacity = 0.6f;
    p.alpha = s.alpha;
    p.origin = s.origin;
    p.voxelSize = s.h;
    p.tile = s.tile;
    p.band = s.band;
    p.ground = {!s.G.empty(), {0.3f, 0.35f, 0.25f}};
    return p;
}

// Renders scene s with render_splat on backend b; the occupancy of both steps
// comes from b's density stage. `batch`: the call is recorded in a batch (gl
// then skips in the vertex shader, see MetaMakeBackend).
MetaImage MetaRenderSplat(Backend& b, const MetaScene& s, const CameraSettings& cam, uint32_t W, uint32_t H,
                          bool culling, bool skipping, bool batch = false) {
    const Extent3 e = s.grid;
    auto qp = test::MakeFilled(b, BufferFormat::F32, e, s.qPrev);
    auto qc = test::MakeFilled(b, BufferFormat::F32, e, s.qCur);
    auto T = test::MakeFilled(b, BufferFormat::F32, e, s.T);
    const Extent3 tiles{CeilDiv(e.nx, s.tile), CeilDiv(e.ny, s.tile), 1},
        bands{tiles.nx, tiles.ny, CeilDiv(e.nz, s.band)};
    std::unique_ptr<Buffer> occ[2][2], D[2];
    for (int step = 0; step < 2; ++step) {
        D[step] = test::MakeBuffer(b, BufferFormat::F32, {e.nx, e.ny, 1});
        occ[step][0] = test::MakeBuffer(b, BufferFormat::U8, tiles);
        occ[step][1] = test::MakeBuffer(b, BufferFormat::U8, bands);
        DensityOutputs out{D[step].get(), occ[step][0].get(), occ[step][1].get(), 0};
        Status st = b.Density({s.tile, s.band, {}}, step == 0 ? *qp : *qc, nullptr, out);
        EXPECT_TRUE(st.has_value()) << (st ? "" : st.error().message);
    }
    std::unique_ptr<Buffer> G;
    if (!s.G.empty()) G = test::MakeFilled(b, BufferFormat::F32, {e.nx, e.ny, 1}, s.G);
    auto image = test::MakeBuffer(b, BufferFormat::F32, {3, W, H});
    SplatParams p = MetaSplatParams(s, MakeCameraFrame(cam, W, H));
    const SplatOrder order =
        MakeSplatOrder(p.camera, e, {double(s.origin[0]), double(s.origin[1]), double(s.origin[2])}, s.h);
    p.order = &order;
    p.culling = culling;
    p.skipping = skipping;
    SplatInputs in{qp.get(), qc.get(), T.get(), occ[0][0].get(), occ[1][0].get(), occ[0][1].get(), occ[1][1].get()};
    in.G = G.get();
    MetaImage r;
    if (batch) {
        EXPECT_TRUE(b.BeginBatch().has_value());
    }
    Status st = b.RenderSplat(p, in, *image, &r.splat);
    if (batch) {
        auto times = b.EndBatch();
        EXPECT_TRUE(times.has_value()) << (times ? "" : times.error().message);
        b.TakeDeferredResults();
    }
    EXPECT_TRUE(st.has_value()) << b.Name() << ": " << (st ? "" : st.error().message);
    r.rgb = st ? test::Read<float>(b, *image) : std::vector<float>{};
    return r;
}

// Renders scene s with render_march on backend b (light from T).
std::vector<float> MetaRenderMarch(Backend& b, const MetaScene& s, const CameraSettings& cam, uint32_t W, uint32_t H,
                                   bool skipping, uint32_t brick) {
    const Extent3 e = s.grid;
    auto qp = test::MakeFilled(b, BufferFormat::F32, e, s.qPrev);
    auto qc = test::MakeFilled(b, BufferFormat::F32, e, s.qCur);
    auto T = test::MakeFilled(b, BufferFormat::F32, e, s.T);
    std::unique_ptr<Buffer> G;
    if (!s.G.empty()) G = test::MakeFilled(b, BufferFormat::F32, {e.nx, e.ny, 1}, s.G);
    auto image = test::MakeBuffer(b, BufferFormat::F32, {3, W, H});
    MarchParams p;
    p.camera = MakeCameraFrame(cam, W, H);
    p.setup.size = {float(e.nx), float(e.ny), float(e.nz)};
    p.setup.voxelSize = p.setup.light.voxelSize = s.h;
    p.setup.step = 0.5f;
    p.setup.sigmaH = 0.6f;
    p.setup.epsilon = 0;
    p.setup.sun = SunDirection(0.7, 0.5);
    p.setup.light.sunRadiance = {1.0f, 0.9f, 0.8f};
    p.setup.light.ambient = {0.2f, 0.25f, 0.3f};
    p.setup.background = kMetaBackground;
    p.setup.light.phase = {PhaseKind::HenyeyGreenstein, 0.5f};
    p.origin = s.origin;
    p.alpha = s.alpha;
    p.skipping = skipping;
    p.brick = brick;
    p.ground = {!s.G.empty(), {0.3f, 0.35f, 0.25f}};
    MarchInputs in{qp.get(), qc.get(), T.get()};
    in.G = G.get();
    MarchStats stats;
    Status st = b.RenderMarch(p, in, *image, &stats);
    EXPECT_TRUE(st.has_value()) << b.Name() << ": " << (st ? "" : st.error().message);
    return st ? test::Read<float>(b, *image) : std::vector<float>{};
}

CameraSettings MetaCamera(std::array<double, 3> eye, std::array<double, 3> target, double fov = 60,
                          std::array<double, 3> up = {0, 0, 1}, double nearPlane = 0.25) {
    CameraSettings c;
    c.eye = eye;
    c.target = target;
    c.up = up;
    c.fovDeg = fov;
    c.nearPlane = nearPlane;
    return c;
}

// Pixels (not channels) that differ from the flat background.
size_t MetaNonBackground(const std::vector<float>& rgb) {
    size_t n = 0;
    for (size_t i = 0; i + 2 < rgb.size(); i += 3)
        n += rgb[i] != kMetaBackground[0] || rgb[i + 1] != kMetaBackground[1] || rgb[i + 2] != kMetaBackground[2];
    return n;
}

// Where the images first differ, for a failure message.
std::string MetaFirstDifference(const std::vector<float>& a, const std::vector<float>& b, uint32_t W) {
    if (a.size() != b.size()) return "sizes " + std::to_string(a.size()) + " and " + std::to_string(b.size());
    size_t count = 0, first = a.size();
    float worst = 0;
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i] != b[i]) {
            if (first == a.size()) first = i;
            ++count;
            worst = std::max(worst, std::fabs(a[i] - b[i]));
        }
    if (!count) return "equal";
    const size_t pixel = first / 3;
    return std::to_string(count) + " channels differ (worst " + std::to_string(worst) + "), first at pixel (" +
           std::to_string(pixel % W) + ", " + std::to_string(pixel / W) + ")";
}

// The backend under test; gl records render_splat in a batch with skipping in
// the vertex shader (SplatSkip::Device), the path a GPU takes.
class MetamorphicRenderBackend : public test::BackendTest {
  protected:
    void SetUp() override {
        test::BackendTest::SetUp();
        if (IsSkipped()) return;
#if CLOUDBENCH_HAVE_GL
        if (auto* gl = dynamic_cast<gl::BackendGL*>(mBackend.get())) gl->SetSplatSkip(gl::BackendGL::SplatSkip::Device);
#endif
    }
    bool HasMarch() const { return mBackend->Supports(Stage::RenderMarch); }

    // The image with culling and skipping off, and expects every other
    // combination (and skipping in a batch) to equal it bit for bit.
    std::vector<float> ExpectSplatUnchanged(const MetaScene& s, const CameraSettings& cam, uint32_t W, uint32_t H,
                                            const std::string& what) {
        const MetaImage off = MetaRenderSplat(*mBackend, s, cam, W, H, false, false);
        uint64_t culledSplats = 0;  // splats drawn with culling on (skipping must not change it)
        for (int combo = 1; combo < 5; ++combo) {
            const bool culling = combo & 1, skipping = combo & 2, batch = combo == 4;
            const MetaImage on = MetaRenderSplat(*mBackend, s, cam, W, H, culling || batch, skipping || batch, batch);
            EXPECT_TRUE(on.rgb == off.rgb)
                << what << ": culling " << (culling || batch) << ", skipping " << (skipping || batch)
                << (batch ? " in a batch" : "") << ": " << MetaFirstDifference(off.rgb, on.rgb, W);
            if (combo == 1) culledSplats = on.splat.splats;
            if (combo == 2) {
                EXPECT_EQ(on.splat.splats, off.splat.splats) << what << ": skipping lost splats";
            }
            if (combo == 3) {
                EXPECT_EQ(on.splat.splats, culledSplats) << what << ": skipping lost splats (culling on)";
            }
        }
        return off.rgb;
    }
    void ExpectMarchUnchanged(const MetaScene& s, const CameraSettings& cam, uint32_t W, uint32_t H,
                              const std::string& what) {
        if (!HasMarch()) return;
        const std::vector<float> off = MetaRenderMarch(*mBackend, s, cam, W, H, false, 4);
        for (uint32_t brick : {1u, 4u, 8u}) {
            const std::vector<float> on = MetaRenderMarch(*mBackend, s, cam, W, H, true, brick);
            EXPECT_TRUE(on == off) << what << ": march brick " << brick << ": " << MetaFirstDifference(off, on, W);
        }
    }
};

}  // namespace
}  // namespace cb
