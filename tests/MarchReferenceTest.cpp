// The exact reference render (reference/MarchReference.h): the empty volume,
// homogeneous slabs against the closed form of the single-scattering integral
// with exact exponential light attenuation, and the fast marcher converging
// to it. Expected values come from closed forms derived here, never from the
// code under test.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/math/March.h"
#include "impl_cpu/BackendCpu.h"
#include "reference/MarchReference.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// A camera at `eye` (voxel units, h = 1, origin 0) looking at `target`, with
// the far plane `far` voxel edges away; a 1 x 1 image shoots its one ray
// straight along the view axis.
MarchParams RefCamera(const Extent3& e, std::array<double, 3> eye, std::array<double, 3> target,
                      std::array<double, 3> up, double farPlane, uint32_t w = 1, uint32_t h = 1) {
    CameraSettings cam;
    cam.eye = eye;
    cam.target = target;
    cam.up = up;
    cam.fovDeg = 40;
    cam.nearPlane = 1e-4;
    cam.farPlane = farPlane;
    MarchParams p;
    p.camera = MakeCameraFrame(cam, w, h);
    MarchSetup& s = p.setup;
    s.size = {float(e.nx), float(e.ny), float(e.nz)};
    s.voxelSize = s.light.voxelSize = 1;
    s.sigmaH = 0.1f;
    s.epsilon = 0.01f;  // the reference must ignore it
    s.light.sunRadiance = {1.0f, 0.8f, 0.6f};
    s.light.ambient = {0.05f, 0.1f, 0.2f};
    s.background = {0.3f, 0.5f, 0.9f};
    s.light.phase.kind = PhaseKind::None;
    p.origin = {0, 0, 0};
    p.alpha = 0.5f;
    return p;
}

std::vector<float> RenderRef(const MarchParams& p, const Extent3& e, const std::vector<float>& q, float step = 0.125f) {
    ref::MarchReferenceOptions o;
    o.stepVoxels = step;
    o.threads = 2;
    auto r = ref::RenderMarchReference(p, e, q, q, o);
    EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
    return r ? r->image : std::vector<float>{};
}

TEST(MarchReference, EmptyVolumeIsTheBackgroundExactly) {
    const Extent3 e{12, 10, 8};
    MarchParams p = RefCamera(e, {-5, -4, 12}, {6, 5, 4}, {0, 0, 1}, 1e4, 16, 12);
    p.setup.light.pointOn = true;
    p.setup.light.pointPosition = {6, 5, 4};
    p.setup.light.pointRadiance = {5, 5, 5};
    const std::vector<float> image = RenderRef(p, e, std::vector<float>(e.Count(), 0.0f));
    ASSERT_EQ(image.size(), 3u * 16 * 12);
    for (size_t v = 0; v < image.size(); v += 3) {
        EXPECT_EQ(image[v + 0], 0.3f);
        EXPECT_EQ(image[v + 1], 0.5f);
        EXPECT_EQ(image[v + 2], 0.9f);
    }
}

// A slab of constant q0 (every voxel), seen from inside along one axis, the
// view ray stopped by the far plane before the box's outer half-voxel shell
// (where the trilinear field ramps to q0/2 at the face). With sigma = sigma h,
// view distance D and light depth b(t) (in voxel edges at q = 1):
//   C = int_0^D s q0 e^{-s q0 t} [S e^{-s b(t)} + A] dt + e^{-s q0 D} B.
// The light ray toward the face first crosses constant q0, then the shell,
// whose depth is int_0^{1/2} q0 (1/2 + u) du = 3/8 q0.
// - Sun straight behind the camera, b(t) = q0 (c + t), c = (distance from the
//   eye to the shell) + 3/8: the sun term is S e^{-s q0 c} (1 - e^{-2 s q0 D}) / 2.
// - Sun overhead, horizontal view: b constant = q0 c: S e^{-s q0 c}(1 - e^{-s q0 D}).
// The reference's midpoint sum differs from the integral per segment by the
// factor 1/cosh(x/2) >= 1 - x^2/8, x = s q0 Delta (for the linear b), and
// not at all for the constant b: relative tolerance x^2/8 plus float rounding.
struct SlabCase {
    const char* name;
    std::array<double, 3> eye, target, up;
    Vec3 sun;
    double D, c;  // view distance, offset of the light depth
    bool linear;  // b(t) grows with t (sun behind the camera) or is constant (sun overhead)
};

TEST(MarchReference, HomogeneousSlabMatchesTheClosedForm) {
    const Extent3 e{8, 8, 24};
    const float q0 = 0.8f;
    const std::vector<float> q(e.Count(), q0);
    const SlabCase cases[] = {
        // Looking up +z from z = 2, sun toward -z: the light goes back down through 1.5 voxels and the shell.
        {"behind, looking up", {4, 4, 2}, {4, 4, 20}, {0, 1, 0}, {0, 0, -1}, 20.0, 1.5 + 0.375, true},
        // Looking down -z from z = 22, sun toward +z: up through 1.5 voxels and the shell.
        {"behind, looking down", {4, 4, 22}, {4, 4, 2}, {0, 1, 0}, {0, 0, 1}, 19.0, 1.5 + 0.375, true},
        // Horizontal along +x at z = 12 from x = 0.75, sun overhead: up through 11.5 voxels and the shell.
        {"overhead, horizontal", {0.75, 4, 12}, {8, 4, 12}, {0, 0, 1}, {0, 0, 1}, 6.5, 11.5 + 0.375, false},
    };
    const float step = 0.125f;
    for (const SlabCase& k : cases) {
        MarchParams p = RefCamera(e, k.eye, k.target, k.up, k.D);
        p.setup.sun = k.sun;
        const std::vector<float> image = RenderRef(p, e, q, step);
        ASSERT_EQ(image.size(), 3u);
        const double s = p.setup.sigmaH, a = s * q0;
        const double sunTerm = k.linear ? std::exp(-a * k.c) * (1 - std::exp(-2 * a * k.D)) / 2
                                        : std::exp(-a * k.c) * (1 - std::exp(-a * k.D));
        const double x = a * step;
        for (int ch = 0; ch < 3; ++ch) {
            const double expected = p.setup.light.sunRadiance[ch] * sunTerm +
                                    p.setup.light.ambient[ch] * (1 - std::exp(-a * k.D)) +
                                    p.setup.background[ch] * std::exp(-a * k.D);
            const double tol = p.setup.light.sunRadiance[ch] * sunTerm * (k.linear ? x * x / 8 : 0) + 2e-5;
            EXPECT_NEAR(image[ch], expected, tol) << k.name << " channel " << ch;
        }
    }
}

// Two Gaussian blobs, zero below 1e-3.
std::vector<float> RefBlobs(const Extent3& e) { return test::GaussianBlobField(e, {{8, 9, 7, 2.5}, {15, 14, 10, 2}}); }

double MeanPixelError(const std::vector<float>& a, const std::vector<float>& b) {
    double sum = 0;
    for (size_t v = 0; v < a.size(); v += 3)
        sum += std::max({std::fabs(a[v] - b[v]), std::fabs(a[v + 1] - b[v + 1]), std::fabs(a[v + 2] - b[v + 2])});
    return sum / double(a.size() / 3);
}

// The CPU backend's fast march with the light march and epsilon 0 approaches
// the reference as n_l grows (same step: only the light differs) and as the
// step shrinks (n_l large).
TEST(MarchReference, FastMarchConvergesToTheReference) {
    const Extent3 e{24, 24, 16};
    const std::vector<float> q = RefBlobs(e);
    MarchParams p = RefCamera(e, {-20, -14, 30}, {12, 12, 8}, {0, 0, 1}, 1e4, 24, 18);
    p.setup.sigmaH = 0.6f;
    p.setup.sun = SunDirection(0.6, 0.5);
    p.setup.light.phase = {PhaseKind::HenyeyGreenstein, 0.5f};
    p.setup.powder = true;
    p.setup.light.pointOn = true;
    p.setup.light.pointPosition = {12, 12, 3};
    p.setup.light.pointRadiance = {20, 15, 10};
    p.setup.epsilon = 0;
    const std::vector<float> reference = RenderRef(p, e, q);

    cpu::BackendCpu backend(2);
    auto qb = test::MakeFilled(backend, BufferFormat::F32, e, q);
    auto image = test::MakeBuffer(backend, BufferFormat::F32, {3, p.camera.width, p.camera.height});
    auto fast = [&](float step, uint32_t nl) {
        MarchParams f = p;
        f.light = MarchLightSource::March;
        f.lightSteps = nl;
        f.setup.step = step;
        const MarchInputs in{qb.get(), qb.get(), nullptr};
        Status status = backend.RenderMarch(f, in, *image, nullptr);
        EXPECT_TRUE(status.has_value()) << status.error().message;
        return MeanPixelError(test::Read<float>(backend, *image), reference);
    };
    const double l2 = fast(0.125f, 2), l8 = fast(0.125f, 8), l64 = fast(0.125f, 64);
    EXPECT_GT(l2, 2 * l8);
    EXPECT_GT(l8, 2 * l64);
    const double s1 = fast(1.0f, 64), s05 = fast(0.5f, 64), s025 = fast(0.25f, 64);
    EXPECT_GT(s1, 2 * s05);
    EXPECT_GT(s05, 2 * s025);
    // Same step and a fine light march: the light's quadrature error alone, small against the image's scale.
    EXPECT_LT(l64, 1e-3);
}

}  // namespace
}  // namespace cb
