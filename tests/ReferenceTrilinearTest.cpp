// The exact optical depth of the trilinear field (reference/Trilinear.h) against
// closed forms, a fine midpoint quadrature and a dual-cell walk, both written
// here with their own trilinear evaluator. Distances are in voxel units.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/math/Random.h"
#include "reference/Trilinear.h"

namespace cb {
namespace {

using ref::Point3d;
using ref::TrilinearDepthTracer;

constexpr double kTriTestInf = std::numeric_limits<double>::infinity();

std::unique_ptr<TrilinearDepthTracer> TriTrace(const Extent3& e, const std::vector<float>& q, int threads = 0) {
    auto tracer = TrilinearDepthTracer::Create(e, q, threads);
    EXPECT_TRUE(tracer.has_value()) << (tracer ? "" : tracer.error().message);
    return std::move(*tracer);
}

// The field written out: zero outside the closed box [0,n]^3; inside, the
// trilinear blend of the 8 voxel centres around x, taps outside the grid 0.
double TriField(const Extent3& e, const std::vector<float>& q, const Point3d& x) {
    const uint32_t n[3] = {e.nx, e.ny, e.nz};
    int lo[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        if (x[a] < 0 || x[a] > n[a]) return 0.0;
        const double u = x[a] - 0.5;
        lo[a] = int(std::floor(u));
        f[a] = u - lo[a];
    }
    auto tap = [&](int i, int j, int k) -> double {
        if (i < 0 || j < 0 || k < 0 || i >= int(e.nx) || j >= int(e.ny) || k >= int(e.nz)) return 0.0;
        return q[VoxelIndex(e, i, j, k)];
    };
    double sum = 0;
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx)
                sum += (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]) *
                       tap(lo[0] + dx, lo[1] + dy, lo[2] + dz);
    return sum;
}

Point3d TriAt(const Point3d& o, const Point3d& d, double t) {
    return {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
}

// A finite end for a ray to infinity: past the box from anywhere we test.
double TriFiniteEnd(const Extent3& e, double t) { return std::min(t, 4.0 * (e.nx + e.ny + e.nz + 10)); }

// Composite midpoint rule with `steps` equal steps over [t0, t1]: the brute force.
double TriMidpoint(const Extent3& e, const std::vector<float>& q, const Point3d& o, const Point3d& d, double t0,
                   double t1, size_t steps) {
    const double h = (t1 - t0) / double(steps);
    double sum = 0;
    for (size_t s = 0; s < steps; ++s) sum += TriField(e, q, TriAt(o, d, t0 + (s + 0.5) * h));
    return sum * h;
}

// A walk over dual cells: every crossing of a plane a + 1/2 and of the box's
// faces splits the ray; on each piece the field is one cubic, integrated by
// 2-point Gauss-Legendre at TriField above.
double TriDualWalk(const Extent3& e, const std::vector<float>& q, const Point3d& o, const Point3d& d, double t0,
                   double t1) {
    const uint32_t n[3] = {e.nx, e.ny, e.nz};
    std::vector<double> cuts = {t0, t1};
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) continue;
        std::vector<double> planes = {0.0, double(n[a])};
        for (uint32_t i = 0; i < n[a]; ++i) planes.push_back(i + 0.5);
        for (double p : planes) {
            const double t = (p - o[a]) / d[a];
            if (t > t0 && t < t1) cuts.push_back(t);
        }
    }
    std::sort(cuts.begin(), cuts.end());
    const double node = 1.0 / std::sqrt(3.0);
    double sum = 0;
    for (size_t c = 0; c + 1 < cuts.size(); ++c) {
        const double mid = 0.5 * (cuts[c] + cuts[c + 1]), half = 0.5 * (cuts[c + 1] - cuts[c]);
        sum += half * (TriField(e, q, TriAt(o, d, mid - half * node)) + TriField(e, q, TriAt(o, d, mid + half * node)));
    }
    return sum;
}

std::vector<float> TriRandomGrid(Pcg32& rng, const Extent3& e, double fillProbability) {
    std::vector<float> q(e.Count(), 0.0f);
    for (float& v : q)
        if (rng.NextDouble() < fillProbability) v = float(rng.Uniform(0.05, 1.0));
    return q;
}

Point3d TriRandomUnit(Pcg32& rng) {
    for (;;) {
        const Point3d v = {rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1)};
        const double r = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (r > 0.1 && r <= 1) return {v[0] / r, v[1] / r, v[2] / r};
    }
}

struct TriTestRay {
    Point3d o, d;
    double t0, t1;
    const char* kind;
};

// Rays of every kind the reference meets: starting inside, from outside
// through the box, axis-aligned along voxel faces, dual-cell faces and the
// box's own faces, grazing (lying in a dual-cell face plane), in the half-voxel
// boundary shell, and finite segments.
std::vector<TriTestRay> TriRandomRays(Pcg32& rng, const Extent3& e, int perKind) {
    const double n[3] = {double(e.nx), double(e.ny), double(e.nz)};
    auto inside = [&] { return Point3d{rng.Uniform(0, n[0]), rng.Uniform(0, n[1]), rng.Uniform(0, n[2])}; };
    // A coordinate on a special plane of axis a: a box face, a voxel face or a dual-cell face.
    auto special = [&](int a) {
        const uint32_t m = uint32_t(n[a]);
        switch (rng.NextU32() % 4) {
            case 0:
                return 0.0;
            case 1:
                return n[a];
            case 2:
                return double(rng.NextU32() % (m + 1));
            default:
                return (rng.NextU32() % m) + 0.5;
        }
    };
    std::vector<TriTestRay> rays;
    for (int r = 0; r < perKind; ++r) {
        rays.push_back({inside(), TriRandomUnit(rng), 0.0, kTriTestInf, "inside"});
        // From outside: a point well away, aimed at a point inside.
        const Point3d target = inside(), u = TriRandomUnit(rng);
        const double back = 2.0 * (n[0] + n[1] + n[2]);
        rays.push_back({TriAt(target, u, -back), u, 0.0, kTriTestInf, "outside"});
        // Axis-aligned along special planes of the other two axes.
        const int axis = int(rng.NextU32() % 3);
        Point3d o = inside(), d = {0, 0, 0};
        d[axis] = rng.NextU32() % 2 ? 1.0 : -1.0;
        o[(axis + 1) % 3] = special((axis + 1) % 3);
        o[(axis + 2) % 3] = special((axis + 2) % 3);
        rays.push_back({o, d, 0.0, kTriTestInf, "axis-aligned"});
        // Grazing: in a special plane of one axis, oblique in the other two.
        const int flat = int(rng.NextU32() % 3);
        Point3d g = inside(), gd = TriRandomUnit(rng);
        g[flat] = special(flat);
        gd[flat] = 0;
        const double gl = std::sqrt(gd[0] * gd[0] + gd[1] * gd[1] + gd[2] * gd[2]);
        for (double& c : gd) c /= gl;
        rays.push_back({g, gd, 0.0, kTriTestInf, "grazing"});
        // The boundary shell: within half a voxel of a face, parallel to it.
        Point3d s = inside(), sd = TriRandomUnit(rng);
        const int face = int(rng.NextU32() % 3);
        s[face] = rng.NextU32() % 2 ? rng.Uniform(0, 0.5) : n[face] - rng.Uniform(0, 0.5);
        sd[face] = 0;
        const double sl = std::sqrt(sd[0] * sd[0] + sd[1] * sd[1] + sd[2] * sd[2]);
        for (double& c : sd) c /= sl;
        rays.push_back({s, sd, 0.0, kTriTestInf, "shell"});
        // A finite segment, possibly starting before its origin.
        rays.push_back({inside(), TriRandomUnit(rng), rng.Uniform(-2, 1), rng.Uniform(1.5, 4), "segment"});
    }
    return rays;
}

// The ray's clipped parameter range inside the closed box (for the brute force,
// which needs finite ends).
bool TriClipToBox(const Extent3& e, const TriTestRay& r, double& t0, double& t1) {
    const double n[3] = {double(e.nx), double(e.ny), double(e.nz)};
    t0 = r.t0;
    t1 = TriFiniteEnd(e, r.t1);
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0) {
            if (r.o[a] < 0 || r.o[a] > n[a]) return false;
            continue;
        }
        double ta = (0 - r.o[a]) / r.d[a], tb = (n[a] - r.o[a]) / r.d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 < t1;
}

// Test that a q whose size is not the grid's is refused.
TEST(ReferenceTrilinear, RefusesAWrongSize) {
    const std::vector<float> q(5, 1.0f);
    EXPECT_FALSE(TrilinearDepthTracer::Create(Extent3{2, 2, 2}, q).has_value());
}

// Test that an empty volume integrates to exactly 0 and transmits exactly 1.
TEST(ReferenceTrilinear, EmptyVolumeIsZero) {
    for (const Extent3 e : {Extent3{1, 1, 1}, Extent3{4, 3, 5}}) {
        const std::vector<float> q(e.Count(), 0.0f);
        auto tracer = TriTrace(e, q);
        EXPECT_EQ(tracer->Primitives(), 0u);
        EXPECT_EQ(tracer->Integrate({0.5, 0.5, 0.5}, {0, 0, 1}, 0, kTriTestInf), 0.0);
        const std::vector<Point3d> points = {{0.5, 0.5, 0.5}, {0.1, 0.9, 0.2}};
        for (float T : tracer->TransmittanceToward(points, {0.3, 0.4, 0.5}, 1.0)) EXPECT_EQ(T, 1.0f);
        for (float T : tracer->TransmittanceToPoint(points, {3, 2, 1}, 1.0)) EXPECT_EQ(T, 1.0f);
    }
}

// Test a constant field q = c. Between the outermost voxel centres (the
// interior [1/2, n - 1/2] on every axis) every tap is c, so the field is c and
// a segment of length L integrates to c L. Along an axis from face to face
// through the interior, the half-voxel shell at each end falls linearly from c
// at x = 1/2 to c/2 at x = 0 (the outside tap reads 0): c (n - 1) + 2 (3/8) c.
TEST(ReferenceTrilinear, ConstantField) {
    const Extent3 e{8, 7, 6};
    const float c = 0.7f;
    auto tracer = TriTrace(e, std::vector<float>(e.Count(), c));
    Pcg32 rng(13);
    for (int r = 0; r < 200; ++r) {
        const Point3d a = {rng.Uniform(0.5, 7.5), rng.Uniform(0.5, 6.5), rng.Uniform(0.5, 5.5)};
        const Point3d b = {rng.Uniform(0.5, 7.5), rng.Uniform(0.5, 6.5), rng.Uniform(0.5, 5.5)};
        const double length = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
        ASSERT_NEAR(tracer->IntegrateSegment(a, b), c * length, 1e-12 * (1 + c * length)) << r;
    }
    for (double y : {0.5, 2.0, 3.5, 6.5})
        for (double dir : {1.0, -1.0}) {
            const double x0 = dir > 0 ? -3.0 : 11.0;
            EXPECT_NEAR(tracer->Integrate({x0, y, 2.25}, {dir, 0, 0}, 0, kTriTestInf), c * (7 + 0.75), 1e-12)
                << "y " << y << " dir " << dir;
        }
}

// Test a field linear in x, q(i,j,k) = a + b (i + 1/2): trilinear reproduces it
// in the interior, q(x) = a + b x, so a segment from o along unit d integrates
// to a L + b (o_x L + d_x L^2 / 2).
TEST(ReferenceTrilinear, LinearField) {
    const Extent3 e{9, 5, 6};
    const double a = 0.2, b = 0.1;
    std::vector<float> q(e.Count());
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) q[VoxelIndex(e, i, j, k)] = float(a + b * (i + 0.5));
    auto tracer = TriTrace(e, q);
    Pcg32 rng(7);
    for (int r = 0; r < 200; ++r) {
        const Point3d o = {rng.Uniform(0.5, 8.5), rng.Uniform(0.5, 4.5), rng.Uniform(0.5, 5.5)};
        const Point3d p = {rng.Uniform(0.5, 8.5), rng.Uniform(0.5, 4.5), rng.Uniform(0.5, 5.5)};
        const double length = std::hypot(p[0] - o[0], p[1] - o[1], p[2] - o[2]);
        const double dx = (p[0] - o[0]) / length;
        // The field's float voxel values carry float rounding (1e-8 relative).
        const double exact = a * length + b * (o[0] * length + dx * length * length / 2);
        ASSERT_NEAR(tracer->IntegrateSegment(o, p), exact, 1e-7 * exact) << r;
    }
}

// Test one nonzero voxel v at (i,j,k): along the axis line through its centre
// the other two weights are 1 and the field is a tent of half-width 1, so the
// integral is v; for a voxel at the grid's edge the box cuts the tent's outer
// quarter-triangle off (area 1/8): 7 v / 8.
TEST(ReferenceTrilinear, SingleVoxelTent) {
    const Extent3 e{5, 4, 3};
    for (uint32_t i : {0u, 2u, 4u}) {
        std::vector<float> q(e.Count(), 0.0f);
        q[VoxelIndex(e, i, 1, 1)] = 2.0f;
        auto tracer = TriTrace(e, q);
        const double exact = (i == 0 || i == 4) ? 2.0 * 7 / 8 : 2.0;
        EXPECT_NEAR(tracer->Integrate({-1, 1.5, 1.5}, {1, 0, 0}, 0, kTriTestInf), exact, 1e-14) << i;
        EXPECT_NEAR(tracer->Integrate({9, 1.5, 1.5}, {-1, 0, 0}, 0, kTriTestInf), exact, 1e-14) << i;
        // Along y through the voxel's centre: the tent in y, both ends inside the box.
        EXPECT_NEAR(tracer->Integrate({i + 0.5, -2, 1.5}, {0, 1, 0}, 0, kTriTestInf), 2.0, 1e-14) << i;
    }
}

// Test against the brute force: a composite midpoint rule with steps h of
// 1/50000 voxel on the field written above. Its error on a piecewise cubic
// with kinks is at most h^2 (L max|q''| / 24 + sum over kinks |jump q'| / 8):
// along a unit ray max|q''| <= 6 q_max, and crossing a plane of axis a makes q'
// jump by at most 2 q_max |d_a|, with at most |d_a| L + 1 such planes. That
// bound (about 1e-9 here) plus 1e-12 of rounding is the tolerance; the rays
// reach lengths of 9 voxels on grids up to 7 x 7 x 5.
TEST(ReferenceTrilinear, MatchesMidpointBruteForce) {
    Pcg32 rng(2024);
    constexpr double kStepsPerVoxel = 50000.0;
    int checked = 0;
    double worst = 0;
    for (int grid = 0; grid < 4; ++grid) {
        const Extent3 e{2 + rng.NextU32() % 6, 2 + rng.NextU32() % 6, 1 + rng.NextU32() % 5};
        const std::vector<float> q = TriRandomGrid(rng, e, 0.6);
        const double qMax = *std::max_element(q.begin(), q.end());
        auto tracer = TriTrace(e, q, 1);
        for (const TriTestRay& r : TriRandomRays(rng, e, 2)) {
            double t0, t1;
            const double got = tracer->Integrate(r.o, r.d, r.t0, r.t1);
            if (!TriClipToBox(e, r, t0, t1)) {
                EXPECT_EQ(got, 0.0) << r.kind;
                continue;
            }
            const double length = t1 - t0;
            const size_t steps = size_t(std::ceil(length * kStepsPerVoxel));
            const double brute = TriMidpoint(e, q, r.o, r.d, t0, t1, steps);
            const double h = length / double(steps);
            double kinks = 0;
            for (double d : r.d) kinks += std::fabs(d) * (std::fabs(d) * length + 1);
            const double bound = h * h * qMax * (length / 4 + kinks / 4);
            worst = std::max(worst, std::fabs(got - brute));
            ASSERT_NEAR(got, brute, bound + 1e-12 * (1 + brute))
                << r.kind << " grid " << e.nx << "x" << e.ny << "x" << e.nz << " o " << r.o[0] << "," << r.o[1] << ","
                << r.o[2] << " d " << r.d[0] << "," << r.d[1] << "," << r.d[2];
            ++checked;
        }
    }
    EXPECT_GT(checked, 30);
    RecordProperty("worst_difference", std::to_string(worst));
}

// Test against the dual-cell walk (independent clipping, same exact rule): the
// two agree to rounding, on many rays and grids with a few threads.
TEST(ReferenceTrilinear, MatchesDualCellWalk) {
    Pcg32 rng(99);
    for (int grid = 0; grid < 12; ++grid) {
        const Extent3 e{1 + rng.NextU32() % 9, 1 + rng.NextU32() % 9, 1 + rng.NextU32() % 7};
        const std::vector<float> q = TriRandomGrid(rng, e, grid % 3 == 0 ? 0.15 : 0.7);
        auto tracer = TriTrace(e, q, 1 + grid % 2);
        for (const TriTestRay& r : TriRandomRays(rng, e, 20)) {
            double t0, t1;
            const double got = tracer->Integrate(r.o, r.d, r.t0, r.t1);
            const double walk = TriClipToBox(e, r, t0, t1) ? TriDualWalk(e, q, r.o, r.d, t0, t1) : 0.0;
            ASSERT_NEAR(got, walk, 1e-12 * (1 + walk))
                << r.kind << " grid " << grid << " o " << r.o[0] << "," << r.o[1] << "," << r.o[2] << " d " << r.d[0]
                << "," << r.d[1] << "," << r.d[2] << " t " << r.t0 << ".." << r.t1;
        }
    }
}

// Test point-to-point depths: they stop at the end point (a constant field
// between two interior points gives c |b - a|, less than to the box edge), are
// symmetric (a -> b equals b -> a), and the batches equal single rays.
TEST(ReferenceTrilinear, SegmentsStopAtTheEndAndAreSymmetric) {
    const Extent3 e{10, 8, 6};
    const float c = 0.5f;
    auto constant = TriTrace(e, std::vector<float>(e.Count(), c), 2);
    const Point3d light = {5.0, 4.0, 3.0};
    const std::vector<Point3d> near = {{1.0, 4.0, 3.0}, {5.0, 1.5, 3.0}, {2.0, 2.0, 2.0}};
    const std::vector<double> depths = constant->DepthsToPoint(near, light);
    for (size_t i = 0; i < near.size(); ++i) {
        const double length = std::hypot(light[0] - near[i][0], light[1] - near[i][1], light[2] - near[i][2]);
        EXPECT_NEAR(depths[i], c * length, 1e-12) << i;
    }
    Pcg32 rng(5);
    const std::vector<float> q = TriRandomGrid(rng, e, 0.5);
    auto tracer = TriTrace(e, q, 2);
    std::vector<Point3d> points;
    for (int r = 0; r < 300; ++r) points.push_back({rng.Uniform(-2, 12), rng.Uniform(-2, 10), rng.Uniform(-1, 7)});
    const Point3d target = {3.3, 4.1, 2.7};
    ref::TraceStats stats;
    const std::vector<double> toTarget = tracer->DepthsToPoint(points, target, &stats);
    const std::vector<float> T = tracer->TransmittanceToPoint(points, target, 0.8, &stats);
    EXPECT_EQ(stats.rays, 600u);
    for (size_t i = 0; i < points.size(); ++i) {
        const Point3d& p = points[i];
        const double back = tracer->IntegrateSegment(target, p);
        ASSERT_NEAR(toTarget[i], back, 1e-12 * (1 + back)) << i;
        const double length = std::hypot(target[0] - p[0], target[1] - p[1], target[2] - p[2]);
        const Point3d d = {(target[0] - p[0]) / length, (target[1] - p[1]) / length, (target[2] - p[2]) / length};
        double t0, t1;
        const TriTestRay ray{p, d, 0.0, length, "segment"};
        const double walk = TriClipToBox(e, ray, t0, t1) ? TriDualWalk(e, q, p, d, t0, t1) : 0.0;
        ASSERT_NEAR(toTarget[i], walk, 1e-12 * (1 + walk)) << i;
        EXPECT_EQ(T[i], float(std::exp(-0.8 * toTarget[i]))) << i;
    }
}

// Test the sun batch: it equals single rays to the box edge (to rounding: a
// packet may visit a ray's runs in another order), with 16-ray packets and
// with single rays, 1 and 2 threads; it normalises its direction, and stays
// finite in [0, 1] for sigma h = 0 and 1e6.
TEST(ReferenceTrilinear, SunBatchMatchesSingleRays) {
    const Extent3 e{12, 9, 7};
    Pcg32 rng(31);
    const std::vector<float> q = TriRandomGrid(rng, e, 0.4);
    auto one = TriTrace(e, q, 1);
    auto two = TriTrace(e, q, 2);
    EXPECT_EQ(one->Primitives(), two->Primitives());
    std::vector<Point3d> points;
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) points.push_back({i + 0.5, j + 0.5, k + 0.5});
    points.push_back({-5, 4, 3});          // outside, aimed away from the box: 0
    const Point3d sun = {0.4, -0.3, 0.6};  // not unit: the batch normalises it
    const double norm = std::sqrt(0.16 + 0.09 + 0.36);
    const Point3d unit = {0.4 / norm, -0.3 / norm, 0.6 / norm};
    ref::TraceStats stats;
    const std::vector<double> a = one->DepthsToward(points, sun, &stats);
    const std::vector<double> b = two->DepthsToward(points, sun);
    two->UsePackets(false);
    const std::vector<double> c = two->DepthsToward(points, sun);
    EXPECT_EQ(stats.rays, points.size());
    EXPECT_EQ(a.back(), 0.0);
    for (size_t i = 0; i < points.size(); ++i) {
        const double single = one->Integrate(points[i], unit, 0, kTriTestInf);
        ASSERT_NEAR(a[i], single, 1e-13 * (1 + single)) << i;
        ASSERT_NEAR(b[i], single, 1e-13 * (1 + single)) << i;
        ASSERT_EQ(c[i], single) << i;  // single rays: the same code, the same order
    }
    for (double sigmaH : {0.0, 1e6}) {
        const std::vector<float> T = one->TransmittanceToward(points, sun, sigmaH);
        for (size_t i = 0; i < points.size(); ++i) {
            ASSERT_TRUE(T[i] >= 0.0f && T[i] <= 1.0f) << i;
            if (sigmaH == 0.0) {
                ASSERT_EQ(T[i], 1.0f);
            }
            if (sigmaH > 0 && a[i] > 1e-3) {
                ASSERT_EQ(T[i], 0.0f);
            }
        }
    }
}

// Test point-light packets against single rays, with points on the light,
// beside it and outside the box.
TEST(ReferenceTrilinear, PointPacketsMatchSingleRays) {
    const Extent3 e{11, 10, 6};
    Pcg32 rng(8);
    const std::vector<float> q = TriRandomGrid(rng, e, 0.5);
    auto tracer = TriTrace(e, q, 2);
    const Point3d light = {4.2, 5.5, 2.9};
    std::vector<Point3d> points = {light, {4.2, 5.5, 3.0}, {-3, -3, -3}, {20, 5, 3}};
    for (int r = 0; r < 500; ++r) points.push_back({rng.Uniform(-1, 12), rng.Uniform(-1, 11), rng.Uniform(-1, 7)});
    const std::vector<double> packets = tracer->DepthsToPoint(points, light);
    tracer->UsePackets(false);
    const std::vector<double> single = tracer->DepthsToPoint(points, light);
    EXPECT_EQ(packets[0], 0.0);
    for (size_t i = 0; i < points.size(); ++i) {
        ASSERT_EQ(single[i], tracer->IntegrateSegment(points[i], light)) << i;
        ASSERT_NEAR(packets[i], single[i], 1e-13 * (1 + single[i])) << i;
    }
}

// Test that the depths grow along a ray (the field is non-negative) and that
// the pieces of a ray add up to the whole: [0, s] + [s, inf) = [0, inf).
TEST(ReferenceTrilinear, PiecesAddUp) {
    const Extent3 e{7, 6, 5};
    Pcg32 rng(77);
    const std::vector<float> q = TriRandomGrid(rng, e, 0.5);
    auto tracer = TriTrace(e, q);
    for (int r = 0; r < 100; ++r) {
        const Point3d o = {rng.Uniform(0, 7), rng.Uniform(0, 6), rng.Uniform(0, 5)};
        const Point3d d = TriRandomUnit(rng);
        const double split = rng.Uniform(0, 5);
        const double whole = tracer->Integrate(o, d, 0, kTriTestInf);
        const double first = tracer->Integrate(o, d, 0, split), second = tracer->Integrate(o, d, split, kTriTestInf);
        EXPECT_GE(first, 0.0);
        EXPECT_GE(second, 0.0);
        ASSERT_NEAR(first + second, whole, 1e-12 * (1 + whole)) << r;
    }
}

}  // namespace
}  // namespace cb
