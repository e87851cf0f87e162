// The ground shadow (SPEC 7) on the CPU backend, worked by hand: the lookup
// height, the thesis form and Wang's form.
#include <gtest/gtest.h>

#include <cmath>

#include "core/math/Shading.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

std::vector<float> ShadowOnCpu(const Extent3& e, const std::vector<float>& D, const ShadowParams& p) {
    cpu::BackendCpu backend;
    auto d = test::MakeFilled(backend, BufferFormat::F32, {e.nx, e.ny, 1}, D);
    auto G = test::MakeBuffer(backend, BufferFormat::F32, {e.nx, e.ny, 1});
    EXPECT_TRUE(backend.Shadow(p, *d, *G).has_value());
    return test::Read<float>(backend, *G);
}

// Test the ground shadow: overhead sun reads D straight above (exp(-sigma h D));
// a sun at 45 degrees in x reads D nz/2 cells toward +x; the thesis form is
// 1 - clamp(kappa D); no sun above the horizon gives 1.
TEST(Shadow, HandWorked) {
    const Extent3 e{10, 4, 8};
    std::vector<float> D(40, 0.0f);
    D[5 + 10 * 2] = 2.0f;
    ShadowParams p;
    p.sigma = 0.01f;
    p.voxelSize = 50;
    p.nz = e.nz;
    p.sun = {0, 0, 1};
    std::vector<float> G = ShadowOnCpu(e, D, p);
    EXPECT_FLOAT_EQ(G[5 + 10 * 2], std::exp(-0.01f * 50 * 2.0f));
    EXPECT_EQ(G[4 + 10 * 2], 1.0f);
    const float s = std::sqrt(0.5f);
    p.sun = {s, 0, s};  // offset nz/2 = 4 cells toward +x
    G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[1 + 10 * 2], std::exp(-0.01f * 50 * 2.0f / s), 1e-6);
    EXPECT_EQ(G[5 + 10 * 2], 1.0f);
    p.form = ShadowForm::Thesis;
    p.kappa = 0.3f;
    G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[1 + 10 * 2], 1.0f - 0.6f, 1e-6);
    p.kappa = 1.0f;
    EXPECT_EQ(ShadowOnCpu(e, D, p)[1 + 10 * 2], 0.0f);  // clamped
    p.sun = {1, 0, 0};
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
    p.sun = {0.6f, 0, -0.8f};
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
    p.sun = SunDirection(1e-4, 0.0);  // grazing: finite
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_TRUE(std::isfinite(g));
}

// Test the lookup height where the hand-worked case above cannot:
// an odd nz = 7 at 45 degrees along +x reads 3.5 cells over, so with only
// D(5, 2) = 2, cells 1 and 2 of row 2 read halfway between columns 4|5 and 5|6:
// D = 1 for both, G = exp(-sigma h / s_z); a lookup with nz/2 in integers reads
// 3 over (G = exp(-2 sigma h / s_z) at cell 2, 1 at cell 1). A sun along -y
// (nz = 8) reads 4 cells toward -y: cell (5, 6) reads D(5, 2).
TEST(Shadow, OddHeightAndMinusYHandWorked) {
    const Extent3 e{10, 8, 7};
    std::vector<float> D(80, 0.0f);
    D[5 + 10 * 2] = 2.0f;
    ShadowParams p;
    p.sigma = 0.01f;
    p.voxelSize = 50;
    p.nz = e.nz;
    const float r = std::sqrt(0.5f);
    p.sun = {r, 0, r};
    std::vector<float> G = ShadowOnCpu(e, D, p);
    const float half = std::exp(-0.01f * 50 * 1.0f / r);
    EXPECT_NEAR(G[1 + 10 * 2], half, 1e-5);
    EXPECT_NEAR(G[2 + 10 * 2], half, 1e-5);
    EXPECT_NEAR(G[0 + 10 * 2], 1.0f, 1e-6);
    EXPECT_NEAR(G[3 + 10 * 2], 1.0f, 1e-6);
    EXPECT_NEAR(G[2 + 10 * 3], 1.0f, 1e-6);  // another row
    p.nz = 8;
    p.sun = {0, -r, r};
    G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[5 + 10 * 6], std::exp(-0.01f * 50 * 2.0f / r), 1e-5);
    EXPECT_NEAR(G[5 + 10 * 2], 1.0f, 1e-6);
    EXPECT_NEAR(G[5 + 10 * 5], 1.0f, 1e-5);
    EXPECT_NEAR(G[5 + 10 * 7], 1.0f, 1e-5);
    EXPECT_NEAR(G[4 + 10 * 6], 1.0f, 1e-6);
}

// Test Wang's form (Wang, Ji and Zhang, eq. 19, S = 1 - D_w max(T_S - (T_2D + 1 - C), 0))
// by hand, with T_S the column's opacity 1 - exp(-sigma h D / s_z) and T_2D = 0
// (docs/pipeline.md). D = 2, sigma h = 0.5: overhead tau = 1, opacity
// 1 - e^-1 = 0.632121; C = 0.8, D_w = 0.5: S = 1 - 0.5 (0.632121 - 0.2) = 0.783940.
// At 45 degrees tau = sqrt 2: S = 1 - 0.5 (1 - e^-1.414214 - 0.2) = 0.721558.
// Coverage 0.3: 1 - C = 0.7 is above the overhead opacity (no shadow) but below
// the slant one (S = 1 - 0.5 (0.756883 - 0.7) = 0.971558); C = D_w = 1 is plain
// exp(-tau) = 0.367879.
TEST(Shadow, WangHandWorked) {
    const Extent3 e{10, 4, 8};
    std::vector<float> D(40, 0.0f);
    D[5 + 10 * 2] = 2.0f;
    ShadowParams p;
    p.form = ShadowForm::Wang;
    p.sigma = 0.01f;
    p.voxelSize = 50;
    p.nz = e.nz;
    p.coverage = 0.8f;
    p.densityFactor = 0.5f;
    p.kappa = 5.0f;  // the thesis form's; Wang's ignores it
    p.sun = {0, 0, 1};
    std::vector<float> G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[5 + 10 * 2], 0.7839397f, 1e-6);
    EXPECT_EQ(G[4 + 10 * 2], 1.0f);  // no cloud: opacity 0, no shadow
    const float s = std::sqrt(0.5f);
    p.sun = {s, 0, s};  // offset nz/2 = 4 cells toward +x
    G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[1 + 10 * 2], 0.7215584f, 1e-6);
    EXPECT_EQ(G[5 + 10 * 2], 1.0f);
    p.coverage = 0.3f;  // slant opacity 0.756883 still exceeds 1 - C = 0.7
    EXPECT_NEAR(ShadowOnCpu(e, D, p)[1 + 10 * 2], 0.9715584f, 1e-6);
    p.sun = {0, 0, 1};  // overhead opacity 0.632121 does not
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
    p.coverage = 1.0f;
    p.densityFactor = 1.0f;
    EXPECT_NEAR(ShadowOnCpu(e, D, p)[5 + 10 * 2], 0.3678794f, 1e-6);
    p.densityFactor = 0.0f;  // no density: no shadow
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
    p.sun = {0.6f, 0, -0.8f};  // no sun above the horizon
    p.densityFactor = 1.0f;
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
}

}  // namespace
}  // namespace cb
