// Temporal reprojection (SPEC 19, core/math/Reprojection.h) and the camera tracks it runs along: the Bayer order, the
// reprojection's geometry and filter against hand-worked cases and closed forms, the march's depth against the
// homogeneous slab's integral, and the CPU's reprojected frames against full frames and against what their pixels
// must hold (a traced pixel the full frame's bits; an empty sky the background, whatever the previous frame held).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "core/math/March.h"
#include "core/math/Reprojection.h"
#include "core/plan/SceneLoad.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/MarchTestUtil.h"
#include "tests/SceneTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// ---- The order --------------------------------------------------------------------

TEST(Reprojection, BayerRanksAreTheClassicMatrices) {
    // Rows y, columns x.
    const uint32_t two[2][2] = {{0, 2}, {3, 1}};
    const uint32_t four[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
    for (uint32_t y = 0; y < 2; ++y)
        for (uint32_t x = 0; x < 2; ++x) EXPECT_EQ(BayerRank(2, x, y), two[y][x]) << x << ", " << y;
    for (uint32_t y = 0; y < 4; ++y)
        for (uint32_t x = 0; x < 4; ++x) EXPECT_EQ(BayerRank(4, x, y), four[y][x]) << x << ", " << y;
    EXPECT_EQ(BayerRank(1, 0, 0), 0u);
}

TEST(Reprojection, EveryPixelOfABlockIsTracedOnceInKSquaredFrames) {
    const CameraFrame camera{};
    for (uint32_t k : {2u, 4u}) {
        std::set<std::pair<uint32_t, uint32_t>> cells;
        for (uint32_t f = 1; f <= k * k; ++f) {
            const ReprojectionSetup r = MakeReprojection(k, f, false, camera);
            EXPECT_FALSE(r.full);
            EXPECT_LT(r.offsetX, k);
            EXPECT_LT(r.offsetY, k);
            cells.insert({r.offsetX, r.offsetY});
        }
        EXPECT_EQ(cells.size(), size_t(k * k));
        // Frame f traces the cell of rank f mod k^2.
        const ReprojectionSetup r = MakeReprojection(k, k * k + 3, false, camera);
        EXPECT_EQ(BayerRank(k, r.offsetX, r.offsetY), 3u);
    }
    EXPECT_TRUE(MakeReprojection(4, 0, false, camera).full);  // the first frame
    EXPECT_TRUE(MakeReprojection(4, 9, true, camera).full);   // a camera cut
    EXPECT_TRUE(MakeReprojection(1, 9, false, camera).full);  // k = 1
}

TEST(Reprojection, ALastBlockTooShortTracesTheAxisLastPixel) {
    // 10 pixels in blocks of 4: blocks 0, 1 hold their offset; block 2 holds pixels 8 and 9 only.
    EXPECT_EQ(ReprojectionBlocks(10, 4), 3u);
    EXPECT_EQ(TracedCoordinate(1, 4, 3, 10), 7u);
    EXPECT_EQ(TracedCoordinate(2, 4, 1, 10), 9u);
    EXPECT_EQ(TracedCoordinate(2, 4, 3, 10), 9u);
}

// ---- Camera tracks -----------------------------------------------------------------

TEST(CameraTrack, MovesLinearlyHoldsAtTheEndsAndJumpsAtACut) {
    CameraSettings c;
    c.track = {{10, {0, 0, 0}, {10, 0, 0}, false}, {20, {4, 8, 0}, {10, 8, 2}, false}, {30, {100, 0, 0}, {0, 0, 0}, true}};
    EXPECT_EQ(c.At(0).eye, (std::array<double, 3>{0, 0, 0}));  // before the first keyframe
    const CameraSettings mid = c.At(15);                         // halfway from 10 to 20
    EXPECT_EQ(mid.eye, (std::array<double, 3>{2, 4, 0}));
    EXPECT_EQ(mid.target, (std::array<double, 3>{10, 4, 1}));
    EXPECT_EQ(c.At(20).eye, (std::array<double, 3>{4, 8, 0}));
    EXPECT_EQ(c.At(29).eye, (std::array<double, 3>{4, 8, 0}));  // held until the cut
    EXPECT_EQ(c.At(30).eye, (std::array<double, 3>{100, 0, 0}));
    EXPECT_EQ(c.At(1000).target, (std::array<double, 3>{0, 0, 0}));
    EXPECT_TRUE(c.At(15).track.empty());
    EXPECT_TRUE(c.CutAt(30));
    EXPECT_FALSE(c.CutAt(29));
    EXPECT_FALSE(c.CutAt(20));
}

constexpr const char* kTrackScene = R"({"grid": {"size": [8, 8, 8]}, "stages": ["noise", "shade", "render_march"],
  "render": {"cameras": [{"name": "fly", "track": TRACK}]}, "march": {"reprojection": {"block": BLOCK}}})";

std::string TrackScene(const std::string& track, const std::string& block = "4") {
    std::string text = kTrackScene;
    text.replace(text.find("TRACK"), 5, track);
    text.replace(text.find("BLOCK"), 5, block);
    return text;
}

TEST(CameraTrack, SceneReadsTheTrackAndTheBlock) {
    const Scene s = test::Parsed(TrackScene(
        R"([{"frame": 0, "eye": [0, 0, 0], "target": [1, 0, 0]}, {"frame": 8, "eye": [8, 0, 0], "target": [9, 0, 0], "cut": true}])"));
    ASSERT_EQ(s.render.cameras.size(), 1u);
    ASSERT_EQ(s.render.cameras[0].track.size(), 2u);
    EXPECT_TRUE(s.render.cameras[0].track[1].cut);
    EXPECT_EQ(s.march.reprojectionBlock, 4u);
}

TEST(CameraTrack, BadTracksAndBlocksAreRefusedWithTheirField) {
    const std::string a = R"({"frame": 5, "eye": [0, 0, 0], "target": [1, 0, 0]})";
    EXPECT_TRUE(test::HasLine(
        test::ErrorOf(TrackScene("[" + a + ", " + R"({"frame": 5, "eye": [1, 0, 0], "target": [2, 0, 0]})" + "]")),
        "test.json: render.cameras[0].track[1].frame: keyframes must come by increasing frame, got 5 after 5"));
    EXPECT_TRUE(test::HasLineStartingWith(
        test::ErrorOf(TrackScene("[" + a + ", " + R"({"frame": 9, "eye": [0, 0, 0], "target": [-1, 0, 0]})" + "]")),
        "test.json: render.cameras[0].track[1].target: the view direction turns through 180 degrees"));
    EXPECT_TRUE(test::HasLine(test::ErrorOf(TrackScene(R"([{"frame": 0, "eye": [1, 1, 1], "target": [1, 1, 1]}])")),
                              "test.json: render.cameras[0].track[0].target: must differ from eye"));
    EXPECT_TRUE(test::HasLine(test::ErrorOf(TrackScene(R"([{"eye": [0, 0, 0], "target": [1, 0, 0]}])")),
                              "test.json: render.cameras[0].track[0].frame: required field is missing"));
    EXPECT_TRUE(test::HasLineStartingWith(test::ErrorOf(TrackScene("[]")),
                                          "test.json: render.cameras[0].track: expected a non-empty array"));
    std::string both = TrackScene("[" + a + "]");
    both.replace(both.find("\"track\""), 0, R"("eye": [0, 0, 0], )");
    EXPECT_TRUE(test::HasLineStartingWith(test::ErrorOf(both),
                                          "test.json: render.cameras[0].eye: cannot be combined with track"));
    EXPECT_TRUE(test::HasLineStartingWith(test::ErrorOf(TrackScene("[" + a + "]", "3")),
                                          "test.json: march.reprojection.block:"));
}

// ---- Geometry and filter -----------------------------------------------------------

CameraFrame Camera(std::array<double, 3> eye, std::array<double, 3> target, uint32_t w = 64, uint32_t h = 48) {
    CameraSettings c;
    c.eye = eye;
    c.target = target;
    c.fovDeg = 50;
    return MakeCameraFrame(c, w, h);
}

TEST(Reprojection, AStillCameraFindsEveryPixelAtItsOwnCentre) {
    const CameraFrame c = Camera({100, -40, 30}, {0, 20, 60});
    for (float z : {1.0f, 37.5f, 900.0f, 1e5f})
        for (uint32_t y : {0u, 17u, 47u})
            for (uint32_t x : {0u, 31u, 63u}) {
                float px = -1, py = -1;
                ASSERT_TRUE(PreviousImagePosition(c, c, PixelPlaneU(c, x), PixelPlaneV(c, y), z, px, py));
                EXPECT_NEAR(px, x + 0.5f, 2e-3f) << z;
                EXPECT_NEAR(py, y + 0.5f, 2e-3f) << z;
            }
}

TEST(Reprojection, ASidewaysMoveShiftsAPointByFocalTimesMoveOverDepth) {
    // The camera looks along +x; the previous one stood 3 m further along -y (to its right: right = forward x up).
    const CameraFrame now = Camera({0, 0, 0}, {10, 0, 0}), before = Camera({0, -3, 0}, {10, -3, 0});
    ASSERT_NEAR(now.right[1], -1.0f, 1e-6f);
    const float z = 60;
    float px, py;
    const float u = PixelPlaneU(now, 20), v = PixelPlaneV(now, 24);
    ASSERT_TRUE(PreviousImagePosition(now, before, u, v, z, px, py));
    // The point is 3 m further to the previous camera's left: focal 3 / z pixels to the left.
    EXPECT_NEAR(px, 20.5f - now.focalPx * 3.0f / z, 1e-3f);
    EXPECT_NEAR(py, 24.5f, 1e-3f);
    // A point behind the previous camera, or beyond its image, is not found.
    const CameraFrame turned = Camera({0, 0, 0}, {-10, 0, 0});
    EXPECT_FALSE(PreviousImagePosition(now, turned, u, v, z, px, py));
    const CameraFrame far = Camera({0, -300, 0}, {10, -300, 0});
    EXPECT_FALSE(PreviousImagePosition(now, far, u, v, z, px, py));
}

TEST(Reprojection, BilinearReadsAPlaneExactlyAndClampsAtTheEdges) {
    const uint32_t W = 7, H = 5;
    std::vector<float> rgb(3 * W * H);
    auto plane = [](int c, float x, float y) { return 0.25f * float(c + 1) + 0.5f * x - 0.125f * y; };
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x)
            for (int c = 0; c < 3; ++c) rgb[3 * (x + W * y) + c] = plane(c, float(x), float(y));
    for (float px : {0.5f, 1.75f, 3.2f, 6.5f})
        for (float py : {0.5f, 2.9f, 4.5f})
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(BilinearRgb(rgb.data(), W, H, px, py)[c], plane(c, px - 0.5f, py - 0.5f), 1e-5f);
    // Within half a pixel of the border the edge pixels are read.
    EXPECT_FLOAT_EQ(BilinearRgb(rgb.data(), W, H, 0.0f, 0.0f)[0], plane(0, 0, 0));
    EXPECT_FLOAT_EQ(BilinearRgb(rgb.data(), W, H, 7.0f, 5.0f)[2], plane(2, 6, 4));
}

// The march's depth through a homogeneous slab along z from t0 to t1 with optical depth s per voxel edge: the mean
// of t under the density s e^{-s (t - t0)} on [t0, t1], t0 + 1/s - L e^{-s L} / (1 - e^{-s L}).
TEST(Reprojection, TheMarchDepthOfAHomogeneousSlabIsItsClosedForm) {
    MarchSetup s = test::PlainSetup({4, 4, 40}, 0.08f);
    s.step = 0.01f;
    MarchRayGeometry ray;
    ray.origin = {2, 2, 0};
    ray.dir = {0, 0, 1};
    ray.tMin = 5, ray.tMax = 35;
    auto q = [](const Vec3&) { return 1.0f; };
    auto light = [](const Vec3&) { return MarchLightSample{}; };
    const MarchRayResult r = MarchRay(s, ray, 0.5f, nullptr, q, light);
    const double sigma = 0.08, L = 30, e = std::exp(-sigma * L);
    const double expected = 5 + 1 / sigma - L * e / (1 - e);
    EXPECT_NEAR(r.depthSum / (1.0 - r.transmittance), expected, 2e-3 * expected);
    // In metres along the view axis, h = 2 and the ray at 60 degrees to it: t h cos.
    EXPECT_NEAR(MarchViewDepth(r.depthSum, r.transmittance, 2.0f, 0.5f, 1e5f), expected, 2e-3 * expected);
    EXPECT_EQ(MarchViewDepth(0.0f, 1.0f, 2.0f, 0.5f, 1e5f), 1e5f);  // nothing on the ray: the far plane
}

// ---- The CPU's reprojected frames ----------------------------------------------------

struct Frames {
    Extent3 grid{32, 32, 32};
    std::vector<float> q;
    cpu::BackendCpu backend{2};
    std::unique_ptr<Buffer> qb, tb;

    explicit Frames(bool empty) {
        q = empty ? std::vector<float>(grid.Count(), 0.0f)
                  : test::GaussianBlobField(grid, {{10, 12, 8, 3}, {22, 20, 14, 4}, {14, 24, 18, 2.5}});
        qb = test::MakeFilled(backend, BufferFormat::F32, grid, q);
        tb = test::MakeFilled(backend, BufferFormat::F32, grid, std::vector<float>(grid.Count(), 1.0f));
    }
    MarchParams Params(std::array<double, 3> eye, std::array<double, 3> target) const {
        MarchParams p = test::CameraParams(grid, eye, target, 61, 45);
        p.setup.epsilon = 0.01f;
        return p;
    }
    // Renders p into `image` (which holds the previous frame when p reprojects) and returns the image.
    std::vector<float> Render(const MarchParams& p, Buffer& image) {
        const Status s = backend.RenderMarch(p, {qb.get(), qb.get(), tb.get()}, image, nullptr);
        EXPECT_TRUE(s.has_value()) << s.error().message;
        return test::Read<float>(backend, image);
    }
    std::unique_ptr<Buffer> Image(const MarchParams& p, float fill) {
        return test::MakeFilled(backend, BufferFormat::F32, {3, p.camera.width, p.camera.height},
                                std::vector<float>(3 * p.camera.width * p.camera.height, fill));
    }
};

// PSNR of `got` against `reference`: 10 log10(peak^2 / MSE), peak the reference's largest value.
double Psnr(const std::vector<float>& got, const std::vector<float>& reference) {
    double mse = 0, peak = 0;
    for (size_t i = 0; i < got.size(); ++i) {
        mse += (double(got[i]) - reference[i]) * (double(got[i]) - reference[i]);
        peak = std::max(peak, double(reference[i]));
    }
    mse /= double(got.size());
    return 10 * std::log10(peak * peak / mse);
}

// The traced pixel (x, y) of block (bx, by) under r.
std::pair<uint32_t, uint32_t> Traced(const ReprojectionSetup& r, uint32_t bx, uint32_t by, uint32_t W, uint32_t H) {
    return {std::min(bx * r.block + r.offsetX, W - 1), std::min(by * r.block + r.offsetY, H - 1)};
}

TEST(ReprojectionCpu, TracedPixelsAreTheFullFramesAndTheRestLieWithinTheirNeighbours) {
    Frames f(false);
    const MarchParams before = f.Params({-20, 6, 20}, {16, 16, 16});
    for (uint32_t k : {2u, 4u}) {
        MarchParams now = f.Params({-19, 7, 20.5}, {16, 16.5, 16});
        auto image = f.Image(now, 0.0f);
        f.Render(before, *image);
        const std::vector<float> full = f.Render(now, *f.Image(now, 0.0f));
        now.reprojection = MakeReprojection(k, 5, false, before.camera);
        ASSERT_FALSE(now.reprojection.full);
        const std::vector<float> got = f.Render(now, *image);
        const uint32_t W = now.camera.width, H = now.camera.height;
        const uint32_t bw = ReprojectionBlocks(W, k), bh = ReprojectionBlocks(H, k);
        size_t traced = 0, differing = 0;
        for (uint32_t y = 0; y < H; ++y)
            for (uint32_t x = 0; x < W; ++x) {
                const uint32_t bx = x / k, by = y / k;
                const size_t i = 3 * (x + size_t(W) * y);
                if (Traced(now.reprojection, bx, by, W, H) == std::pair{x, y}) {
                    ++traced;
                    for (int c = 0; c < 3; ++c) ASSERT_EQ(got[i + c], full[i + c]) << x << ", " << y;
                    continue;
                }
                for (int c = 0; c < 3; ++c) {
                    float lo = INFINITY, hi = -INFINITY;
                    for (uint32_t ny = by ? by - 1 : 0; ny <= std::min(by + 1, bh - 1); ++ny)
                        for (uint32_t nx = bx ? bx - 1 : 0; nx <= std::min(bx + 1, bw - 1); ++nx) {
                            const auto [tx, ty] = Traced(now.reprojection, nx, ny, W, H);
                            lo = std::min(lo, full[3 * (tx + size_t(W) * ty) + c]);
                            hi = std::max(hi, full[3 * (tx + size_t(W) * ty) + c]);
                        }
                    ASSERT_GE(got[i + c], lo) << x << ", " << y;
                    ASSERT_LE(got[i + c], hi) << x << ", " << y;
                    differing += got[i + c] != full[i + c];
                }
            }
        EXPECT_EQ(traced, size_t(bw) * bh);
        EXPECT_GT(differing, 0u);  // the untraced pixels came from the previous frame, not from a trace
        EXPECT_GT(Psnr(got, full), 30.0) << k;
    }
}

// An empty sky: every traced colour is the background, so the clamp gives the background whatever the previous frame
// held (here 7 in every channel, far from it).
TEST(ReprojectionCpu, AnEmptySkyIsTheBackgroundWhateverThePreviousFrameHeld) {
    Frames f(true);
    MarchParams now = f.Params({-19, 7, 20.5}, {16, 16.5, 16});
    now.reprojection = MakeReprojection(4, 7, false, f.Params({-20, 6, 20}, {16, 16, 16}).camera);
    auto image = f.Image(now, 7.0f);
    const std::vector<float> got = f.Render(now, *image);
    for (size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], now.setup.background[i % 3]) << i;
}

// The camera turned through 90 degrees: no point is in the previous image, so every pixel takes its block's traced
// colour.
TEST(ReprojectionCpu, WithNothingToReprojectEveryPixelTakesItsBlocksTracedColour) {
    Frames f(false);
    MarchParams now = f.Params({-20, 16, 16}, {16, 16, 16});
    const std::vector<float> full = f.Render(now, *f.Image(now, 0.0f));
    now.reprojection = MakeReprojection(2, 3, false, f.Params({-20, 16, 16}, {-20, 50, 16}).camera);
    auto image = f.Image(now, 7.0f);
    const std::vector<float> got = f.Render(now, *image);
    const uint32_t W = now.camera.width, H = now.camera.height;
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            const auto [tx, ty] = Traced(now.reprojection, x / 2, y / 2, W, H);
            for (int c = 0; c < 3; ++c)
                ASSERT_EQ(got[3 * (x + size_t(W) * y) + c], full[3 * (tx + size_t(W) * ty) + c]) << x << ", " << y;
        }
}

// Through the harness: the run numbers its frames, the first traces every pixel, the next ones one ray per 4 x 4 block
// (the rays that meet the box, at most one per block), and a camera cut traces every pixel again.
TEST(ReprojectionRun, TheFirstFrameAndACutTraceEveryPixelTheOthersOneABlock) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/noise-flight.json",
                           {{"grid.size", "[32, 32, 32]"},
                            {"grid.voxel_size", "200"},
                            {"render.width", "64"},
                            {"render.height", "48"},
                            {"steps", "4"},
                            {"render.cameras", R"([{"name": "fly", "track": [
                                {"frame": 0, "eye": [1600, 1800, 150], "target": [4600, 4800, 1800]},
                                {"frame": 2, "eye": [1650, 1850, 160], "target": [4600, 4700, 1800]},
                                {"frame": 3, "eye": [3200, 3200, 3200], "target": [5200, 4800, 600], "cut": true}]}])"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    cpu::BackendCpu backend(2);
    auto sim = Simulation::Create(*scene, backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    static_assert(kMarchCounters[0].name == "rays");
    std::vector<uint64_t> rays;
    for (uint32_t t = 0; t < scene->steps; ++t) {
        StepRecord record;
        ASSERT_TRUE((*sim)->Step(record).has_value());
        ASSERT_EQ(record.frames.size(), 1u);
        rays.push_back(record.frames[0].counters[0]);
    }
    EXPECT_EQ((*sim)->FramesDrawn(), 4u);
    const uint64_t blocks = 16 * 12;
    ASSERT_EQ(rays.size(), 4u);
    EXPECT_GT(rays[0], blocks);
    EXPECT_LE(rays[1], blocks);
    EXPECT_GT(rays[1], 0u);
    EXPECT_LE(rays[2], blocks);
    EXPECT_GT(rays[3], blocks);
}

}  // namespace
}  // namespace cb
