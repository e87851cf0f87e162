// Shafts of light (SPEC 18, core/math/Shafts.h): the shells against sums and integrals worked by hand, and the GPU
// backends' passes against the CPU's.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "BackendTestUtil.h"
#include "core/math/Shafts.h"
#include "registry/Registry.h"

namespace cb {
namespace {

constexpr double kVoxel = 10;  // h, metres

// A 1 x 1 image looks along `forward` exactly: its one pixel's ray is the view axis (cos 1).
CameraFrame OnePixelCamera(std::array<double, 3> eyeVoxels, std::array<double, 3> direction, double farMetres) {
    CameraSettings c;
    c.eye = {eyeVoxels[0] * kVoxel, eyeVoxels[1] * kVoxel, eyeVoxels[2] * kVoxel};
    c.target = {c.eye[0] + direction[0], c.eye[1] + direction[1], c.eye[2] + direction[2]};
    c.nearPlane = 1;
    c.farPlane = farMetres;
    return MakeCameraFrame(c, 1, 1);
}

struct Haze {
    uint32_t shells = 50;
    double extinction = 2e-3;  // per metre: 0.02 per voxel edge
    double g = 0.6;
    double falloffDeg = 0;
    Vec3 sun = SunDirection(30 * std::numbers::pi / 180, 0);
    ShadowForm form = ShadowForm::Beer;
    double cloudSigma = 0.05, kappa = 0.3;
    bool tiling = true;
    uint32_t nz = 20;  // the haze's top at 10 voxels
};

ShaftsFrame FrameOf(const Haze& h, const CameraFrame& camera) {
    ShaftsSettings s;
    s.on = true;
    s.shells = h.shells;
    s.extinction = h.extinction;
    s.g = h.g;
    s.falloffDeg = h.falloffDeg;
    return MakeShaftsFrame(s, camera, {0, 0, 0}, float(kVoxel), 8, 8, h.nz, h.tiling, h.sun, {1, 0.5f, 0.25f}, h.form,
                           float(h.cloudSigma), float(h.kappa), 0.7f, 0.6f);
}

// Henyey-Greenstein's 4 pi p in double, written out again.
double Hg(double g, double c) { return (1 - g * g) / std::pow(1 + g * g - 2 * g * c, 1.5); }

double Dot(const Vec3& a, const std::array<double, 3>& b) {
    const double n = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    return (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / n;
}

// The red channel of pixel (0, 0) with every column's D equal to `column`.
float Red(const ShaftsFrame& frame, float column) {
    return ShaftsPixel(frame, 0, 0, [column](uint32_t, uint32_t) { return column; })[0];
}

TEST(Shafts, ClearSkyIsTheShellSumOfTheHazeIntegral) {
    // The eye 2 voxels up, level: the ray stays in the haze to the far plane, 200 voxels; 50 shells 4 apart, all
    // inside. With no cloud G = 1, so the pixel is sigma dr P^ sum_j exp(-sigma (j + 1/2) dr), a geometric series.
    const std::array<double, 3> dir{1, 0.5, 0};
    Haze h;
    const ShaftsFrame frame = FrameOf(h, OnePixelCamera({1, 1, 2}, dir, 2000));
    ASSERT_FLOAT_EQ(frame.shellSpacing, 4.0f);
    const double sigma = h.extinction * kVoxel, dr = 4, q = std::exp(-sigma * dr);
    const double series = std::exp(-sigma * dr / 2) * (1 - std::pow(q, 50)) / (1 - q);
    const double phase = Hg(h.g, Dot(h.sun, dir));
    EXPECT_NEAR(Red(frame, 0), sigma * dr * phase * series, 1e-5 * sigma * dr * phase * series);
    // The green channel is the sun's green, half the red.
    EXPECT_FLOAT_EQ(ShaftsPixel(frame, 0, 0, [](uint32_t, uint32_t) { return 0.0f; })[1], 0.5f * Red(frame, 0));

    // 1000 shells: the midpoint rule of P^ integral_0^200 sigma exp(-sigma t) dt = P^ (1 - exp(-4)), whose error
    // is at most (sigma dr)^2 / 24 of it (and a float sum of 1000 terms, within 1e-4).
    h.shells = 1000;
    const double exact = phase * (1 - std::exp(-sigma * 200));
    const double midpointBound = (sigma * 0.2) * (sigma * 0.2) / 24;
    EXPECT_NEAR(Red(FrameOf(h, OnePixelCamera({1, 1, 2}, dir, 2000)), 0), exact, exact * (midpointBound + 1e-4));
}

TEST(Shafts, TheSlabAndTheNearPlaneClipTheShells) {
    // Looking straight up from 2 voxels: the haze ends 8 voxels on, at its top (nz / 2 = 10). 100 shells 2 apart
    // (far 2000 m): r = 1, 3, 5, 7 count, 9 does not.
    Haze h;
    h.shells = 100;
    const double sigma = h.extinction * kVoxel;
    const double phase = Hg(h.g, h.sun[2]);
    const double up =
        sigma * 2 * phase * (std::exp(-sigma) + std::exp(-3 * sigma) + std::exp(-5 * sigma) + std::exp(-7 * sigma));
    EXPECT_NEAR(Red(FrameOf(h, OnePixelCamera({1, 1, 2}, {0, 0, 1}, 2000)), 0), up, 1e-5 * up);
    // A near plane 40 m (4 voxels) away drops r = 1 and 3.
    CameraFrame nearer = OnePixelCamera({1, 1, 2}, {0, 0, 1}, 2000);
    nearer.nearPlane = 40;
    const double clipped = sigma * 2 * phase * (std::exp(-5 * sigma) + std::exp(-7 * sigma));
    EXPECT_NEAR(Red(FrameOf(h, nearer), 0), clipped, 1e-5 * clipped);
    // Above the haze looking up: nothing.
    EXPECT_EQ(Red(FrameOf(h, OnePixelCamera({1, 1, 12}, {0, 0, 1}, 2000)), 0), 0.0f);
}

TEST(Shafts, UniformCloudShadowsEveryShellAndVeilsTheHazeBelow) {
    // Every column's D = 3 (tiled): the beer form gives every shell point G = exp(-sigma h D / s_z), and an eye
    // above the haze looking straight down sees it through exp(-sigma h D / |d_z|). From 30 voxels up the haze is
    // t in [20, 30]; 100 shells 2 apart: r = 21, 23, 25, 27, 29.
    Haze h;
    h.shells = 100;
    const double sigma = h.extinction * kVoxel, tau = h.cloudSigma * kVoxel * 3;
    const double phase = Hg(h.g, -h.sun[2]);
    double sum = 0;
    for (double r : {21, 23, 25, 27, 29}) sum += std::exp(-sigma * r);
    const double clear = sigma * 2 * phase * sum;
    const CameraFrame down = OnePixelCamera({1, 1, 30}, {0, 0, -1}, 2000);
    EXPECT_NEAR(Red(FrameOf(h, down), 0), clear, 1e-5 * clear);
    const double shadowed = clear * std::exp(-tau / h.sun[2]) * std::exp(-tau);
    EXPECT_NEAR(Red(FrameOf(h, down), 3), shadowed, 1e-5 * shadowed);
    // The thesis's form does not depend on the path: 1 - clamp(kappa D) for the sun's and the view's crossing.
    h.form = ShadowForm::Thesis;
    const double thesis = clear * (1 - 0.3 * 3 * 0.5) * (1 - 0.3 * 3 * 0.5);
    EXPECT_NEAR(Red(FrameOf(h, down), 1.5f), thesis, 1e-5 * thesis);
    // Looking up from below the haze's top the cloud is not in front: the sun's shadow alone.
    h.form = ShadowForm::Beer;
    const double upClear = Red(FrameOf(h, OnePixelCamera({1, 1, 2}, {0, 0, 1}, 2000)), 0);
    EXPECT_NEAR(Red(FrameOf(h, OnePixelCamera({1, 1, 2}, {0, 0, 1}, 2000)), 3), upClear * std::exp(-tau / h.sun[2]),
                1e-5 * upClear);
}

TEST(Shafts, EachShellReadsTheColumnItsSunRayCrosses) {
    // The sun 45 degrees up along +x: from a shell point at height z the sun ray reaches the mid-height (10)
    // 10 - z voxels further along x. Looking straight up from (0.5, 4.5, 2), the shells r = 1, 3, 5, 7 sit at z = 3,
    // 5, 7, 9 and read the columns centred at x = 7.5, 5.5, 3.5, 1.5 (i = 7, 5, 3, 1; j = 4). Cloud in column (3, 4)
    // alone (untiled) shadows the shell r = 5 alone, by exp(-sigma h D / s_z).
    Haze h;
    h.shells = 100;
    h.tiling = false;
    h.sun = SunDirection(std::numbers::pi / 4, 0);
    const ShaftsFrame frame = FrameOf(h, OnePixelCamera({0.5, 4.5, 2}, {0, 0, 1}, 2000));
    auto oneColumn = [](uint32_t i, uint32_t j) { return i == 3 && j == 4 ? 2.0f : 0.0f; };
    const double sigma = h.extinction * kVoxel, shadow = std::exp(-h.cloudSigma * kVoxel * 2 / std::sqrt(0.5));
    const double expected =
        sigma * 2 * Hg(h.g, std::sqrt(0.5)) *
        (std::exp(-sigma) + std::exp(-3 * sigma) + shadow * std::exp(-5 * sigma) + std::exp(-7 * sigma));
    EXPECT_NEAR(ShaftsPixel(frame, 0, 0, oneColumn)[0], expected, 1e-5 * expected);
}

TEST(Shafts, FalloffScalesByTheAngleToTheSun) {
    // The sun 30 degrees up ahead (azimuth 0); looking level along +x is 30 degrees from it. A falloff of 60
    // degrees scales the pixel by (cos 30 - cos 60) / (1 - cos 60); one of 20 degrees removes it.
    Haze h;
    const CameraFrame level = OnePixelCamera({1, 1, 2}, {1, 0, 0}, 2000);
    const double off = Red(FrameOf(h, level), 0);
    ASSERT_GT(off, 0.0);
    h.falloffDeg = 60;
    const double f = (std::cos(std::numbers::pi / 6) - 0.5) / 0.5;
    EXPECT_NEAR(Red(FrameOf(h, level), 0), off * f, 1e-5 * off);
    h.falloffDeg = 20;
    EXPECT_EQ(Red(FrameOf(h, level), 0), 0.0f);
}

TEST(Shafts, ColumnsReadBilinearlyAndWrapWithTiling) {
    // D of column (i, j) = i + 10 j on a 4 x 3 grid: bilinear between centres (i + 0.5, j + 0.5) is x - 0.5 +
    // 10 (y - 0.5) inside; outside, taps read 0 untiled and wrap tiled (one period over is the same value).
    auto d = [](uint32_t i, uint32_t j) { return float(i + 10 * j); };
    EXPECT_FLOAT_EQ(ShaftsColumnAt(1.5f, 1.5f, 4, 3, false, d), 11.0f);
    EXPECT_FLOAT_EQ(ShaftsColumnAt(2.25f, 1.0f, 4, 3, false, d), 1.75f + 5.0f);
    EXPECT_FLOAT_EQ(ShaftsColumnAt(-3.0f, 1.5f, 4, 3, false, d), 0.0f);
    EXPECT_FLOAT_EQ(ShaftsColumnAt(4.0f, 1.5f, 4, 3, false, d), 0.5f * 13.0f);  // half of the last column, half 0
    EXPECT_FLOAT_EQ(ShaftsColumnAt(2.25f + 4.0f, 1.0f - 3.0f, 4, 3, true, d), 1.75f + 5.0f);
    // Between the last column and the first, across the seam: the mean of columns 3 and 0 in row 1.
    EXPECT_FLOAT_EQ(ShaftsColumnAt(4.0f, 1.5f, 4, 3, true, d), 0.5f * (13.0f + 10.0f));
}

// The CPU's image and a GPU backend's for the same frames and D: a twin of ShaftsPixel as the shaders run it.
class ShaftsBackends : public test::BackendTest {};

TEST_P(ShaftsBackends, MatchTheCpu) {
    const uint32_t W = 37, H = 23, nx = 8, ny = 6;
    std::vector<float> column(nx * ny);
    for (size_t n = 0; n < column.size(); ++n) column[n] = float((n * 37) % 11) * 0.7f;
    std::vector<float> start(3 * W * H);
    for (size_t n = 0; n < start.size(); ++n) start[n] = float(n % 7) * 0.125f;
    auto cpu = CreateBackend("cpu", {});
    ASSERT_TRUE(cpu) << cpu.error().message;
    struct View {
        std::array<double, 3> eye, target;
    };
    const View views[] = {{{40, 30, 20}, {0, 0, 60}},     // below the haze's top, looking up across the grid
                          {{-20, 30, 50}, {80, 30, 10}},  // inside, level-ish
                          {{40, 30, 400}, {10, 10, 0}}};  // above, looking down through the cloud layer
    for (const View& v : views)
        for (ShadowForm form : {ShadowForm::Beer, ShadowForm::Thesis, ShadowForm::Wang})
            for (bool tiling : {false, true}) {
                CameraSettings c;
                c.eye = v.eye;
                c.target = v.target;
                c.farPlane = 3000;
                ShaftsSettings s;
                s.on = true;
                s.shells = 96;
                s.extinction = 2e-3;
                s.falloffDeg = form == ShadowForm::Thesis ? 120 : 0;
                const ShaftsFrame frame =
                    MakeShaftsFrame(s, MakeCameraFrame(c, W, H), {0, 0, 0}, 10.0f, nx, ny, 12, tiling,
                                    SunDirection(0.5, 2.0), {1.5f, 1.2f, 0.9f}, form, 0.04f, 0.3f, 0.7f, 0.6f);
                std::vector<float> images[2];
                Backend* backends[] = {cpu->get(), mBackend.get()};
                for (int b = 0; b < 2; ++b) {
                    auto D = backends[b]->CreateBuffer(BufferFormat::F32, {nx, ny, 1});
                    auto image = backends[b]->CreateBuffer(BufferFormat::F32, {3, W, H});
                    ASSERT_TRUE(D && image);
                    ASSERT_TRUE(backends[b]->Upload(**D, std::as_bytes(std::span(column))));
                    ASSERT_TRUE(backends[b]->Upload(**image, std::as_bytes(std::span(start))));
                    const Status added = backends[b]->AddShafts(frame, **D, **image);
                    ASSERT_TRUE(added) << added.error().message;
                    images[b].resize(start.size());
                    ASSERT_TRUE(backends[b]->Download(**image, std::as_writable_bytes(std::span(images[b]))));
                }
                double peak = 0, worst = 0;
                for (size_t n = 0; n < start.size(); ++n) {
                    peak = std::max(peak, double(images[0][n] - start[n]));
                    worst = std::max(worst, std::fabs(double(images[0][n]) - double(images[1][n])));
                }
                EXPECT_GT(peak, 1e-3) << "the shafts add light";
                // The same float operations on both sides; lavapipe's and llvmpipe's sqrt and division round alike.
                EXPECT_LE(worst, 1e-6 * (1 + peak))
                    << "form " << int(form) << " tiling " << tiling << " eye z " << v.eye[2];
            }
}

INSTANTIATE_TEST_SUITE_P(Gpu, ShaftsBackends, ::testing::ValuesIn(test::GpuTestBackends()),
                         [](const auto& info) { return info.param; });

TEST(Shafts, SunAtOrBelowTheHorizonAddsNothing) {
    auto cpu = CreateBackend("cpu", {});
    ASSERT_TRUE(cpu);
    std::vector<float> start(3 * 9 * 7);
    for (size_t n = 0; n < start.size(); ++n) start[n] = float(n) * 0.01f;
    for (double elevation : {0.0, -0.1, -1.2}) {
        CameraSettings c;
        c.eye = {40, 30, 20};
        c.target = {0, 0, 30};
        ShaftsSettings s;
        s.on = true;
        const ShaftsFrame frame =
            MakeShaftsFrame(s, MakeCameraFrame(c, 9, 7), {0, 0, 0}, 10.0f, 4, 4, 8, false, SunDirection(elevation, 0.3),
                            {1, 1, 1}, ShadowForm::Beer, 0.04f, 0.3f, 0.7f, 0.6f);
        auto D = (*cpu)->CreateBuffer(BufferFormat::F32, {4, 4, 1});
        auto image = (*cpu)->CreateBuffer(BufferFormat::F32, {3, 9, 7});
        ASSERT_TRUE(D && image);
        ASSERT_TRUE((*cpu)->Upload(**image, std::as_bytes(std::span(start))));
        ASSERT_TRUE((*cpu)->AddShafts(frame, **D, **image));
        std::vector<float> out(start.size());
        ASSERT_TRUE((*cpu)->Download(**image, std::as_writable_bytes(std::span(out))));
        EXPECT_EQ(out, start) << "elevation " << elevation;
    }
}

}  // namespace
}  // namespace cb
