// Pipelined timing on gl (core/pipeline/Backend.h, "Pipelined timing"), what
// only gl does; what every GPU backend does is PipelinedGpuTest.cpp. A whole
// step's batch waits once (density's cover and render_splat's stats deferred,
// its box visibility worked out on the device), and each read back inside it
// once more; how render_splat skips in a batch follows the rasterizer; a
// renderer's image is downloaded from the pixel buffer it passed through, and
// never stale; layered passes give the bytes of one draw per slice.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/math/Camera.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"
#include "core/stages/ca/Ca.h"
#include "core/stages/density/Density.h"
#include "core/stages/render_splat/RenderSplat.h"
#include "core/stages/shade/Shade.h"
#include "core/stages/shadow/Shadow.h"
#include "registry/Registry.h"
#if CLOUDBENCH_HAVE_GL
#include "impl_gl/BackendGL.h"
#endif
#include "tests/TestUtil.h"

namespace cb {
namespace {

constexpr Extent3 kPipeGrid{40, 36, 12};

// A gl backend whose render_splat skips empty boxes in the vertex shader in a batch (SplatSkip::Device), the path
// these tests check whatever the rasterizer; PipelinedGL.SplatSkipAutoFollowsTheRasterizer checks Auto.
std::unique_ptr<Backend> PipeMakeGl() {
    auto b = gl::BackendGL::Create();
    if (!b) return nullptr;
    (*b)->SetSplatSkip(gl::BackendGL::SplatSkip::Device);
    return std::move(*b);
}

// The buffers and host results of one step on the splat pipeline.
struct PipeStep {
    std::unique_ptr<Buffer> region, fields[2][3], q, D, tiles, bands, T, G, image;
    uint32_t covered = 0;
    SplatStats stats;
};

struct PipeInputs {
    std::vector<RasterEllipsoid> ellipsoids = test::RandomEllipsoids(kPipeGrid, 11);
    CaInitParams init{9, 0x60000000u, 0x30000000u};
    CaStepParams step;
    ShadeParams shade;
    ShadowParams shadow;
    SplatParams splat;
    SplatOrder order;
    PipeInputs() {
        step.seed = 4, step.step = 0, step.qExt = 0x08000000u, step.qHum = 0x20000000u, step.qAct = 0x30000000u;
        const Vec3 sun = SunDirection(0.45, 0.7);
        shade.sun = sun;
        shadow.sun = sun, shadow.nz = kPipeGrid.nz;
        CameraSettings camera;
        camera.eye = {-800, -600, 300}, camera.target = {1000, 900, 300}, camera.fovDeg = 60;
        splat.camera = MakeCameraFrame(camera, 64, 48);
        order = MakeSplatOrder(splat.camera, kPipeGrid, {0, 0, 0}, 50);
        splat.order = &order;
        splat.sun = sun;
        splat.background = {0.4f, 0.5f, 0.8f};
        splat.tile = 8, splat.band = 4;
        splat.qMin = 0.05f;
    }
};

PipeStep PipeBuffers(Backend& b) {
    const Extent3 e = kPipeGrid, plane{e.nx, e.ny, 1};
    const Extent3 tiles{CeilDiv(e.nx, 8), CeilDiv(e.ny, 8), 1}, bands{tiles.nx, tiles.ny, CeilDiv(e.nz, 4)};
    PipeStep s;
    s.region = test::MakeBuffer(b, BufferFormat::U8, e);
    for (auto& step : s.fields)
        for (auto& field : step) field = test::MakeBuffer(b, BufferFormat::Bits, e);
    s.q = test::MakeBuffer(b, BufferFormat::F32, e);
    s.D = test::MakeBuffer(b, BufferFormat::F32, plane);
    s.tiles = test::MakeBuffer(b, BufferFormat::U8, tiles);
    s.bands = test::MakeBuffer(b, BufferFormat::U8, bands);
    s.T = test::MakeBuffer(b, BufferFormat::F32, e);
    s.G = test::MakeBuffer(b, BufferFormat::F32, plane);
    s.image = test::MakeBuffer(b, BufferFormat::F32, {3, 64, 48});
    return s;
}

// The stage calls of one step, each followed by `mark` (MarkBatch in a batch);
// `density` and `splat` leave out the calls that return host values.
Status PipeRun(Backend& b, const PipeInputs& in, PipeStep& s, bool densityAndSplat, void (*mark)(Backend&)) {
    CB_TRY(b.Region(in.ellipsoids, *s.region));
    mark(b);
    CB_TRY(b.CaInitialize(in.init, {s.fields[0][0].get(), s.fields[0][1].get(), s.fields[0][2].get()}));
    mark(b);
    CB_TRY(b.CaStep(in.step, {s.fields[0][0].get(), s.fields[0][1].get(), s.fields[0][2].get()}, *s.region,
                    {s.fields[1][0].get(), s.fields[1][1].get(), s.fields[1][2].get()}));
    mark(b);
    CB_TRY(b.Smooth(1, *s.fields[1][2], *s.q));
    mark(b);
    if (densityAndSplat) {
        DensityOutputs out{s.D.get(), s.tiles.get(), s.bands.get(), 0};
        CB_TRY(b.Density({8, 4, {}}, *s.q, s.fields[1][2].get(), out));
        s.covered = out.coveredColumns;
        mark(b);
    }
    CB_TRY(b.Shade(in.shade, *s.q, *s.T));
    mark(b);
    if (densityAndSplat) {
        CB_TRY(b.Shadow(in.shadow, *s.D, *s.G));
        mark(b);
        SplatInputs si{s.q.get(), s.q.get(), s.T.get(), s.tiles.get(), s.tiles.get(), s.bands.get(), s.bands.get()};
        CB_TRY(b.RenderSplat(in.splat, si, *s.image, &s.stats));
    }
    return {};
}

void PipeNoMark(Backend&) {}
void PipeMark(Backend& b) { b.MarkBatch(); }

// Every output of the step, canonical bytes, in a fixed order.
std::vector<std::vector<uint8_t>> PipeOutputs(Backend& b, PipeStep& s, bool densityAndSplat) {
    std::vector<const Buffer*> list{s.region.get(),
                                    s.fields[0][0].get(),
                                    s.fields[0][1].get(),
                                    s.fields[0][2].get(),
                                    s.fields[1][0].get(),
                                    s.fields[1][1].get(),
                                    s.fields[1][2].get(),
                                    s.q.get(),
                                    s.T.get()};
    if (densityAndSplat)
        for (const Buffer* x : {s.D.get(), s.tiles.get(), s.bands.get(), s.G.get(), s.image.get()}) list.push_back(x);
    std::vector<std::vector<uint8_t>> bytes;
    for (const Buffer* x : list) bytes.push_back(test::Read<uint8_t>(b, *x));
    return bytes;
}

SubmissionCounts PipeDelta(const SubmissionCounts& before, const SubmissionCounts& after) {
    return {after.submissions - before.submissions, after.hostWaits - before.hostWaits};
}

// A whole step's batch waits once, at EndBatch: density's cover and
// render_splat's stats are read after it (deferred), and render_splat's box
// visibility is worked out on the device. Each read back inside a batch waits
// once more: two downloads between calls add 2 waits to a batch of calls
// without host values, and see the work before them.
TEST(PipelinedGL, AStepWaitsOnceAndEachReadBackInABatchOnceMore) {
    auto b = PipeMakeGl(), ref = PipeMakeGl();
    if (!b || !ref) GTEST_SKIP() << "no gl backend here";
    const PipeInputs in;
    PipeStep s = PipeBuffers(*b);
    SubmissionCounts before = b->Submissions();
    ASSERT_TRUE(b->BeginBatch().has_value());
    ASSERT_TRUE(PipeRun(*b, in, s, true, PipeMark).has_value());
    ASSERT_TRUE(b->EndBatch().has_value());
    SubmissionCounts d = PipeDelta(before, b->Submissions());
    EXPECT_EQ(d.hostWaits, 1u);
    EXPECT_EQ(d.submissions, 1u);
    EXPECT_EQ(b->TakeDeferredResults().size(), 2u);

    PipeStep r = PipeBuffers(*ref);
    ASSERT_TRUE(PipeRun(*ref, in, r, false, PipeNoMark).has_value());
    const auto cld = test::Read<uint8_t>(*ref, *r.fields[0][2]);
    const auto q = test::Read<float>(*ref, *r.q);
    before = b->Submissions();
    ASSERT_TRUE(b->BeginBatch().has_value());
    ASSERT_TRUE(b->Region(in.ellipsoids, *s.region).has_value());
    ASSERT_TRUE(b->CaInitialize(in.init, {s.fields[0][0].get(), s.fields[0][1].get(), s.fields[0][2].get()}));
    EXPECT_EQ(test::Read<uint8_t>(*b, *s.fields[0][2]), cld);
    ASSERT_TRUE(b->CaStep(in.step, {s.fields[0][0].get(), s.fields[0][1].get(), s.fields[0][2].get()}, *s.region,
                          {s.fields[1][0].get(), s.fields[1][1].get(), s.fields[1][2].get()}));
    ASSERT_TRUE(b->Smooth(1, *s.fields[1][2], *s.q).has_value());
    EXPECT_EQ(test::Read<float>(*b, *s.q), q);
    ASSERT_TRUE(b->Shade(in.shade, *s.q, *s.T).has_value());
    ASSERT_TRUE(b->EndBatch().has_value());
    d = PipeDelta(before, b->Submissions());
    EXPECT_EQ(d.hostWaits, 3u);
    EXPECT_EQ(d.submissions, 3u);
}

// Auto skips by the host's runs on a software rasterizer (one read back of the bands in the batch: a second wait)
// and in the vertex shader on a GPU (one wait); the same image and stats either way.
TEST(PipelinedGL, SplatSkipAutoFollowsTheRasterizer) {
    auto autoMade = gl::BackendGL::Create();
    auto device = PipeMakeGl();
    if (!autoMade || !device) GTEST_SKIP() << "no gl backend here";
    gl::BackendGL& automatic = **autoMade;
    // The renderer's name, read apart from the backend's own test.
    const bool software = automatic.Device().find("llvmpipe") != std::string::npos ||
                          automatic.Device().find("softpipe") != std::string::npos;
    EXPECT_EQ(automatic.SplatSkipOnDevice(), !software);
    const PipeInputs in;
    PipeStep a = PipeBuffers(automatic), d = PipeBuffers(*device);
    const SubmissionCounts before = automatic.Submissions();
    ASSERT_TRUE(automatic.BeginBatch().has_value());
    ASSERT_TRUE(PipeRun(automatic, in, a, true, PipeMark).has_value());
    ASSERT_TRUE(automatic.EndBatch().has_value());
    EXPECT_EQ(PipeDelta(before, automatic.Submissions()).hostWaits, software ? 2u : 1u);
    ASSERT_TRUE(device->BeginBatch().has_value());
    ASSERT_TRUE(PipeRun(*device, in, d, true, PipeMark).has_value());
    ASSERT_TRUE(device->EndBatch().has_value());
    EXPECT_EQ(test::Read<uint8_t>(automatic, *a.image), test::Read<uint8_t>(*device, *d.image));
    const auto statsA = automatic.TakeDeferredResults(), statsD = device->TakeDeferredResults();
    ASSERT_EQ(statsA.size(), 2u);
    ASSERT_EQ(statsD.size(), 2u);
    ASSERT_TRUE(statsA[1].frameCounters && statsD[1].frameCounters);
    EXPECT_EQ(*statsA[1].frameCounters, *statsD[1].frameCounters) << "splats, voxels visited, fragments";
}

// The image comes from the renderer's pixel buffer right after the call, from
// the texture once anything else was written, and an upload into the image is
// never hidden by the kept copy.
TEST(PipelinedGL, ImageDownloadFromThePixelBufferIsNeverStale) {
    auto b = PipeMakeGl();
    if (!b) GTEST_SKIP() << "no gl backend here";
    const PipeInputs in;
    PipeStep s = PipeBuffers(*b);
    ASSERT_TRUE(PipeRun(*b, in, s, true, PipeNoMark).has_value());
    const auto fromCopy = test::Read<float>(*b, *s.image);
    auto other = test::MakeBuffer(*b, BufferFormat::U8, {1, 1, 1});  // any write: the texture is read
    const auto fromTexture = test::Read<float>(*b, *s.image);
    EXPECT_EQ(fromCopy, fromTexture);
    ASSERT_TRUE(PipeRun(*b, in, s, true, PipeNoMark).has_value());
    const std::vector<float> uploaded(s.image->CanonicalBytes() / 4, 0.25f);
    ASSERT_TRUE(b->Upload(*s.image, std::as_bytes(std::span(uploaded))).has_value());
    EXPECT_EQ(test::Read<float>(*b, *s.image), uploaded);
    size_t lit = 0;
    for (float v : fromCopy) lit += v != fromCopy[0];
    EXPECT_GT(lit, 0u) << "the image should not be flat";
}

#if CLOUDBENCH_HAVE_GL
// Layered passes: one instanced draw over the slices gives
// the bytes of one draw per slice, and the draws per call drop to what the
// passes need: ca init 1 (not nz), a step without wind 1, smooth 3 (not 3 nz),
// density 4 (sum, cover, bands, tiles; not nz + bands + 2), shade's
// up-sampling 1 (not nz), region 1 (not nz).
TEST(PipelinedGL, LayeredPassesGiveTheBytesOfOneDrawPerSlice) {
    auto madeA = gl::BackendGL::Create(), madeB = gl::BackendGL::Create();
    if (!madeA || !madeB) GTEST_SKIP() << "no gl backend here";
    gl::BackendGL &layered = **madeA, &perSlice = **madeB;
    perSlice.SetLayered(false);
    const PipeInputs in;
    PipeStep a = PipeBuffers(layered), s = PipeBuffers(perSlice);
    std::vector<uint64_t> draws[2];
    auto run = [&](gl::BackendGL& b, PipeStep& step, std::vector<uint64_t>& d) {
        static gl::BackendGL* current = nullptr;
        static std::vector<uint64_t>* out = nullptr;
        static uint64_t last = 0;
        current = &b, out = &d, last = b.Draws();
        return PipeRun(b, in, step, true, [](Backend&) {
            out->push_back(current->Draws() - last);
            last = current->Draws();
        });
    };
    ASSERT_TRUE(run(layered, a, draws[0]).has_value());
    ASSERT_TRUE(run(perSlice, s, draws[1]).has_value());
    EXPECT_TRUE(layered.Layered()) << "llvmpipe has ARB_shader_viewport_layer_array";
    EXPECT_FALSE(perSlice.Layered());
    const auto expected = PipeOutputs(perSlice, s, true), got = PipeOutputs(layered, a, true);
    for (size_t n = 0; n < expected.size(); ++n) EXPECT_EQ(expected[n], got[n]) << "output " << n;
    EXPECT_EQ(a.covered, s.covered);
    EXPECT_EQ(a.stats.fragments, s.stats.fragments);
    const uint32_t nz = kPipeGrid.nz, bandCount = CeilDiv(nz, 4u);
    // Intervals: region, ca init, ca step, smooth, density, shade, shadow.
    ASSERT_EQ(draws[0].size(), 7u);
    ASSERT_EQ(draws[1].size(), 7u);
    EXPECT_EQ(draws[1][0], nz);
    EXPECT_EQ(draws[0][0], 1u);
    EXPECT_EQ(draws[1][1], nz);
    EXPECT_EQ(draws[0][1], 1u);
    EXPECT_EQ(draws[1][2], nz);
    EXPECT_EQ(draws[0][2], 1u);
    EXPECT_EQ(draws[1][3], 3 * nz);
    EXPECT_EQ(draws[0][3], 3u);
    EXPECT_EQ(draws[1][4], nz + 1 + bandCount + 1);
    EXPECT_EQ(draws[0][4], 4u);
    EXPECT_EQ(draws[1][5] - draws[0][5], nz - 1);
    EXPECT_EQ(draws[0][6], 1u);
    EXPECT_EQ(draws[1][6], 1u);
}
#endif

#if CLOUDBENCH_HAVE_GL
// Not a test: the numbers of docs/performance.md ("OpenGL: pipelined timing"),
// run by hand with --gtest_also_run_disabled_tests. Thesis-medium after its
// warm-up on gl: per stage, draws and host waits per call, and wall and
// device ms per call, one by one (synchronised) and in one batch per step,
// and one by one with one draw per slice (SetLayered(false)), the three modes
// interleaved step by step; then the 1920 x 1080 image's
// Download from the renderer's pixel buffer against one from the texture.
double PipeMedian(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

TEST(PipelinedGL, DISABLED_ThesisMediumTiming) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/thesis-medium.json");
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const Scene& sc = *scene;
    auto made = gl::BackendGL::Create();
    if (!made) GTEST_SKIP() << made.error().message;
    gl::BackendGL& b = **made;
    const Extent3 e = sc.grid.size, plane{e.nx, e.ny, 1};
    const DensityParams dp = MakeDensityParams(sc);
    const Extent3 tiles{CeilDiv(e.nx, dp.tile), CeilDiv(e.ny, dp.tile), 1},
        bands{tiles.nx, tiles.ny, CeilDiv(e.nz, dp.band)};
    std::unique_ptr<Buffer> f[2][3];
    for (auto& step : f)
        for (auto& x : step) x = test::MakeBuffer(b, BufferFormat::Bits, e);
    auto region = test::MakeBuffer(b, BufferFormat::U8, e);
    std::unique_ptr<Buffer> q[2] = {test::MakeBuffer(b, BufferFormat::F32, e),
                                    test::MakeBuffer(b, BufferFormat::F32, e)};
    std::unique_ptr<Buffer> tl[2] = {test::MakeBuffer(b, BufferFormat::U8, tiles),
                                     test::MakeBuffer(b, BufferFormat::U8, tiles)};
    std::unique_ptr<Buffer> bd[2] = {test::MakeBuffer(b, BufferFormat::U8, bands),
                                     test::MakeBuffer(b, BufferFormat::U8, bands)};
    auto D = test::MakeBuffer(b, BufferFormat::F32, plane), G = test::MakeBuffer(b, BufferFormat::F32, plane);
    auto T = test::MakeBuffer(b, BufferFormat::F32, e);
    auto image = test::MakeBuffer(b, BufferFormat::F32, {3, sc.render.width, sc.render.height});
    ASSERT_TRUE(b.CaInitialize(MakeCaInitParams(sc), {f[0][0].get(), f[0][1].get(), f[0][2].get()}));
    EllipsoidList list(sc.ellipsoids, e);
    const CameraSettings& camera = sc.render.cameras.at(0);
    int cur = 0;
    const char* names[] = {"region", "ca", "smooth", "density", "shade", "shadow", "render_splat"};
    struct Samples {
        std::vector<double> wall, device, waits, draws;
    };
    std::map<std::string, Samples> sync, batch, slices;
    std::vector<double> stepSync, stepBatch, stepSlices, endBatch, waitsBatch;
    const int warm = int(std::max(sc.warmupSteps, 2u)), measured = 3 * 12;
    for (int t = 0; t < warm + measured; ++t) {
        const bool inBatch = t >= warm && t % 3 == 1, perSlice = t >= warm && t % 3 == 2, record = t >= warm;
        b.SetLayered(!perSlice);
        const auto raster = list.Raster();
        CaStepParams cp = MakeCaStepParams(sc, uint32_t(t));
        ShadeParams shp = MakeShadeParams(sc);
        ShadowParams sdp = MakeShadowParams(sc);
        SplatParams spp = MakeSplatParams(sc, camera);
        const SplatOrder order =
            MakeSplatOrder(spp.camera, e, {spp.origin[0], spp.origin[1], spp.origin[2]}, spp.voxelSize);
        spp.order = &order;
        const int o = 1 - cur;
        DensityOutputs out{D.get(), tl[o].get(), bd[o].get(), 0};
        SplatInputs si{q[cur].get(), q[o].get(),    T.get(),     tl[cur].get(),
                       tl[o].get(),  bd[cur].get(), bd[o].get(), G.get()};
        std::function<Status()> calls[] = {
            [&] { return b.Region(raster, *region); },
            [&] {
                return b.CaStep(cp, {f[cur][0].get(), f[cur][1].get(), f[cur][2].get()}, *region,
                                {f[o][0].get(), f[o][1].get(), f[o][2].get()});
            },
            [&] { return b.Smooth(sc.smooth.radius, *f[o][2], *q[o]); },
            [&] { return b.Density(dp, *q[o], f[o][2].get(), out); },
            [&] { return b.Shade(shp, *q[o], *T); },
            [&] { return b.Shadow(sdp, *D, *G); },
            [&] { return b.RenderSplat(spp, si, *image, nullptr); },
        };
        const auto step0 = std::chrono::steady_clock::now();
        if (inBatch) {
            ASSERT_TRUE(b.BeginBatch().has_value());
        }
        // The warm-up runs the automaton alone but for its last two steps.
        for (int n = 0; n < (t >= warm - 2 ? 7 : 2); ++n) {
            const SubmissionCounts c0 = b.Submissions();
            const uint64_t d0 = b.Draws();
            const auto t0 = std::chrono::steady_clock::now();
            Status s = calls[n]();
            const double wall =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            if (!s) FAIL() << names[n] << ": " << s.error().message;
            if (inBatch) b.MarkBatch();
            Samples& x = (inBatch ? batch : perSlice ? slices : sync)[names[n]];
            if (!record) continue;
            x.wall.push_back(wall);
            if (!inBatch) x.device.push_back(b.LastDeviceMs().value_or(-1));
            x.waits.push_back(double(b.Submissions().hostWaits - c0.hostWaits));
            x.draws.push_back(double(b.Draws() - d0));
        }
        if (inBatch) {
            const SubmissionCounts c0 = b.Submissions();
            const auto t0 = std::chrono::steady_clock::now();
            auto ms = b.EndBatch();
            endBatch.push_back(
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            ASSERT_TRUE(ms.has_value());
            for (int n = 0; n < 7; ++n) batch[names[n]].device.push_back((*ms)[n]);
            waitsBatch.push_back(double(b.Submissions().hostWaits - c0.hostWaits));
        }
        const double stepMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - step0).count();
        if (record) (inBatch ? stepBatch : perSlice ? stepSlices : stepSync).push_back(stepMs);
        cur = o;
        list.Update();
    }
    std::printf("thesis-medium on %s, %d steps per mode after %d, interleaved; median (min-max)\n", b.Device().c_str(),
                measured / 3, warm);
    std::printf("%-13s %6s %6s %-22s %-22s | %6s %-22s %-22s | %6s %-22s %-22s\n", "stage", "draws", "waits",
                "sync wall", "sync device", "waits", "batch wall (record)", "batch device", "draws", "per-slice wall",
                "per-slice device");
    auto span = [](const std::vector<double>& v) {
        char text[64];
        std::snprintf(text, sizeof text, "%.2f (%.2f-%.2f)", PipeMedian(v), *std::min_element(v.begin(), v.end()),
                      *std::max_element(v.begin(), v.end()));
        return std::string(text);
    };
    for (const char* n : names) {
        const Samples &s = sync[n], &p = batch[n], &l = slices[n];
        std::printf("%-13s %6.0f %6.0f %-22s %-22s | %6.0f %-22s %-22s | %6.0f %-22s %-22s\n", n, PipeMedian(s.draws),
                    PipeMedian(s.waits), span(s.wall).c_str(), span(s.device).c_str(), PipeMedian(p.waits),
                    span(p.wall).c_str(), span(p.device).c_str(), PipeMedian(l.draws), span(l.wall).c_str(),
                    span(l.device).c_str());
    }
    std::printf("EndBatch wall %s ms, its waits %.0f\nstep wall: sync %s ms, batch %s ms, per-slice sync %s ms\n",
                span(endBatch).c_str(), PipeMedian(waitsBatch), span(stepSync).c_str(), span(stepBatch).c_str(),
                span(stepSlices).c_str());
    b.SetLayered(true);

    // The 1080p image: Download from the pixel buffer vs from the texture (any write in between).
    SplatParams big = MakeSplatParams(sc, camera);
    big.camera = MakeCameraFrame(camera, 1920, 1080);
    const SplatOrder bigOrder =
        MakeSplatOrder(big.camera, e, {big.origin[0], big.origin[1], big.origin[2]}, big.voxelSize);
    big.order = &bigOrder;
    auto bigImage = test::MakeBuffer(b, BufferFormat::F32, {3, 1920, 1080});
    std::vector<float> pixels(bigImage->CanonicalBytes() / 4);
    std::vector<double> render, fromCopy, fromTexture;
    for (int r = 0; r < 7; ++r) {
        SplatInputs si{q[0].get(), q[1].get(), T.get(), tl[0].get(), tl[1].get(), bd[0].get(), bd[1].get(), G.get()};
        auto t0 = std::chrono::steady_clock::now();
        ASSERT_TRUE(b.RenderSplat(big, si, *bigImage, nullptr).has_value());
        auto t1 = std::chrono::steady_clock::now();
        ASSERT_TRUE(b.Download(*bigImage, std::as_writable_bytes(std::span(pixels))).has_value());
        auto t2 = std::chrono::steady_clock::now();
        auto other = test::MakeBuffer(b, BufferFormat::U8, {1, 1, 1});
        auto t3 = std::chrono::steady_clock::now();
        ASSERT_TRUE(b.Download(*bigImage, std::as_writable_bytes(std::span(pixels))).has_value());
        auto t4 = std::chrono::steady_clock::now();
        render.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        fromCopy.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
        fromTexture.push_back(std::chrono::duration<double, std::milli>(t4 - t3).count());
    }
    std::printf("1920x1080 render_splat %s ms; Download from the pixel buffer %s ms, from the texture %s ms\n",
                span(render).c_str(), span(fromCopy).c_str(), span(fromTexture).c_str());
}
#endif

}  // namespace
}  // namespace cb
