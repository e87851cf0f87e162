// Metamorphic invariant of both renderers (docs/testing.md,
// "Metamorphic invariants: culling, skipping, origin"): moving the grid's
// corner and the cameras by an exactly representable offset changes no pixel
// (docs/pipeline.md, "Floating point"). Every backend, ground on.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "tests/MetamorphicRender.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// The same fixture, instantiated here on its own.
class MetamorphicOrigin : public MetamorphicRenderBackend {};

// ---- Moving the world origin -------------------------------------------------------
//
// h = 2 (a power of two); the grid's corner and the cameras move by Delta =
// (2048, -4096, 1024) = 2^k h. Every coordinate (corner, voxel centres
// corner + (i + 1/2) h, eyes, targets) is a float with spare bits before and
// after the move, so each difference the renderers form (centre - eye,
// (eye - corner)/h) is exact and the same: the images must be equal bit for
// bit, ground on (the plane z = corner z moves with it).
TEST_P(MetamorphicOrigin, MovingTheOriginChangesNothing) {
    MetaScene s;
    s.grid = {16, 12, 6};
    s.h = 2;
    s.origin = {-8, 4, 0};
    s.qPrev = test::GaussianBlobField(s.grid, {{4, 4, 2, 1.5}, {12, 7, 3, 1.8}});
    s.qCur = test::GaussianBlobField(s.grid, {{5, 5, 2.5, 1.5}, {11, 8, 3, 1.8}});
    s.T.resize(s.grid.Count());
    for (size_t n = 0; n < s.T.size(); ++n) s.T[n] = 0.3f + 0.7f * float((n * 2654435761u) % 1000) / 1000.0f;
    s.G.resize(size_t(s.grid.nx) * s.grid.ny);
    for (uint32_t j = 0; j < s.grid.ny; ++j)
        for (uint32_t i = 0; i < s.grid.nx; ++i)
            s.G[i + s.grid.nx * j] = 0.2f + 0.8f * float((i * 7 + j * 3) % 11) / 10.0f;
    s.splatDiameter = 3;
    const std::array<double, 3> delta{2048, -4096, 1024};
    const std::array<std::array<std::array<double, 3>, 2>, 3> views = {{
        {{{-20.5, -14.25, 18}, {8, 16, 2}}},  // oblique: sky, ground, clouds
        {{{8.5, 12, 40}, {9, 12.5, 0}}},      // from above
        {{{10, 14, 5}, {30, 2, 3}}},          // inside, looking out over the ground
    }};
    const uint32_t W = 56, H = 40;
    for (const auto& v : views) {
        MetaScene moved = s;
        std::array<double, 3> eye = v[0], target = v[1];
        for (int a = 0; a < 3; ++a) {
            moved.origin[a] = float(s.origin[a] + delta[a]);
            ASSERT_EQ(double(moved.origin[a]), s.origin[a] + delta[a]);  // exact
            eye[a] += delta[a];
            target[a] += delta[a];
            ASSERT_EQ(double(float(eye[a])), eye[a]);
        }
        const CameraSettings here = MetaCamera(v[0], v[1], 70), there = MetaCamera(eye, target, 70);
        const std::vector<float> a = MetaRenderSplat(*mBackend, s, here, W, H, true, true).rgb;
        const std::vector<float> b = MetaRenderSplat(*mBackend, moved, there, W, H, true, true).rgb;
        EXPECT_GT(MetaNonBackground(a), size_t(W) * H / 4);
        EXPECT_TRUE(a == b) << "splat: " << MetaFirstDifference(a, b, W);
        if (!HasMarch()) continue;
        const std::vector<float> c = MetaRenderMarch(*mBackend, s, here, W, H, true, 4);
        const std::vector<float> d = MetaRenderMarch(*mBackend, moved, there, W, H, true, 4);
        EXPECT_GT(MetaNonBackground(c), size_t(W) * H / 4);
        EXPECT_TRUE(c == d) << "march: " << MetaFirstDifference(c, d, W);
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, MetamorphicOrigin, ::testing::ValuesIn(cb::test::TestBackends()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace cb
