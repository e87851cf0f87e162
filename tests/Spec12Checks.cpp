// The items' own properties for SPEC 12's suite (tests/Spec12Checks.h), each
// hand-derived from docs/contract.md and docs/pipeline.md.
#include "tests/Spec12Checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>

#include "core/math/Shading.h"
#include "core/stages/shade/Shade.h"
#include "harness/accuracy/Accuracy.h"
#include "tests/TestUtil.h"

namespace cb::spec12_test {

std::string Num(double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

// Scene values that make the region R = 255 in every voxel: one ellipsoid of
// semi-axes 1e6 voxels that never moves, shrinks or dies. Its centre lies in
// the region bounds (margin 0), so every voxel centre is within ~92 voxels of
// it: rho <= 1e-4, w >= 0.9999, floor(255 w + 0.5) = 255 (SPEC 2).
std::vector<SceneOverride> FullRegion() {
    return {{"ellipsoids",
             R"({"target_count": 1, "density_adaption": 1, "size_mean": [1e6, 1e6, 1e6], "size_variance": [0, 0, 0],
                 "lifetime_mean": 1e6, "lifetime_variance": 0, "shrink_steps": 0, "margin": 0, "wind": [0, 0],
                 "jitter": 0})"}};
}

// With R = 255 (so P_ext = (0*Q + 127)/255 = 0 and P_hum = Q_hum, P_act = Q_act,
// SPEC 3.2), hum0 = act0 = 1 and every p = 0: step 0 has hum = act = 1, cld = 0;
// step 0 -> 1 gives cld1 = cld | act = 1, hum1 = hum & !act = 0, act1 = !act & .. = 0,
// no event fires and none is extinguished. So from step 1 on cld = 1 everywhere,
// hum = act = 0: a completely full volume.
std::vector<SceneOverride> FullVolume() {
    std::vector<SceneOverride> o = FullRegion();
    o.push_back({"ca", R"({"seed": 3, "hum0": 1, "act0": 1, "p_ext": 0, "p_hum": 0, "p_act": 0})"});
    return o;
}

std::vector<SceneOverride> Plus(std::vector<SceneOverride> a, const std::vector<SceneOverride>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

void ExpectAll(const std::vector<float>& values, float expected, const std::string& what) {
    size_t bad = 0, first = 0;
    for (size_t n = 0; n < values.size(); ++n)
        if (!(values[n] == expected)) first = bad++ ? first : n;
    EXPECT_EQ(bad, 0u) << what << ": " << bad << " of " << values.size() << " differ from " << expected << "; first ["
                       << first << "] = " << values[first];
}

// Largest |a - b| over two arrays (NaN counts as infinite).
double WorstDifference(const std::vector<float>& a, const std::vector<double>& b) {
    double worst = 0;
    for (size_t n = 0; n < a.size(); ++n) {
        const double d = std::fabs(double(a[n]) - b[n]);
        worst = std::isnan(d) ? std::numeric_limits<double>::infinity() : std::max(worst, d);
    }
    return worst;
}

// T for a sun straight overhead (up = true) or straight below, by hand: SPEC 6
// with w = z, the taps at the voxel's own column, so along each column
// T = 1 in the slice nearest the sun and T_m = T_{m-1} exp(-sigma h q_{m-1}).
// (The float sun vector keeps cos(90 deg) ~ 6e-17 sideways; see sunOverhead.)
std::vector<double> VerticalSunT(const Extent3& e, const std::vector<float>& q, double sigma, double h, bool up) {
    std::vector<double> T(q.size());
    for (uint32_t j = 0; j < e.ny; ++j)
        for (uint32_t i = 0; i < e.nx; ++i) {
            double t = 1;
            for (uint32_t m = 0; m < e.nz; ++m) {
                const uint32_t k = up ? e.nz - 1 - m : m;
                const uint32_t kPrev = up ? k + 1 : k - 1;
                if (m > 0) t *= std::exp(-sigma * h * q[VoxelIndex(e, i, j, kPrev)]);
                T[VoxelIndex(e, i, j, k)] = t;
            }
        }
    return T;
}

void CheckVerticalSun(const ItemContext& c, bool up) {
    if (!c.now.Has(Resource::T)) return;
    const Extent3 e = c.scene.grid.size;
    const std::vector<double> T =
        VerticalSunT(e, c.now.Of(Resource::Q), c.scene.shade.sigma, c.scene.grid.voxelSize, up);
    EXPECT_LE(WorstDifference(c.now.Of(Resource::T), T), 1e-5) << "T against the hand-computed columns";
    const std::vector<float>& D = c.now.Of(Resource::ColumnSum);
    std::vector<double> G(D.size(), 1.0);  // sun below: no sun, no shadow (SPEC 7)
    if (up)  // overhead: the ground point's own column, G = exp(-sigma h D / 1)
        for (size_t n = 0; n < D.size(); ++n) G[n] = std::exp(-c.scene.shade.sigma * c.scene.grid.voxelSize * D[n]);
    EXPECT_LE(WorstDifference(c.now.Of(Resource::Shadow), G), 1e-5) << "G against exp(-sigma h D)";
}

// Sun straight overhead or below with sigma huge: T is 0 (to 1e-5) below any
// voxel with q > 0 on the way to the sun, and 1 on clear paths.
void CheckOpaqueColumns(const ItemContext& c, bool up) {
    const Extent3 e = c.scene.grid.size;
    const std::vector<float>& q = c.now.Of(Resource::Q);
    std::vector<double> expected(q.size());
    for (uint32_t j = 0; j < e.ny; ++j)
        for (uint32_t i = 0; i < e.nx; ++i) {
            bool blocked = false;
            for (uint32_t m = 0; m < e.nz; ++m) {
                const uint32_t k = up ? e.nz - 1 - m : m;
                expected[VoxelIndex(e, i, j, k)] = blocked ? 0 : 1;
                blocked = blocked || q[VoxelIndex(e, i, j, k)] > 0;
            }
        }
    EXPECT_LE(WorstDifference(c.now.Of(Resource::T), expected), 1e-5);
}

// The principal axis of SPEC 6 for a sun vector: z if |s_z| >= max(|s_x|, |s_y|), else y if |s_y| >= |s_x|, else x.
int PrincipalAxis(const Vec3& s) {
    if (std::fabs(s[2]) >= std::max(std::fabs(s[0]), std::fabs(s[1]))) return 2;
    return std::fabs(s[1]) >= std::fabs(s[0]) ? 1 : 0;
}

// The smoothing weight along one axis of a voxel at index i of n when every
// voxel is cloud (SPEC 4, r = 1: w = (1, 2, 1)/4, outside counts 0).
double FullAxisWeight(uint32_t i, uint32_t n) { return (2.0 + (i > 0) + (i + 1 < n)) / 4.0; }

// A full volume from step 1 on (see FullVolume): cld = 1, hum = act = 0, the
// cover is every column, q is the product of the three axis weights (exact
// in float: multiples of 1/64), D sums it; and when the grid is one voxel
// thick along the sun's principal axis, T = 1 (only the first slice, SPEC 6).
void CheckFullVolume(const ItemContext& c) {
    const Extent3 e = c.scene.grid.size;
    if (c.now.step == 0) {
        ExpectAll(c.now.Of(Resource::Cld), 0, "cld at step 0");
        return;
    }
    ExpectAll(c.now.Of(Resource::Cld), 1, "cld");
    ExpectAll(c.now.Of(Resource::Hum), 0, "hum");
    ExpectAll(c.now.Of(Resource::Act), 0, "act");
    EXPECT_EQ(c.now.coveredColumns, std::optional<uint32_t>(e.nx * e.ny)) << "cover fraction 1";
    const std::vector<float>& q = c.now.Of(Resource::Q);
    const std::vector<float>& D = c.now.Of(Resource::ColumnSum);
    for (uint32_t j = 0; j < e.ny; ++j)
        for (uint32_t i = 0; i < e.nx; ++i) {
            double column = 0;
            for (uint32_t k = 0; k < e.nz; ++k) {
                const double w = FullAxisWeight(i, e.nx) * FullAxisWeight(j, e.ny) * FullAxisWeight(k, e.nz);
                column += w;
                ASSERT_EQ(q[VoxelIndex(e, i, j, k)], w) << "q at " << i << "," << j << "," << k;
            }
            ASSERT_EQ(D[i + e.nx * j], column) << "D at " << i << "," << j;
        }
    const int w = PrincipalAxis(c.scene.sun.Direction());
    const uint32_t n[3] = {e.nx, e.ny, e.nz};
    if (n[w] == 1 && c.now.Has(Resource::T)) ExpectAll(c.now.Of(Resource::T), 1, "T with one slice along the principal axis");
}

// Occupancy, cover and D recomputed from the downloaded q and cld (SPEC 5),
// for sizes that are not multiples of 64 or of the tile: edge tiles and bands are partial.
void CheckDensityOnPartialTiles(const ItemContext& c) {
    const Extent3 e = c.scene.grid.size;
    const uint32_t T = c.scene.density.tile, B = c.scene.density.band;
    const Extent3 tiles{CeilDiv(e.nx, T), CeilDiv(e.ny, T), 1}, bands{tiles.nx, tiles.ny, CeilDiv(e.nz, B)};
    const std::vector<float>& q = c.now.Of(Resource::Q);
    const std::vector<float>& cld = c.now.Of(Resource::Cld);
    std::vector<float> D(size_t(e.nx) * e.ny, 0), tileMap(tiles.Count(), 0), bandMap(bands.Count(), 0);
    uint32_t covered = 0;
    for (uint32_t j = 0; j < e.ny; ++j)
        for (uint32_t i = 0; i < e.nx; ++i) {
            bool cloud = false;
            float sum = 0;
            for (uint32_t k = 0; k < e.nz; ++k) {
                const float v = q[VoxelIndex(e, i, j, k)];
                sum += v;  // ascending k (docs/pipeline.md)
                if (v > 0) bandMap[VoxelIndex(bands, i / T, j / T, k / B)] = 1;
                cloud = cloud || cld[VoxelIndex(e, i, j, k)] != 0;
            }
            D[i + e.nx * j] = sum;
            if (sum > 0) tileMap[VoxelIndex(tiles, i / T, j / T, 0)] = 1;
            covered += cloud;
        }
    EXPECT_EQ(c.now.Of(Resource::ColumnSum), D);
    EXPECT_EQ(c.now.Of(Resource::Tiles), tileMap);
    EXPECT_EQ(c.now.Of(Resource::Bands), bandMap);
    EXPECT_EQ(c.now.coveredColumns, std::optional<uint32_t>(covered));
}

// The sun 1e-6 rad either side of a switch of the principal axis (SPEC 12),
// shaded on this step's q: both sides use different axes, and T jumps by at
// most the documented bound (docs/accuracy.md, SwitchSideBound for each side
// against the tie direction, summed).
void CheckAcrossSwitch(const ItemContext& c, double elevation, double azimuth, bool alongElevation) {
    if (!c.now.Has(Resource::T)) return;
    const Extent3 e = c.scene.grid.size;
    const double eps = 1e-6;
    const Vec3 tie = SunDirection(elevation, azimuth);
    const Vec3 minus = alongElevation ? SunDirection(elevation - eps, azimuth) : SunDirection(elevation, azimuth - eps);
    const Vec3 plus = alongElevation ? SunDirection(elevation + eps, azimuth) : SunDirection(elevation, azimuth + eps);
    ASSERT_NE(PrincipalAxis(minus), PrincipalAxis(plus)) << "the two sides must use different principal axes";
    std::vector<float> T[2];
    double bound = 0;
    for (int side = 0; side < 2; ++side) {
        ShadeParams p = MakeShadeParams(c.scene);
        p.sun = side == 0 ? minus : plus;
        auto out = test::MakeBuffer(c.backend, BufferFormat::F32, e);
        const Status s = c.backend.Shade(p, *c.sim.Q(), *out);
        ASSERT_TRUE(s.has_value()) << s.error().message;
        T[side] = test::Read<float>(c.backend, *out);
        CheckArray(Resource::T, c.scene, T[side], side == 0 ? "T at -1e-6 rad" : "T at +1e-6 rad");
        float qMax = 0;
        for (float v : c.now.Of(Resource::Q)) qMax = std::max(qMax, v);
        bound += SwitchSideBound(p, e, p.sun, tie, PrincipalAxis(p.sun), qMax);
    }
    const std::vector<double> other(T[1].begin(), T[1].end());
    const double jump = WorstDifference(T[0], other);
    EXPECT_LE(jump, bound) << "jump of T across the switch";
    EXPECT_GT(bound, 0.0);
}

// T stored as fp16 or unorm8: every value is a code of the format (fp16: a
// finite half, exponent bits not all ones; unorm8: k/255), in [0, 1].
void CheckStorageCodes(const ItemContext& c) {
    const std::vector<float>& T = c.now.Of(Resource::T);
    size_t bad = 0;
    for (float v : T) {
        if (c.scene.shade.storage == StorageFormat::Fp16) {
            const uint32_t bits = std::bit_cast<uint32_t>(v);
            const int floatExponent = int((bits >> 23) & 0xff) - 127;
            const bool halfFinite = v == 0 || floatExponent <= 15;  // half exponent field 31 is Inf/NaN
            bad += !(RoundToHalf(v) == v && halfFinite);
        } else {
            bad += !(std::nearbyint(v * 255.0f) / 255.0f == v);
        }
    }
    EXPECT_EQ(bad, 0u) << "T values that are not codes of the storage format";
    // Lit through cloud somewhere by the last step, or every value would be a code trivially.
    if (c.now.step + 1 == kSteps) {
        EXPECT_TRUE(std::any_of(T.begin(), T.end(), [](float v) { return v > 0 && v < 1; })) << "no T strictly in (0, 1)";
    }
}

// Camera indices in CameraItem.
enum Cam { kInside, kOnCorner, kOnVoxelCentre, kDownDegenerate, kDownExplicit, kUpDegenerate, kUpExplicit, kCams };

// Cameras inside the volume, on a voxel boundary (a corner), at a voxel
// centre (a splat at depth 0), and straight down and up with the degenerate
// up = +z beside twins given up = +y, which docs/pipeline.md says stands in.
std::string CamerasJson(const Extent3& e, double h) {
    const double cx = e.nx / 2 * h, cy = e.ny / 2 * h, cz = e.nz / 2 * h;  // a voxel corner
    std::ostringstream s;
    auto cam = [&](const char* name, double ex, double ey, double ez, double tx, double ty, double tz, const char* up) {
        s << (s.tellp() > 1 ? "," : "") << R"({"name": ")" << name << R"(", "eye": [)" << Num(ex) << "," << Num(ey) << ","
          << Num(ez) << "], \"target\": [" << Num(tx) << "," << Num(ty) << "," << Num(tz) << "], \"up\": " << up
          << ", \"near\": 1}";
    };
    s << "[";
    cam("inside", cx + 0.3 * h, cy + 0.2 * h, cz + 0.1 * h, 4 * cx, 1.5 * cy, cz, "[0, 0, 1]");
    cam("corner", cx, cy, cz, cx + 10 * h, cy + 3 * h, cz + h, "[0, 0, 1]");
    cam("centre", cx + h / 2, cy + h / 2, cz + h / 2, cx - 10 * h, cy + 2 * h, cz, "[0, 0, 1]");
    cam("down", cx, cy, 4 * cz, cx, cy, 0, "[0, 0, 1]");
    cam("down_y", cx, cy, 4 * cz, cx, cy, 0, "[0, 1, 0]");
    cam("up", cx, cy, -2 * cz, cx, cy, 4 * cz, "[0, 0, 1]");
    cam("up_y", cx, cy, -2 * cz, cx, cy, 4 * cz, "[0, 1, 0]");
    s << "]";
    return s.str();
}

void CheckCameras(const ItemContext& c) {
    ASSERT_EQ(c.scene.render.cameras.size(), size_t(kCams));
    EXPECT_EQ(c.now.Of(Resource::SplatImage, kDownDegenerate), c.now.Of(Resource::SplatImage, kDownExplicit))
        << "looking straight down with up parallel to the view: +y stands in";
    EXPECT_EQ(c.now.Of(Resource::SplatImage, kUpDegenerate), c.now.Of(Resource::SplatImage, kUpExplicit))
        << "looking straight up with up parallel to the view: +y stands in";
}

}  // namespace cb::spec12_test
