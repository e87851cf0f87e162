// The algorithm of the lighting stages (docs/contract.md sections 6-9): sun direction,
// principal axis, per-slice attenuation, phase functions, storage rounding,
// and the splat kernel. Backends keep only their schedule.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

namespace cb {

using Vec3 = std::array<float, 3>;

// s = (cos el cos az, cos el sin az, sin el): unit vector toward the sun.
inline Vec3 SunDirection(double elevationRad, double azimuthRad) {
    return {float(std::cos(elevationRad) * std::cos(azimuthRad)), float(std::cos(elevationRad) * std::sin(azimuthRad)),
            float(std::sin(elevationRad))};
}

// Principal axis w (0 = x, 1 = y, 2 = z): z if |s_z| >= max(|s_x|, |s_y|),
// else y if |s_y| >= |s_x|, else x. Ties go to the later axis in that order.
inline int PrincipalAxis(const Vec3& s) {
    const float ax = std::fabs(s[0]), ay = std::fabs(s[1]), az = std::fabs(s[2]);
    if (az >= std::max(ax, ay)) return 2;
    if (ay >= ax) return 1;
    return 0;
}

// ---- exp ---------------------------------------------------------------------

// exp(x) for x <= 0 in float, within 2 ulp of the correctly rounded result for
// x in [-87, 0] (tested against std::exp in double), and exactly 0 below -87,
// so no result is subnormal. Written so that loops over it vectorise
// (std::exp does not without -ffast-math).
inline float ExpNonPositive(float x) {
    const bool underflows = x < -87.0f;
    x = std::max(x, -87.0f);
    // x = k ln2 + r, |r| <= ln2/2, with ln2 split in a high part exact in float.
    const float k = std::nearbyint(x * 1.44269504088896341f);
    float r = x - k * 0.693145751953125f;
    r = r - k * 1.42860682030941723212e-6f;
    // exp(r) by its Taylor series to r^7 (|error| < 2^-26 on |r| <= ln2/2).
    float p = 1.0f / 5040.0f;
    p = p * r + 1.0f / 720.0f;
    p = p * r + 1.0f / 120.0f;
    p = p * r + 1.0f / 24.0f;
    p = p * r + 1.0f / 6.0f;
    p = p * r + 0.5f;
    p = p * r + 1.0f;
    p = p * r + 1.0f;
    // 2^k, k in [-126, 0]: build the float exponent directly.
    const int32_t bits = (int32_t(k) + 127) << 23;
    const float result = p * std::bit_cast<float>(bits);
    return underflows ? 0.0f : result;
}

// Transmittance below this is stored as 0: products of many small factors would
// otherwise reach subnormal floats, which are slow on CPUs and flushed on GPUs.
inline constexpr float kTransmittanceFloor = 1e-30f;

// ---- Storage precision of T (SPEC 6) -------------------------------------------

enum class StorageFormat : uint8_t { Fp32, Fp16, Unorm8 };

// Rounds to the nearest IEEE half (ties to even) and back. T is in [0, 1], so
// the result is never infinite; subnormal halves are kept.
inline float RoundToHalf(float value) {
    const uint32_t bits = std::bit_cast<uint32_t>(value);
    const uint32_t sign = bits & 0x80000000u;
    const uint32_t magnitude = bits & 0x7fffffffu;
    if (magnitude >= 0x477ff000u) return std::bit_cast<float>(sign | 0x7f800000u);  // overflow: not reached for T
    if (magnitude < 0x38800000u) {
        // Half subnormal range: quantum 2^-24. Rounding x * 2^24 to an integer
        // (ties to even, the default mode) is exact rounding here.
        const float scaled = std::nearbyint(std::fabs(value) * 16777216.0f);
        return std::copysign(scaled * (1.0f / 16777216.0f), value);
    }
    // Normal: keep 10 of the 23 mantissa bits, ties to even.
    const uint32_t lsb = (magnitude >> 13) & 1u;
    const uint32_t rounded = (magnitude + 0x0fffu + lsb) & ~0x1fffu;
    return std::bit_cast<float>(sign | rounded);
}

// Rounds to k/255 for the nearest integer k (ties to even); value in [0, 1].
inline float RoundToUnorm8(float value) { return std::nearbyint(std::clamp(value, 0.0f, 1.0f) * 255.0f) / 255.0f; }

inline float RoundToStorage(StorageFormat format, float value) {
    switch (format) {
        case StorageFormat::Fp32:
            return value;
        case StorageFormat::Fp16:
            return RoundToHalf(value);
        case StorageFormat::Unorm8:
            return RoundToUnorm8(value);
    }
    return value;
}

// The integer code of a stored value (RoundToStorage's output, in [0, 1]): k
// for k/255 in unorm8, the half's bit pattern in fp16, the float's bits in
// fp32. Codes grow with the value and neighbouring stored values differ by
// one, so SPEC 6's "one storage quantum" is |code difference| <= 1, compared
// as integers: a float difference can exceed 1/255 by an ulp.
inline uint32_t StorageCode(StorageFormat format, float stored) {
    switch (format) {
        case StorageFormat::Fp32:
            return std::bit_cast<uint32_t>(stored);
        case StorageFormat::Unorm8:
            return uint32_t(std::lround(std::clamp(stored, 0.0f, 1.0f) * 255.0f));
        case StorageFormat::Fp16: {
            const uint32_t bits = std::bit_cast<uint32_t>(std::fabs(stored));
            if (bits < 0x38800000u) return uint32_t(std::lround(std::fabs(stored) * 16777216.0f));  // subnormal half
            return ((((bits >> 23) - 112u) << 10) | ((bits >> 13) & 0x3ffu));  // rebias 127 -> 15, top 10 bits
        }
    }
    return 0;
}

// One storage quantum at value v: the comparison tolerance for fp16/unorm8 (SPEC 6).
inline float StorageQuantum(StorageFormat format) {
    switch (format) {
        case StorageFormat::Fp32:
            return 0.0f;
        case StorageFormat::Fp16:
            return 1.0f / 2048.0f;  // half spacing just below 1
        case StorageFormat::Unorm8:
            return 1.0f / 255.0f;
    }
    return 0.0f;
}

// a (1 - t) + b t (the build never fuses it into an FMA). GLSL twin: shading.glsl Lerp.
inline float Lerp(float a, float b, float t) { return a * (1.0f - t) + b * t; }

// Wang, Ji and Zhang's eq. 16: D max(v - (m + 1 - C), 0), clamped to 1, for a value v in [0, 1], the 2-D
// modulation map m, coverage C and density factor D: the noise stage's coverage form of q, and
// render_layers' `wang` opacity.
inline float CoverageModulate(float v, float m, float coverage, float density) {
    const float excess = v - (m + 1.0f - coverage);
    return std::min(density * (excess > 0.0f ? excess : 0.0f), 1.0f);
}

// ---- Phase functions (SPEC 9), normalised so that isotropic gives 1 ----------

enum class PhaseKind : uint8_t { None, HenyeyGreenstein, CornetteShanks, Mie, DualLobe };

// The dual lobe's defaults (docs/scenes.md, "phase"): Hillaire's Frostbite clouds (2016), a forward lobe of g 0.8
// and a backward one of g -0.5 blended half and half.
inline constexpr float kDualLobeGForward = 0.8f, kDualLobeGBackward = -0.5f, kDualLobeBlend = 0.5f;

struct PhaseParams {
    PhaseKind kind = PhaseKind::HenyeyGreenstein;
    float g = 0.6f;  // Henyey-Greenstein and Cornette-Shanks; Mie ignores it (its g is the table's)
    // The dual lobe, (1 - blend) HG(gForward) + blend HG(gBackward); only it reads these.
    float gForward = kDualLobeGForward;    // in [0, 1)
    float gBackward = kDualLobeGBackward;  // in (-1, 0]
    float blend = kDualLobeBlend;          // the backward lobe's weight w, in [0, 1]
};

// P^ tabulated at `count` uniform angles theta_i = i pi / (count - 1), values[0]
// at theta = 0 and values[count - 1] at pi; count >= 2. Not owning.
struct PhaseTable {
    const float* values = nullptr;
    uint32_t count = 0;
    float indexPerRadian = 0;  // (count - 1) / pi
};

// arccos(x) for x in [-1, 1], |error| < 1e-6 rad: Abramowitz & Stegun 4.4.46,
// acos(x) = sqrt(1 - x) (a0 + a1 x + ... + a7 x^7) on [0, 1] (|error| <= 2e-8
// in exact arithmetic), and pi - acos(-x) below 0. The project's own so that
// every backend evaluates the same operations (GLSL's acos has no stated
// precision); twin in core/math/shading.glsl.
inline float ArcCos(float x) {
    const float a = std::fabs(x);
    float p = -0.0012624911f;
    p = p * a + 0.0066700901f;
    p = p * a - 0.0170881256f;
    p = p * a + 0.0308918810f;
    p = p * a - 0.0501743046f;
    p = p * a + 0.0889789874f;
    p = p * a - 0.2145988016f;
    p = p * a + 1.5707963050f;
    const float r = std::sqrt(1.0f - a) * p;
    return x < 0.0f ? 3.14159265358979f - r : r;
}

// The table linearly interpolated in theta = ArcCos(cosTheta), cosTheta
// clamped to [-1, 1]. The result lies between the two nearest values.
inline float SamplePhaseTable(const PhaseTable& table, float cosTheta) {
    const float theta = ArcCos(std::clamp(cosTheta, -1.0f, 1.0f));
    const float x = std::clamp(theta * table.indexPerRadian, 0.0f, float(table.count - 1));
    const uint32_t i = std::min(uint32_t(x), table.count - 2);
    return Lerp(table.values[i], table.values[i + 1], x - float(i));
}

// The project's Lorenz-Mie table for cumulus droplets (r_eff 10 um, v_eff 0.1,
// 0.55 um, water): generated at build time by tools/MieTableGen.cpp
// (docs/pipeline.md, "Mie phase table"); defined in the generated MieTable.cpp
// of cloudbench_core.
extern const PhaseTable kMieCloudTable;

// Henyey-Greenstein's P^(cos theta) = (1 - g^2) / (1 + g^2 - 2 g cos)^1.5. GLSL twin: shading.glsl HenyeyGreenstein.
inline float HenyeyGreenstein(float g, float cosTheta) {
    const float denom = 1.0f + g * g - 2.0f * g * cosTheta;
    return (1.0f - g * g) / (denom * std::sqrt(denom));
}

// P^(cos theta) = 4 pi p(theta).
inline float PhaseValue(const PhaseParams& phase, float cosTheta) {
    const float g = phase.g;
    switch (phase.kind) {
        case PhaseKind::None:
            return 1.0f;
        case PhaseKind::HenyeyGreenstein:
            return HenyeyGreenstein(g, cosTheta);
        case PhaseKind::CornetteShanks: {
            const float denom = 1.0f + g * g - 2.0f * g * cosTheta;
            return 1.5f * (1.0f - g * g) / (2.0f + g * g) * (1.0f + cosTheta * cosTheta) / (denom * std::sqrt(denom));
        }
        case PhaseKind::Mie:
            return SamplePhaseTable(kMieCloudTable, cosTheta);
        case PhaseKind::DualLobe:
            // Lerp: a blend of 0 gives the forward lobe's bits, 1 the backward's (each lobe is finite).
            return Lerp(HenyeyGreenstein(phase.gForward, cosTheta), HenyeyGreenstein(phase.gBackward, cosTheta),
                        phase.blend);
    }
    return 1.0f;
}

// The largest P^ over cos theta in [-1, 1] as PhaseValue evaluates it in float:
// at cos = 1 for g >= 0 and at -1 for g < 0 (Henyey-Greenstein, Cornette-
// Shanks: every rounding in PhaseValue is monotone in cos, and g -> -g,
// cos -> -cos gives the same floats), the table's largest value for Mie (the
// interpolation lies between two values), 1 for none. Near |g| = 1 the float
// value is far from the exact (1 + g)/(1 - g)^2: the denominator 1 + g^2 - 2g
// is a difference of numbers near 2, a multiple of 2^-23, and 0 (peak inf)
// for most |g| within 3e-4 of 1 (the first at 0.999701). The dual lobe: the larger of its values at cos = 1
// and -1. Its lobes run opposite ways (the forward one, g >= 0, rises with cos, the backward one falls), so
// the blend is not monotone, but each lobe is convex in cos ((a - b cos)^-1.5 with a > |b|) and so is any
// blend with weights >= 0: its largest value on [-1, 1] is at an end, and either end may be it (cos = -1
// with blend 0.9 and g_backward -0.9). In float an inner cos may round an ulp above the larger end where
// the blend is nearly flat ((0.2, -0.2, 1/2) at cos = -1 + 2^-22; DualLobe.PeakIsAtAnEnd bounds it at 2),
// far inside kMaxPhasePeak's margin of 2^1.5 (below).
inline float PhasePeak(const PhaseParams& phase) {
    if (phase.kind == PhaseKind::Mie) {
        float peak = 0;
        for (uint32_t i = 0; i < kMieCloudTable.count; ++i) peak = std::max(peak, kMieCloudTable.values[i]);
        return peak;
    }
    const float forward = PhaseValue(phase, 1.0f), backward = PhaseValue(phase, -1.0f);
    // NaN (never for |g| < 1, but a bound must not pass it) reads as infinite.
    if (std::isnan(forward) || std::isnan(backward)) return std::numeric_limits<float>::infinity();
    return std::max(forward, backward);
}

// The largest phase peak (PhasePeak) a scene may have: 2^18. The renderers
// evaluate P^ at cos theta = s . d of unit vectors in float, which may round
// past 1 (by 2 ulps of 1 in float on the CPU; the twins' GLSL division and
// square root add a few more): bounds are made for |cos| up to 1 + 2^-19, 16
// ulps. For Henyey-Greenstein and Cornette-Shanks the peak is about 2/d with
// d = (1 - |g|)^2 the denominator at |cos| = 1, so a peak <= 2^18 keeps
// d >= 2^-17, and cos = 1 + 2^-19 lowers d by 2|g| 2^-19 <= 2^-18, at most
// half: no denominator reaches 0 (inf) or goes negative (NaN, from the square
// root), and every P^ a renderer evaluates is at most 2^1.5 times the peak,
// 2^19.5 < 7.5e5 (checked for every float g in [0.9, 1) whose peak passes:
// FiniteBounds.PhasePeakBoundKeepsEveryCosineFinite). Shade's forward
// scattering gain alpha_s P^(0) gamma / (4 pi) is then at most 2^18 too.
inline constexpr float kMaxPhasePeak = 262144.0f;

// ---- Per-slice attenuation (SPEC 6) --------------------------------------------

enum class AttenuationKind : uint8_t { Beer, Thesis };
// Forms of the ground shadow (SPEC 7): beer, the thesis's inverted density map,
// and Wang's coverage-modulated shadow factor (Wang, Ji and Zhang, eq. 19).
enum class ShadowForm : uint8_t { Beer, Thesis, Wang };
enum class SampleFilter : uint8_t { Bilinear, Nearest };

struct SliceAttenuation {
    AttenuationKind kind = AttenuationKind::Beer;
    float opticalDepthPerQ = 0;  // sigma * h_slice / |s_w| (beer, and tau for scattering)
    float thesisAr = 0.9f;       // a_r of the thesis form
    float scatterGain = 0;       // albedo * P^(0) * gamma / (4 pi); 0 = no multiple scattering

    float Factor(float q) const;
};

// The factor by which light is multiplied crossing a slice of density q,
// clamped to [0, 1] (forward scattering may otherwise exceed 1). Free of the
// struct so that a loop with `beer` fixed at compile time vectorises.
// GLSL twin: shading.glsl SliceFactor.
inline float SliceFactor(bool beer, float depthPerQ, float thesisAr, float scatterGain, float q) {
    const float tau = depthPerQ * q;
    const float a = beer ? ExpNonPositive(-tau) : 1.0f - (1.0f - thesisAr) * q;
    return std::clamp(a + scatterGain * tau, 0.0f, 1.0f);
}

inline float SliceAttenuation::Factor(float q) const {
    return SliceFactor(kind == AttenuationKind::Beer, opticalDepthPerQ, thesisAr, scatterGain, q);
}

// T of a slice as stored: previousT * factor rounded to the storage format, and
// 0 below kTransmittanceFloor. GLSL twin: shading.glsl StoreTransmittance.
inline float StoreTransmittance(StorageFormat storage, float previousT, float factor) {
    const float value = RoundToStorage(storage, previousT * factor);
    return value < kTransmittanceFloor ? 0.0f : value;
}

// Ground shadow G from the column sum d (SPEC 7): exp(-opticalDepthPerD d) for
// the beer form, 1 - clamp(kappa d) for the thesis form. GLSL twin: shading.glsl GroundShadow.
inline float GroundShadow(bool beer, float opticalDepthPerD, float kappa, float d) {
    return beer ? ExpNonPositive(-opticalDepthPerD * d) : 1.0f - std::clamp(kappa * d, 0.0f, 1.0f);
}

// Wang's ground shadow (Wang, Ji and Zhang, eq. 19), S = 1 - D_w max(T_S - (T_2D + 1 - C), 0),
// on our data (docs/pipeline.md "Wang's shadow form"): the shadow texture T_S
// is the opacity of the column along the sun, 1 - exp(-opticalDepthPerD d);
// the modulation texture T_2D is 0 (the automaton already varies the cloud);
// C = coverage and D_w = densityFactor are scene constants in [0, 1].
// GLSL twin: shading.glsl WangShadow.
inline float WangShadow(float opticalDepthPerD, float coverage, float densityFactor, float d) {
    const float shadowTexture = 1.0f - ExpNonPositive(-opticalDepthPerD * d);
    const float modulation = 0.0f;
    return 1.0f - densityFactor * std::max(shadowTexture - (modulation + 1.0f - coverage), 0.0f);
}

// Trilinear read-back of a shade grid at resolution f (SPEC 6): fine voxel i
// sits at coarse coordinate (i + 0.5)/f - 0.5, clamped to the cell centres;
// taps i0, i1 = min(i0 + 1, cells - 1), weight w. GLSL twin: shading.glsl UpsampleTap.
struct UpsampleTaps {
    uint32_t i0, i1;
    float w;
};
inline UpsampleTaps UpsampleTap(uint32_t i, int f, uint32_t cells) {
    const float x = std::clamp((float(i) + 0.5f) / float(f) - 0.5f, 0.0f, float(cells - 1));
    const uint32_t i0 = uint32_t(x);
    return {i0, std::min(i0 + 1, cells - 1), x - float(i0)};
}

// Bilinear blend of four taps: t00 at (0,0), t10 at (1,0), t01 at (0,1), t11 at (1,1).
// GLSL twin: shading.glsl Bilinear.
inline float Bilinear(float t00, float t10, float t01, float t11, float fu, float fv) {
    return Lerp(Lerp(t00, t10, fu), Lerp(t01, t11, fu), fv);
}

// The geometry of one shear-warp pass (SPEC 6), shared by every backend:
// principal axis w, the other two axes u, v (x, y, z order), and where output
// (u, v) reads the previous slice: taps at (u + u0, v + v0) and +1, weights fu, fv.
struct ShearWarp {
    int w = 2, u = 0, v = 1;
    float absSw = 1;       // |s_w|
    bool sunAbove = true;  // s_w > 0: slices are visited from the highest w index down
    int u0 = 0, v0 = 0;
    float fu = 0, fv = 0;
};

inline ShearWarp MakeShearWarp(const Vec3& s, SampleFilter filter) {
    ShearWarp g;
    g.w = PrincipalAxis(s);
    g.u = g.w == 0 ? 1 : 0;
    g.v = g.w == 2 ? 1 : 2;
    g.absSw = std::fabs(s[g.w]);
    g.sunAbove = s[g.w] > 0;
    // |du|, |dv| <= 1 since w is the largest component (a float quotient of |a| <= |b| is at most 1). Clamped all
    // the same, NaN to 1 (fmin returns the number), so that the taps are -1, 0 or 1 for any s: the CPU sizes its
    // scratch by them, and a NaN direction once gave int(floor(NaN)) = INT_MIN and rows for 2^31 cells.
    const float du = std::fmax(-1.0f, std::fmin(s[g.u] / g.absSw, 1.0f));
    const float dv = std::fmax(-1.0f, std::fmin(s[g.v] / g.absSw, 1.0f));
    if (filter == SampleFilter::Nearest) {
        g.u0 = int(std::floor(du + 0.5f));
        g.v0 = int(std::floor(dv + 0.5f));
    } else {
        g.u0 = int(std::floor(du));
        g.v0 = int(std::floor(dv));
        g.fu = du - std::floor(du);
        g.fv = dv - std::floor(dv);
    }
    return g;
}

// The per-slice factor for slices `cellSize` metres thick.
inline SliceAttenuation MakeSliceAttenuation(AttenuationKind kind, float sigma, float cellSize, float absSw,
                                             float thesisAr, bool scattering, float albedo, float solidAngle,
                                             const PhaseParams& phase) {
    SliceAttenuation a;
    a.kind = kind;
    // Finite even when sigma h overflows float (sigma 1e39, h 1e300: valid
    // scenes): an infinite depth would make 0 * inf = NaN where q = 0 (GPUs
    // then read exp(NaN) as 0). FLT_MAX * q stays finite for q <= 1, and
    // sigma = 0 gives 0 whatever the slice thickness.
    a.opticalDepthPerQ = sigma > 0 ? std::min(sigma * cellSize / absSw, std::numeric_limits<float>::max()) : 0.0f;
    a.thesisAr = thesisAr;
    if (scattering) a.scatterGain = albedo * PhaseValue(phase, 1.0f) * solidAngle / (4.0f * std::numbers::pi_v<float>);
    return a;
}

// Where the ground shadow reads D (SPEC 7), shared by every backend. From
// ground cell (i, j) along s to mid-height (nz/2 voxels up), D is read
// bilinearly at (i + ox, j + oy): taps at (i + baseX, j + baseY) and +1 with
// weights fx, fy. `noSun` (s_z <= 0) means G = 1 everywhere.
struct ShadowLookup {
    bool noSun = true;
    int32_t baseX = 0, baseY = 0;
    float fx = 0, fy = 0;
    float opticalDepthPerD = 0;  // sigma h / s_z, the beer form's factor
};

inline ShadowLookup MakeShadowLookup(const Vec3& s, uint32_t nx, uint32_t ny, uint32_t nz, float sigma,
                                     float voxelSize) {
    ShadowLookup l;
    if (s[2] <= 0.0f) return l;
    l.noSun = false;
    const float climb = 0.5f * float(nz) / s[2];
    // Offsets beyond the grid put every tap outside; clamping them keeps the
    // integer conversion defined and changes no result.
    const float limit = float(nx + ny) + 2.0f;
    const float cx = std::clamp(s[0] * climb, -limit, limit), cy = std::clamp(s[1] * climb, -limit, limit);
    l.baseX = int32_t(std::floor(cx));
    l.baseY = int32_t(std::floor(cy));
    l.fx = cx - std::floor(cx);
    l.fy = cy - std::floor(cy);
    // Finite, like opticalDepthPerQ: D = 0 then gives exp(-0) = 1, not NaN.
    l.opticalDepthPerD = sigma > 0 ? std::min(sigma * voxelSize / s[2], std::numeric_limits<float>::max()) : 0.0f;
    return l;
}

// ---- Splat kernel (SPEC 8) -------------------------------------------------------

// kappa = max(0, 1 - rho^2)^2 at splat coordinate (a, b) in [0, 1]^2.
inline float SplatKernel(float a, float b) {
    const float x = 2.0f * a - 1.0f, y = 2.0f * b - 1.0f;
    const float t = std::max(0.0f, 1.0f - (x * x + y * y));
    return t * t;
}

}  // namespace cb
