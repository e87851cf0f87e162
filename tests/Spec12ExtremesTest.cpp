// SPEC 12, "Numerical stability at the extremes", as one suite run on every
// backend (issue 11, item 7). Each item is a scene (ci-small with overrides)
// run through the Simulation with every output on every step. At each step,
// every output array of every enabled stage (found through the stage
// descriptors, so a new stage's outputs are checked too) is downloaded in
// canonical form and checked: no NaN or Inf, within the resource's documented
// range, 0/1 for bit fields and occupancy, T never subnormal; then the item's
// own property, hand-derived from SPEC.md and docs/pipeline.md.
//
// The soak (Spec12Soak): 10,000 automaton steps per backend with the cover
// held in a band derived from the automaton's rules, and RSS after step 100
// and step 10,000.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "core/Random.h"
#include "core/Scene.h"
#include "core/StageDescriptors.h"
#include "harness/Accuracy.h"
#include "harness/Simulation.h"
#include "harness/StageParams.h"
#include "registry/Registry.h"
#include "tests/TestUtil.h"

namespace cb::spec12_test {

// One backend per name for the whole run (an OpenGL context or a Vulkan
// device is slow to make on llvmpipe); nullptr with the reason when it cannot start.
Backend* BackendFor(const std::string& name, std::string& whyNot) {
    static std::map<std::string, std::unique_ptr<Backend>> made;
    static std::map<std::string, std::string> failed;
    if (auto it = made.find(name); it != made.end()) return it->second.get();
    if (auto it = failed.find(name); it != failed.end()) return whyNot = it->second, nullptr;
    auto backend = CreateBackend(name);
    if (!backend) return whyNot = failed[name] = backend.error().message, nullptr;
    return (made[name] = std::move(*backend)).get();
}

// ---- Every output array, downloaded and checked -------------------------------

// The outputs of one step, canonical, as float (bytes widened): current[r][camera].
struct Snapshot {
    uint32_t step = 0;
    std::optional<uint32_t> coveredColumns;
    std::array<std::vector<std::vector<float>>, kResourceCount> current;
    const std::vector<float>& Of(Resource r, size_t camera = 0) const { return current[size_t(r)].at(camera); }
    bool Has(Resource r) const { return !current[size_t(r)].empty(); }
};

// Largest P^ = 4 pi p(theta) over theta (SPEC 9): at cos = sign(g), where both
// the numerator (1 + cos^2 for Cornette-Shanks) and 1/denominator peak.
double PhaseMax(const PhaseParams& phase) {
    const double g = std::fabs(double(phase.g));
    switch (phase.kind) {
        case PhaseKind::None: return 1;
        case PhaseKind::HenyeyGreenstein: return (1 + g) / ((1 - g) * (1 - g));
        case PhaseKind::CornetteShanks: return 3 * (1 - g * g) / ((2 + g * g) * std::pow(1 - g, 3));
        // Linear interpolation never exceeds the largest tabulated value.
        case PhaseKind::Mie:
            return *std::max_element(kMieCloudTable.values, kMieCloudTable.values + kMieCloudTable.count);
    }
    return std::numeric_limits<double>::infinity();
}

// The documented range of element `index` of a resource. Images (SPEC 8, 10):
// each pixel is a convex combination (compositing with alpha in [0, 1], or
// T_view weights summing to 1) of the background and of colours
// sun*T*P^ + ambient with T in [0, 1], so each channel lies between
// min(background, ambient) and max(background, sun*P^max + ambient).
struct Bounds {
    double lo, hi;
    bool zeroOrOne = false;
};
Bounds DocumentedBounds(Resource r, const Scene& s, size_t index) {
    switch (r) {
        case Resource::Region: return {0, 255};
        case Resource::Hum:
        case Resource::Act:
        case Resource::Cld:
        case Resource::Tiles:
        case Resource::Bands: return {0, 1, true};
        case Resource::Q: return {0, 1};                      // SPEC 4: a weighted mean of bits
        case Resource::ColumnSum: return {0, double(s.grid.size.nz)};  // SPEC 5: nz values of q
        case Resource::T:
        case Resource::Shadow: return {0, 1};                 // SPEC 6, 7
        case Resource::SplatImage:
        case Resource::MarchImage: {
            const size_t c = index % 3;
            const double sun = double(s.sun.Radiance()[c]), ambient = s.lighting.ambient[c], bg = s.lighting.background[c];
            const double lo = std::min(bg, ambient), hi = std::max(bg, sun * PhaseMax(s.phase) + ambient);
            return {lo * (1 - 1e-5), hi * (1 + 1e-5)};  // float rounding of the blends
        }
    }
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
}

std::vector<float> DownloadAsFloat(Backend& backend, const Buffer& buffer) {
    if (buffer.Format() == BufferFormat::F32) return test::Read<float>(backend, buffer);
    const std::vector<uint8_t> bytes = test::Read<uint8_t>(backend, buffer);
    return std::vector<float>(bytes.begin(), bytes.end());
}

// Checks one array: finite, within DocumentedBounds, 0/1 where it is a flag,
// and for T (docs/pipeline.md "No subnormals") 0 or at least 1e-30.
void CheckArray(Resource r, const Scene& s, const std::vector<float>& values, const std::string& what) {
    size_t bad = 0, first = values.size();
    for (size_t n = 0; n < values.size(); ++n) {
        const float v = values[n];
        const Bounds b = DocumentedBounds(r, s, n);
        bool ok = std::isfinite(v) && v >= b.lo && v <= b.hi;
        if (b.zeroOrOne) ok = ok && (v == 0 || v == 1);
        if (r == Resource::T) ok = ok && (v == 0 || v >= kTransmittanceFloor);
        if (!ok) {
            if (first == values.size()) first = n;
            ++bad;
        }
    }
    if (bad > 0) {
        const Bounds b = DocumentedBounds(r, s, first);
        ADD_FAILURE() << what << ": " << bad << " of " << values.size() << " values outside the documented range; first ["
                      << first << "] = " << values[first] << ", allowed [" << b.lo << ", " << b.hi << "]"
                      << (b.zeroOrOne ? " as 0 or 1" : "") << (r == Resource::T ? ", 0 or >= 1e-30" : "");
    }
}

// Downloads and checks every output of every enabled stage: each resource an
// enabled stage writes (one buffer per camera for images), and the previous
// step's copy where one is kept. Counts the arrays checked.
Snapshot CheckEveryOutput(const Simulation& sim, uint32_t step, std::optional<uint32_t> cover, size_t& arraysChecked) {
    const Scene& scene = sim.GetScene();
    Backend& backend = sim.GetBackend();
    Snapshot snap;
    snap.step = step;
    snap.coveredColumns = cover;
    for (Stage stage : sim.Schedule()) {
        for (Resource r : Describe(stage).writes) {
            if (snap.Has(r)) continue;
            const size_t buffers = IsPerCamera(r) ? scene.render.cameras.size() : 1;
            for (size_t n = 0; n < buffers; ++n) {
                const Buffer* buffer = sim.Get(r, n);
                if (!buffer) {
                    ADD_FAILURE() << StageName(stage) << " writes " << ResourceName(r) << " but it has no buffer " << n;
                    continue;
                }
                EXPECT_EQ(buffer->Extent(), ResourceExtent(r, scene)) << ResourceName(r);
                snap.current[size_t(r)].push_back(DownloadAsFloat(backend, *buffer));
                CheckArray(r, scene, snap.current[size_t(r)].back(),
                           std::string(ResourceName(r)) + "[" + std::to_string(n) + "] at step " + std::to_string(step));
                ++arraysChecked;
            }
            if (const Buffer* previous = sim.Previous(r)) {
                CheckArray(r, scene, DownloadAsFloat(backend, *previous),
                           "previous " + std::string(ResourceName(r)) + " at step " + std::to_string(step));
                ++arraysChecked;
            }
        }
    }
    return snap;
}

// ---- The items -----------------------------------------------------------------

struct ItemContext {
    const Scene& scene;
    const Simulation& sim;
    Backend& backend;
    const Snapshot& now;    // this step's outputs
    const Snapshot& first;  // step 0's outputs
};

struct Item {
    std::string name;
    std::vector<SceneOverride> overrides;
    // The item's own property, checked at every step after the generic checks.
    std::function<void(const ItemContext&)> check;
    // A value at the edge of what docs/scenes.md accepts: the scene may
    // instead be refused at load time, naming this field.
    std::string mayBeRefusedAt = "";
};

constexpr uint32_t kSteps = 3;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

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

std::vector<Item> Items() {
    // Overhead, cos(90 deg) ~ 6e-17 leaves s_x, s_y tiny. At azimuth 225 both
    // are negative: column 0's taps are -1 and 0 with weights 0 and 1 (the
    // fraction 1 - 4e-17 rounds to 1), every other column's its own, so the
    // taps are exact even for an infinitely opaque neighbour.
    const std::string sunOverhead = R"({"elevation_deg": 90, "azimuth_deg": 225})";
    std::vector<Item> items;
    items.push_back({"SunOverhead", {{"sun", sunOverhead}}, [](const ItemContext& c) { CheckVerticalSun(c, true); }});
    items.push_back({"SunStraightBelow",
                     {{"sun", R"({"elevation_deg": -90, "azimuth_deg": 60})"}},
                     [](const ItemContext& c) { CheckVerticalSun(c, false); }});
    // The switches of docs/accuracy.md: z/y at azimuth 60 (elevation atan(sin 60)),
    // x/y at azimuth 45 (elevation 25), and z/x at azimuth 0 (elevation 45). The
    // simulation runs with the sun exactly on the switch; the sides are shaded on its q.
    const double zy = std::atan(std::sin(60 * kDeg));
    items.push_back({"SunOnSwitchZY",
                     {{"sun.elevation_deg", Num(zy / kDeg)}, {"sun.azimuth_deg", "60"}},
                     [zy](const ItemContext& c) { CheckAcrossSwitch(c, zy, 60 * kDeg, true); }});
    items.push_back({"SunOnSwitchXY",
                     {{"sun.elevation_deg", "25"}, {"sun.azimuth_deg", "45"}},
                     [](const ItemContext& c) { CheckAcrossSwitch(c, 25 * kDeg, 45 * kDeg, false); }});
    items.push_back({"SunOnSwitchZX",
                     {{"sun.elevation_deg", "45"}, {"sun.azimuth_deg", "0"}},
                     [](const ItemContext& c) { CheckAcrossSwitch(c, 45 * kDeg, 0, true); }});
    // Grazing: s_z = 1e-4 sends the ground shadow's tap (s_x, s_y) nz / (2 s_z)
    // ~ 8e4 cells away, outside the grid (D = 0): G = exp(0) = 1 exactly.
    // On and below the horizon, s_z <= 0: G = 1 (SPEC 7, docs/pipeline.md).
    auto groundIsLit = [](const ItemContext& c) { ExpectAll(c.now.Of(Resource::Shadow), 1, "G"); };
    items.push_back({"SunGrazing", {{"sun.elevation_deg", Num(std::asin(1e-4) / kDeg)}}, groundIsLit});
    items.push_back({"SunOnHorizon", {{"sun.elevation_deg", "0"}}, groundIsLit});
    items.push_back({"SunBelowHorizon", {{"sun.elevation_deg", "-10"}}, groundIsLit});
    items.push_back({"SunGrazingThesisForms",
                     {{"sun.elevation_deg", Num(std::asin(1e-4) / kDeg)},
                      {"shade.attenuation", "thesis"},
                      {"shadow.form", "thesis"}},
                     groundIsLit});
    // sigma = 0: every factor is exp(0) = 1, so T = 1 and G = 1 exactly (SPEC 12).
    items.push_back({"SigmaZero", {{"shade.sigma", "0"}}, [](const ItemContext& c) {
                         ExpectAll(c.now.Of(Resource::T), 1, "T");
                         ExpectAll(c.now.Of(Resource::Shadow), 1, "G");
                     }});
    // sigma = 1e6: sigma h q >= 1e6 * 50 / 64 for any q > 0, so T = 0 behind cloud.
    items.push_back({"SigmaHugeOverhead",
                     {{"shade.sigma", "1e6"}, {"sun", sunOverhead}},
                     [](const ItemContext& c) { CheckOpaqueColumns(c, true); }});
    // SPEC 12: "No stage may return NaN or Inf for any valid input". sigma and
    // voxel_size accept any finite positive number (docs/scenes.md), but
    // sigma h overflows float beyond ~3e38: such a scene must either be refused
    // or shade as opaque cloud, like sigma = 1e6 (T = 0 behind cloud, 1 on
    // clear paths; G = 0 under cloud, 1 elsewhere).
    auto opaqueOverhead = [](const ItemContext& c) {
        CheckOpaqueColumns(c, true);
        const std::vector<float>& D = c.now.Of(Resource::ColumnSum);
        std::vector<double> G(D.size());
        for (size_t n = 0; n < D.size(); ++n) G[n] = D[n] > 0 ? 0 : 1;
        EXPECT_LE(WorstDifference(c.now.Of(Resource::Shadow), G), 1e-5) << "G: 0 under cloud, 1 elsewhere";
    };
    for (const auto& [name, path, value] : std::vector<std::tuple<std::string, std::string, std::string>>{
             {"SigmaBeyondFloat", "shade.sigma", "1e39"},
             {"SigmaLargestDouble", "shade.sigma", "1.7976931348623157e308"},
             {"VoxelSizeBeyondFloat", "grid.voxel_size", "1e39"},
             {"VoxelSize1e300", "grid.voxel_size", "1e300"}}) {
        items.push_back({name, {{path, value}, {"sun", sunOverhead}}, opaqueOverhead, path});
        items.push_back({name + "Scattering",
                         {{path, value}, {"shade.scattering", R"({"enabled": true})"}, {"shade.storage", "fp16"}},
                         {},
                         path});
    }
    items.push_back({"SigmaHugeTilted", {{"shade.sigma", "1e6"}, {"shade.resolution", "2"}}, {}});
    items.push_back({"SigmaHugeScattering",
                     {{"shade.sigma", "1e6"}, {"shade.scattering", R"({"enabled": true, "albedo": 1})"}},
                     {}});
    // Empty sky: no ellipsoid, so R = 0 and no cloud ever (cld2 & R > 0):
    // q = D = 0, no occupancy, cover 0, T = G = 1, every pixel the background.
    items.push_back({"EmptyVolume", {{"ellipsoids.target_count", "0"}}, [](const ItemContext& c) {
                         ExpectAll(c.now.Of(Resource::Region), 0, "R");
                         ExpectAll(c.now.Of(Resource::Cld), 0, "cld");
                         ExpectAll(c.now.Of(Resource::Q), 0, "q");
                         ExpectAll(c.now.Of(Resource::ColumnSum), 0, "D");
                         ExpectAll(c.now.Of(Resource::Tiles), 0, "tiles");
                         ExpectAll(c.now.Of(Resource::Bands), 0, "bands");
                         EXPECT_EQ(c.now.coveredColumns, std::optional<uint32_t>(0));
                         ExpectAll(c.now.Of(Resource::T), 1, "T");
                         ExpectAll(c.now.Of(Resource::Shadow), 1, "G");
                         const std::vector<float>& image = c.now.Of(Resource::SplatImage);
                         for (size_t n = 0; n < image.size(); ++n)
                             ASSERT_EQ(image[n], float(c.scene.lighting.background[n % 3])) << "pixel value " << n;
                     }});
    items.push_back({"FullVolume", FullVolume(), CheckFullVolume});
    items.push_back({"FullVolumeSigmaHuge", Plus(FullVolume(), {{"shade.sigma", "1e6"}}), CheckFullVolume});
    items.push_back({"Grid1x1x1", Plus(FullVolume(), {{"grid.size", "[1, 1, 1]"}}), CheckFullVolume});
    items.push_back({"Grid1x1xNz", Plus(FullVolume(), {{"grid.size", "[1, 1, 16]"}}), CheckFullVolume});
    items.push_back({"Grid1x1x1Clouds", {{"grid.size", "[1, 1, 1]"}}, {}});
    items.push_back({"Grid1x1xNzClouds", {{"grid.size", "[1, 1, 16]"}, {"ca.act0", "0.05"}}, {}});
    // Sizes that are not multiples of 64 or of the tile (16) or band (4; 3).
    items.push_back({"OddSizes70x33x17", {{"grid.size", "[70, 33, 17]"}}, CheckDensityOnPartialTiles});
    items.push_back({"OddSizes65x63x5Tile7Band3",
                     {{"grid.size", "[65, 63, 5]"}, {"density.tile", "7"}, {"density.band", "3"}},
                     CheckDensityOnPartialTiles});
    items.push_back({"OddSizesFull70x33x17", Plus(FullVolume(), {{"grid.size", "[70, 33, 17]"}}),
                     [](const ItemContext& c) {
                         CheckFullVolume(c);
                         CheckDensityOnPartialTiles(c);
                     }});
    // p = 1 always fires: with R = 255 (P = Q), hum2 = act2 = 1 every step and
    // nothing is extinguished (P_ext = 0), and step 0's act makes cld = 1.
    items.push_back({"ProbabilitiesOne",
                     Plus(FullRegion(), {{"ca", R"({"hum0": 1, "act0": 1, "p_ext": 1, "p_hum": 1, "p_act": 1})"}}),
                     [](const ItemContext& c) {
                         ExpectAll(c.now.Of(Resource::Hum), 1, "hum");
                         ExpectAll(c.now.Of(Resource::Act), 1, "act");
                         ExpectAll(c.now.Of(Resource::Cld), c.now.step == 0 ? 0 : 1, "cld");
                     }});
    // p = 0 never fires: act0 = 0 and p_act = 0 leave act = 0, so nothing
    // grows, cld stays 0, and hum (hum & !act | never) keeps its initial
    // draw, rand24(seed, 0xFFFFFFFF, 1, v) < Q(0.5), at every step (SPEC 3).
    items.push_back({"ProbabilitiesZero",
                     Plus(FullRegion(), {{"ca", R"({"seed": 9, "hum0": 0.5, "act0": 0, "p_ext": 0, "p_hum": 0, "p_act": 0})"}}),
                     [](const ItemContext& c) {
                         ExpectAll(c.now.Of(Resource::Act), 0, "act");
                         ExpectAll(c.now.Of(Resource::Cld), 0, "cld");
                         const std::vector<float>& hum = c.now.Of(Resource::Hum);
                         size_t differ = 0, humid = 0;
                         for (uint32_t v = 0; v < hum.size(); ++v) {
                             const bool expected = Rand24(9, kInitialStateStep, 1, v) < QuantizeProbability(0.5);
                             differ += (hum[v] != 0) != expected;
                             humid += expected;
                         }
                         EXPECT_EQ(differ, 0u) << "hum differs from its initial draw";
                         EXPECT_NEAR(double(humid) / double(hum.size()), 0.5, 0.02);
                     }});
    const Extent3 camGrid{32, 32, 8};
    const std::string cameras = CamerasJson(camGrid, 50);
    items.push_back({"CamerasInClouds", {{"grid.size", "[32, 32, 8]"}, {"render.cameras", cameras}}, CheckCameras});
    items.push_back({"CamerasInFullVolume",
                     Plus(FullVolume(), {{"grid.size", "[32, 32, 8]"}, {"render.cameras", cameras}}),
                     CheckCameras});
    // fp16 and unorm8 storage at full resolution: T holds storage codes. At
    // f = 2 and 4, T is read trilinearly from the coarse grid's codes (not a
    // code itself): checked for range only.
    items.push_back({"StorageFp16", {{"shade.storage", "fp16"}}, CheckStorageCodes});
    items.push_back({"StorageUnorm8", {{"shade.storage", "unorm8"}}, CheckStorageCodes});
    items.push_back({"StorageFp16SigmaHuge", {{"shade.storage", "fp16"}, {"shade.sigma", "1e6"}}, CheckStorageCodes});
    items.push_back({"StorageUnorm8Thesis", {{"shade.storage", "unorm8"}, {"shade.attenuation", "thesis"}}, CheckStorageCodes});
    items.push_back({"StorageFp16Coarse", {{"shade.storage", "fp16"}, {"shade.resolution", "2"}}, {}});
    items.push_back({"StorageUnorm8Coarse", {{"shade.storage", "unorm8"}, {"shade.resolution", "4"}}, {}});
    // A strongly forward phase function makes the scattering factor exceed 1
    // (docs/pipeline.md: clamped to [0, 1]).
    items.push_back({"ScatteringStrongForwardFp16",
                     {{"shade.storage", "fp16"},
                      {"shade.scattering", R"({"enabled": true, "albedo": 1, "solid_angle": 1})"},
                      {"phase.g", "0.9"}},
                     {}});
    return items;
}

// Every item shares: ci-small, kSteps steps from step 0, a 64 x 48 image.
std::vector<SceneOverride> BaseOverrides() {
    return {{"steps", std::to_string(kSteps)}, {"warmup_steps", "0"}, {"render.width", "64"}, {"render.height", "48"}};
}

// Runs one SPEC 12 item on one backend: every output of every enabled stage
// at every step is finite and in its documented range, and the item's own property holds.
void RunItem(Backend& backend, const Item& item) {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", Plus(BaseOverrides(), item.overrides));
    if (!scene && !item.mayBeRefusedAt.empty()) {
        EXPECT_NE(scene.error().message.find(item.mayBeRefusedAt), std::string::npos) << scene.error().message;
        return;
    }
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    auto sim = Simulation::Create(*scene, backend, /*everyStepOutputs=*/true);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;
    size_t arrays = 0;
    Snapshot first;
    for (uint32_t t = 0; t < scene->steps; ++t) {
        StepRecord record;
        const Status status = (*sim)->Step(record, [&](const Simulation& s) -> Status {
            const Snapshot now = CheckEveryOutput(s, t, record.coveredColumns, arrays);
            if (t == 0) first = now;
            if (item.check) item.check({*scene, s, backend, now, first});
            return {};
        });
        ASSERT_TRUE(status.has_value()) << "step " << t << ": " << status.error().message;
    }
    // After the last step the automaton's next state is current: check it too.
    CheckEveryOutput(**sim, scene->steps, std::nullopt, arrays);
    // Every buffer the enabled stages write (less the automaton's next-step
    // buffers, swapped in each step) was checked after every step.
    size_t perStep = 0;
    for (const PlannedBuffer& planned : PlanBuffers(*scene)) perStep += planned.role != BufferRole::Next;
    EXPECT_EQ(arrays, perStep * (scene->steps + 1));
}

class Spec12Extremes : public ::testing::TestWithParam<std::string> {};

// Test every SPEC 12 item on one backend (RunItem). One test per backend, the
// items in a loop, each failure naming its item: one process per item and
// backend cost more in start-up than the items themselves (docs: reports/reliability/spec12.md).
TEST_P(Spec12Extremes, EveryItemEveryOutputFiniteAndInRange) {
    std::string whyNot;
    Backend* backend = BackendFor(GetParam(), whyNot);
    if (!backend) GTEST_SKIP() << "unsupported here: " << whyNot;
    for (const Item& item : Items()) {
        SCOPED_TRACE("item " + item.name);
        const auto start = std::chrono::steady_clock::now();
        RunItem(*backend, item);
        std::printf("%s %s: %.0f ms\n", GetParam().c_str(), item.name.c_str(),
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, Spec12Extremes, ::testing::Values("cpu", "gl", "vk"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// ---- The soak: 10,000 automaton steps ---------------------------------------------

// VmRSS of this process in KiB (0 where /proc is missing).
uint64_t ResidentKiB() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmRSS:", 0) == 0) return std::stoull(line.substr(6));
    return 0;
}

// P_x of SPEC 3.2 for region weight R: (R Q + 127) / 255, uint32.
uint32_t RegionProbability(uint32_t R, uint32_t Q) { return (R * Q + 127) / 255; }

constexpr uint32_t kSoakSteps = 10000;

class Spec12Soak : public ::testing::TestWithParam<std::string> {};

// Test 10,000 automaton steps (SPEC 12) on a 32 x 32 x 8 grid with ci-small's
// probabilities and its ellipsoids scaled to the grid, stages region and ca
// (smooth and density tripled gl's time; their cover is tested by the
// items), the cover counted from the downloaded cld every step. The band is
// derived from SPEC 3, pathwise (no statistics, so it cannot flake), for
// every step t:
//
// Upper: step 3 ends with cld2 = cld2 & (R > 0) and there is no wind shift, so
//   cld_t lies inside R_{t-1} > 0 and cover_t <= the columns with any R_{t-1} > 0.
// Lower: strip the automaton of growth. act2 = act1 | [rand24(seed,t,2,v) < P_act]
//   holds the spontaneous activations whatever the state, and
//   cld_{t+1} = (cld_t | act_t) & !ext & (R_t > 0) is monotone in cld_t and
//   act_t, with the extinction draws fixed by (seed, t, v). So a host automaton
//   with only those draws, act'_{t+1} = [rand24(seed,t,2,v) < P_act(R_t)],
//   cld'_{t+1} = (cld'_t | act'_t) & !ext_t & (R_t > 0), from the same act_0
//   and cld_0 = 0, stays inside the real one step after step (induction), and
//   cover_t >= the columns with any cld'_t.
// Memory must stay flat: RSS after step 10,000 at most 32 MiB above step 100
// (a leak of 4 KiB per step would exceed it).
TEST_P(Spec12Soak, TenThousandStepsCoverInBandMemoryFlat) {
    std::string whyNot;
    Backend* backend = BackendFor(GetParam(), whyNot);
    if (!backend) GTEST_SKIP() << "unsupported here: " << whyNot;
    auto scene = LoadScene(
        std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
        {{"grid.size", "[32, 32, 8]"},
         {"steps", std::to_string(kSoakSteps)},
         {"warmup_steps", "0"},
         {"stages", R"(["region", "ca"])"},
         {"ellipsoids.size_mean", "[5, 5, 2.5]"},
         {"ellipsoids.size_variance", "[1.5, 1.5, 0.5]"},
         {"ellipsoids.margin", "4"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const Extent3 e = scene->grid.size;
    const uint32_t seed = scene->ca.seed, columns = e.nx * e.ny;
    const uint32_t qExt = QuantizeProbability(scene->ca.pExt), qAct = QuantizeProbability(scene->ca.pAct);
    ASSERT_TRUE(scene->ca.windShift.empty() || !scene->ca.HasWind()) << "the upper bound assumes no advection";
    auto sim = Simulation::Create(*scene, *backend);
    ASSERT_TRUE(sim.has_value()) << sim.error().message;

    std::vector<uint8_t> act(e.Count()), cld(e.Count(), 0), supportPrev;  // the growth-free automaton
    for (uint32_t v = 0; v < act.size(); ++v)
        act[v] = Rand24(seed, kInitialStateStep, 2, v) < QuantizeProbability(scene->ca.act0);
    auto coveredBy = [&](const std::vector<uint8_t>& field) {
        uint32_t n = 0;
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) {
                bool any = false;
                for (uint32_t k = 0; k < e.nz && !any; ++k) any = field[VoxelIndex(e, i, j, k)] != 0;
                n += any;
            }
        return n;
    };
    uint32_t minCover = columns, maxCover = 0, outside = 0;
    double sumCover = 0, sumLower = 0, sumUpper = 0;
    uint64_t rss100 = 0;
    const auto start = std::chrono::steady_clock::now();
    for (uint32_t t = 0; t < kSoakSteps; ++t) {
        StepRecord record;
        std::vector<uint8_t> R, cldNow;
        const Status status = (*sim)->Step(record, [&](const Simulation& s) -> Status {
            R = test::Read<uint8_t>(*backend, *s.Region());
            cldNow = test::Read<uint8_t>(*backend, *s.Cld());
            return {};
        });
        ASSERT_TRUE(status.has_value()) << "step " << t << ": " << status.error().message;
        const uint32_t cover = coveredBy(cldNow);
        const uint32_t lower = coveredBy(cld), upper = t == 0 ? 0 : coveredBy(supportPrev);
        if (cover < lower || cover > upper) {
            if (outside++ < 5) ADD_FAILURE() << "step " << t << ": cover " << cover << " outside [" << lower << ", " << upper << "]";
        }
        minCover = std::min(minCover, cover), maxCover = std::max(maxCover, cover);
        sumCover += cover, sumLower += lower, sumUpper += upper;
        // Advance the growth-free automaton with R_t, and keep R_t > 0 for the next step's upper bound.
        supportPrev.assign(R.size(), 0);
        for (uint32_t v = 0; v < R.size(); ++v) {
            const bool extinct = Rand24(seed, t, 0, v) < RegionProbability(255 - R[v], qExt);
            const bool nextCld = (cld[v] || act[v]) && !extinct && R[v] > 0;
            act[v] = R[v] > 0 && Rand24(seed, t, 2, v) < RegionProbability(R[v], qAct);
            cld[v] = nextCld;
            supportPrev[v] = R[v] > 0;
        }
        if (t + 1 == 100) rss100 = ResidentKiB();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const uint64_t rssEnd = ResidentKiB();
    EXPECT_EQ(outside, 0u) << "steps with the cover outside its band";
    EXPECT_GT(sumLower, 0.0) << "the lower bound never rose above 0: the band proves nothing";
    EXPECT_LE(rssEnd, rss100 + 32 * 1024) << "RSS grew from " << rss100 << " KiB at step 100 to " << rssEnd << " KiB";
    std::printf("soak %s: %u steps of %ux%ux%u in %.1f s; RSS %llu KiB after step 100, %llu KiB after step %u; "
                "cover min %.4f max %.4f mean %.4f (band means: lower %.4f, upper %.4f)\n",
                GetParam().c_str(), kSoakSteps, e.nx, e.ny, e.nz, seconds, (unsigned long long)rss100,
                (unsigned long long)rssEnd, kSoakSteps, minCover / double(columns), maxCover / double(columns),
                sumCover / kSoakSteps / columns, sumLower / kSoakSteps / columns, sumUpper / kSoakSteps / columns);
}

INSTANTIATE_TEST_SUITE_P(Backends, Spec12Soak, ::testing::Values("cpu", "gl", "vk"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace cb::spec12_test
