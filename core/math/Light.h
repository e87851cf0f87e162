// The light a sample scatters toward the eye, ONE function for every renderer
// (ray march, layers, splats) on every backend: the scene's enabled light terms
// (the sun, the ambient light, the sky light, the lightning's point light, the city glow, eye scattering) gathered at a
// sample. GLSL twin: core/math/light.glsl (InScattered, LightGpu), which the
// GPU blocks of the renderers (MarchGpu, LayersGpu, SplatFrame) nest as their
// member `light`, made by MakeLightGpu below.
//
// Every renderer's setup carries the terms once, as its member `light`
// (MarchSetup, LayersSetup, SplatParams), made by MakeLightTerms
// (core/pipeline/LightTerms.h) in each renderer's Make*Params.
//
// Adding a light term: a member of
// LightTerms (and, if it varies per sample, of LightSample) and its lines in
// InScattered, here and in light.glsl; its member of LightGpu in both languages
// and its line in MakeLightGpu / LightTermsOf; its line in MakeLightTerms and
// the scene section it reads; and the exact reference. The renderers do not change.
//
// The sun's gain is the renderer's: SunGain (below) of the sample's transmittance and the ray's SunPhases, times
// the powder where the renderer has it. The operations, in this order (bit-identical on every backend, built with
// -ffp-contract=off): per channel c = sunRadiance_c * sunGain + ambient_c,
// then with the sky light on c += skyRadiance_c * skyGain,
// then with the point light on c += pointRadiance_c * g, g = T_point / max(d^2, r0^2) P^(cos theta_point),
// then with the city glow on c += glowColor_c * GlowMap(x, y) (1 - clamp(glowFade (z invThickness), 0, 1)),
// then with eye scattering on c += sunRadiance_c * (sunT ((eyeIntensity cone) rise)).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "core/math/Shading.h"

namespace cb {

// The point light's radiance factor at distance^2 d2 (metres^2): 1 / max(d2, r0^2).
inline float PointLightFalloff(float distance2, float minDistance2) { return 1.0f / std::max(distance2, minDistance2); }

// The most blobs a city glow map has (LightGpu's rows).
inline constexpr uint32_t kMaxGlowBlobs = 4;

// The most multiple-scattering octaves (SunPhases' size).
inline constexpr uint32_t kMaxOctaves = 8;

// City glow's map g at (x, y) (voxel units): the sum of the blobs' strength exp(-d^2 k), in blob order.
inline float GlowMap(const std::array<std::array<float, 4>, kMaxGlowBlobs>& blobs, uint32_t count, float x, float y) {
    float g = 0.0f;
    for (uint32_t i = 0; i < count; ++i) {
        const float dx = x - blobs[i][0], dy = y - blobs[i][1];
        g += blobs[i][3] * ExpNonPositive(-((dx * dx + dy * dy) * blobs[i][2]));
    }
    return g;
}

// The scene's light terms as a renderer sees them (voxel units as in core/math/March.h).
struct LightTerms {
    Vec3 sunRadiance{1, 1, 1};  // colour * intensity
    Vec3 ambient{0, 0, 0};
    PhaseParams phase;            // the phase function, of the sun's and the point light's angle alike
    float voxelSize = 1;          // h (metres): a voxel-unit distance^2 d times h h is metres^2
    bool pointOn = false;         // the lightning's point light (Wang, Ji and Zhang, eq. 21)
    Vec3 pointPosition{};         // voxel units
    Vec3 pointRadiance{};         // colour * intensity (radiance * m^2)
    float pointMinDistance2 = 1;  // r0^2 in metres^2: the 1/D^2 law is capped at 1/r0^2
    // City glow (Wang, Ji and Zhang, eq. 20): glowColor g(x, y) (1 - clamp(glowFade z / nz, 0, 1)), with
    // g = sum over the blobs of strength exp(-((x - cx)^2 + (y - cy)^2) k) at the sample (voxel units).
    float invThickness = 1;  // 1 / nz: z / nz is dH / thickness (z from the grid's bottom, the cloud base)
    bool glowOn = false;
    Vec3 glowColor{};
    float glowFade = 1;          // f_c
    uint32_t glowBlobCount = 0;  // at most kMaxGlowBlobs
    std::array<std::array<float, 4>, kMaxGlowBlobs> glowBlobs{};  // (cx, cy, k = h^2 / (2 sigma^2), strength)
    // Eye scattering (Wang, Ji and Zhang, eq. 17): sunRadiance T I_e, I_e = eyeIntensity max(0, (d . sun - cos phi)
    // / (1 - cos phi)) (eyeHeightGain clamp(z / nz, 0, 1) + 1), d the ray's unit direction (eye to sample).
    bool eyeOn = false;
    Vec3 sunDirection{0, 0, 1};   // unit, toward the sun, at the step
    float eyeIntensity = 1;       // I_e0
    float eyeCosCone = 0;         // cos phi
    float eyeInvOneMinusCos = 1;  // 1 / (1 - cos phi)
    float eyeHeightGain = 0;      // f_e
    // The sky light (Wang, Ji and Zhang, section 3.3): skyRadiance T_sky P^(skyDirection . d), T_sky its own
    // attenuation (stage shade_sky).
    bool skyOn = false;
    Vec3 skyRadiance{};          // colour * intensity
    Vec3 skyDirection{0, 0, 1};  // unit, toward the sky light
    // Multiple scattering as octaves of single scattering (Wrenninge, Kulla and Lundqvist's approximation, as
    // Frostbite, Unreal Engine and Nubis use it): octave i scales the extinction toward the sun by a^i (T^(a^i)),
    // its contribution by b^i and the phase's eccentricity by c^i (SunPhases, SunGain). 1 octave: single scattering.
    uint32_t octaves = 1;                                                         // n, in [1, kMaxOctaves]
    float octaveAttenuation = 1, octaveContribution = 1, octaveEccentricity = 1;  // a, b, c
};

// The sun's phase values on one ray, P^_i(s . d) for octave i < octaves: the scene's phase function with its
// eccentricity (g, or the dual lobe's gForward and gBackward) times c^i; Mie's table and none unchanged (a scene
// with Mie and c < 1 is refused). value[0] is PhaseValue(phase, cos) itself.
struct SunPhases {
    std::array<float, kMaxOctaves> value{};
};
inline SunPhases MakeSunPhases(const LightTerms& L, float cosTheta) {
    SunPhases p;
    p.value[0] = PhaseValue(L.phase, cosTheta);
    PhaseParams scaled = L.phase;
    for (uint32_t i = 1; i < L.octaves; ++i) {
        scaled.g *= L.octaveEccentricity;
        scaled.gForward *= L.octaveEccentricity;
        scaled.gBackward *= L.octaveEccentricity;
        p.value[i] = PhaseValue(scaled, cosTheta);
    }
    return p;
}

// The sun's gain at a sample whose transmittance toward the sun is T: T P^_0, plus with octaves the sum over
// i = 1 .. n - 1 of b^i P^_i T^(a^i) (b^i and a^i as running products, in that order; T^x as std::pow, GLSL's pow).
inline float SunGain(const LightTerms& L, const SunPhases& p, float T) {
    float gain = T * p.value[0];
    if (L.octaves > 1) [[unlikely]] {
        float contribution = 1.0f, attenuation = 1.0f;
        for (uint32_t i = 1; i < L.octaves; ++i) {
            contribution *= L.octaveContribution;
            attenuation *= L.octaveAttenuation;
            gain += (contribution * p.value[i]) * std::pow(T, attenuation);
        }
    }
    return gain;
}

// What varies per sample: the sun's gain (its transmittance times the phase,
// times the powder where the renderer has it), the sun's transmittance alone, the
// point light's transmittance, the sample's position (voxel units), the ray's unit direction and the sky light's
// gain (T_sky P^(skyDirection . d); read only with the sky light on).
struct LightSample {
    float sunGain = 0;
    float sunT = 0;
    float pointT = 1;
    Vec3 position{};
    Vec3 dir{};
    float skyGain = 0;
};

// The sky light's P^(skyDirection . d) on a ray of unit direction d; 0 with the sky light off.
inline float SkyPhase(const LightTerms& L, const Vec3& d) {
    if (!L.skyOn) return 0.0f;
    return PhaseValue(L.phase, L.skyDirection[0] * d[0] + L.skyDirection[1] * d[1] + L.skyDirection[2] * d[2]);
}

// The city glow, then eye scattering, each where it is on (InScattered's last terms). Out of line: a renderer's
// loop without them keeps InScattered small.
[[gnu::noinline]] inline void AddWangTerms(const LightTerms& L, const LightSample& s, Vec3& c) {
    if (L.glowOn) {
        const float height = std::clamp(L.glowFade * (s.position[2] * L.invThickness), 0.0f, 1.0f);
        const float glow = GlowMap(L.glowBlobs, L.glowBlobCount, s.position[0], s.position[1]) * (1.0f - height);
        for (int i = 0; i < 3; ++i) c[i] += L.glowColor[i] * glow;
    }
    if (L.eyeOn) {
        const float cosE = s.dir[0] * L.sunDirection[0] + s.dir[1] * L.sunDirection[1] + s.dir[2] * L.sunDirection[2];
        const float cone = std::max(0.0f, (cosE - L.eyeCosCone) * L.eyeInvOneMinusCos);
        const float rise = L.eyeHeightGain * std::clamp(s.position[2] * L.invThickness, 0.0f, 1.0f) + 1.0f;
        const float eye = s.sunT * ((L.eyeIntensity * cone) * rise);
        for (int i = 0; i < 3; ++i) c[i] += L.sunRadiance[i] * eye;
    }
}

// The light scattered toward the eye at the sample, per channel.
inline Vec3 InScattered(const LightTerms& L, const LightSample& s) {
    Vec3 c{L.sunRadiance[0] * s.sunGain + L.ambient[0], L.sunRadiance[1] * s.sunGain + L.ambient[1],
           L.sunRadiance[2] * s.sunGain + L.ambient[2]};
    if (L.skyOn)
        for (int i = 0; i < 3; ++i) c[i] += L.skyRadiance[i] * s.skyGain;
    if (L.pointOn) {
        const Vec3 toLight{L.pointPosition[0] - s.position[0], L.pointPosition[1] - s.position[1],
                           L.pointPosition[2] - s.position[2]};
        const float d2v = toLight[0] * toLight[0] + toLight[1] * toLight[1] + toLight[2] * toLight[2];
        const float d2 = d2v * L.voxelSize * L.voxelSize;
        // cos theta = u . d with u the unit vector from the sample toward the light: 1 when the
        // light shines straight at the eye through the sample, as s . d for the sun.
        const float cosL =
            d2v > 0.0f ? (toLight[0] * s.dir[0] + toLight[1] * s.dir[1] + toLight[2] * s.dir[2]) / std::sqrt(d2v)
                       : 1.0f;
        const float g = s.pointT * PointLightFalloff(d2, L.pointMinDistance2) * PhaseValue(L.phase, cosL);
        for (int i = 0; i < 3; ++i) c[i] += L.pointRadiance[i] * g;
    }
    if (L.glowOn || L.eyeOn) [[unlikely]]
        AddWangTerms(L, s, c);
    return c;
}

// LightTerms as the GPU blocks nest it: core/math/light.glsl's `LightGpu`,
// member for member (std140 and std430 alike: a scalar after a vec3 takes its fourth lane).
struct alignas(16) LightGpu {
    std::array<float, 3> sunRadiance;
    uint32_t phaseKind;  // PhaseKind
    std::array<float, 3> ambient;
    float phaseG;
    std::array<float, 3> pointPosition;
    float pointMinDistance2;
    std::array<float, 3> pointRadiance;
    uint32_t pointOn;  // 1: the point light shines
    float voxelSize;
    float mieIndexPerRadian;  // kMieCloudTable's, read with phase Mie
    uint32_t mieCount;        // likewise
    uint32_t unused;
    float phaseGForward;  // the dual lobe's (PhaseParams), read with phase dual-lobe
    float phaseGBackward;
    float phaseBlend;
    uint32_t phaseUnused;
    std::array<float, 3> glowColor;
    uint32_t glowOn;  // 1: the city glow shines
    float glowFade;
    float invThickness;
    uint32_t glowBlobCount;
    uint32_t glowUnused;
    std::array<std::array<float, 4>, kMaxGlowBlobs> glowBlobs;  // (cx, cy, k, strength)
    std::array<float, 3> sunDirection;
    uint32_t eyeOn;  // 1: eye scattering
    float eyeIntensity;
    float eyeCosCone;
    float eyeInvOneMinusCos;
    float eyeHeightGain;
    std::array<float, 3> skyRadiance;
    uint32_t skyOn;  // 1: the sky light shines
    std::array<float, 3> skyDirection;
    uint32_t skyUnused;
    uint32_t octaves;
    float octaveAttenuation;
    float octaveContribution;
    float octaveEccentricity;
};
static_assert(sizeof(LightGpu) == (13 + kMaxGlowBlobs) * 16, "LightGpu is 13 16-byte rows and one per glow blob");

inline LightGpu MakeLightGpu(const LightTerms& L) {
    LightGpu g{};
    g.sunRadiance = L.sunRadiance;
    g.phaseKind = uint32_t(L.phase.kind);
    g.ambient = L.ambient;
    g.phaseG = L.phase.g;
    g.pointPosition = L.pointPosition;
    g.pointMinDistance2 = L.pointMinDistance2;
    g.pointRadiance = L.pointRadiance;
    g.pointOn = L.pointOn ? 1u : 0u;
    g.voxelSize = L.voxelSize;
    g.mieIndexPerRadian = kMieCloudTable.indexPerRadian;
    g.mieCount = kMieCloudTable.count;
    g.phaseGForward = L.phase.gForward;
    g.phaseGBackward = L.phase.gBackward;
    g.phaseBlend = L.phase.blend;
    g.glowColor = L.glowColor;
    g.glowOn = L.glowOn ? 1u : 0u;
    g.glowFade = L.glowFade;
    g.invThickness = L.invThickness;
    g.glowBlobCount = L.glowBlobCount;
    g.glowBlobs = L.glowBlobs;
    g.sunDirection = L.sunDirection;
    g.eyeOn = L.eyeOn ? 1u : 0u;
    g.eyeIntensity = L.eyeIntensity;
    g.eyeCosCone = L.eyeCosCone;
    g.eyeInvOneMinusCos = L.eyeInvOneMinusCos;
    g.eyeHeightGain = L.eyeHeightGain;
    g.skyRadiance = L.skyRadiance;
    g.skyOn = L.skyOn ? 1u : 0u;
    g.skyDirection = L.skyDirection;
    g.octaves = L.octaves;
    g.octaveAttenuation = L.octaveAttenuation;
    g.octaveContribution = L.octaveContribution;
    g.octaveEccentricity = L.octaveEccentricity;
    return g;
}

// The terms back from a block (the splats' C++ reads its GPU frame).
inline LightTerms LightTermsOf(const LightGpu& g) {
    LightTerms L;
    L.sunRadiance = g.sunRadiance;
    L.ambient = g.ambient;
    L.phase = PhaseParams{PhaseKind(uint8_t(g.phaseKind)), g.phaseG, g.phaseGForward, g.phaseGBackward, g.phaseBlend};
    L.voxelSize = g.voxelSize;
    L.pointOn = g.pointOn != 0u;
    L.pointPosition = g.pointPosition;
    L.pointRadiance = g.pointRadiance;
    L.pointMinDistance2 = g.pointMinDistance2;
    L.glowOn = g.glowOn != 0u;
    L.glowColor = g.glowColor;
    L.glowFade = g.glowFade;
    L.invThickness = g.invThickness;
    L.glowBlobCount = g.glowBlobCount;
    L.glowBlobs = g.glowBlobs;
    L.eyeOn = g.eyeOn != 0u;
    L.sunDirection = g.sunDirection;
    L.eyeIntensity = g.eyeIntensity;
    L.eyeCosCone = g.eyeCosCone;
    L.eyeInvOneMinusCos = g.eyeInvOneMinusCos;
    L.eyeHeightGain = g.eyeHeightGain;
    L.skyOn = g.skyOn != 0u;
    L.skyRadiance = g.skyRadiance;
    L.skyDirection = g.skyDirection;
    L.octaves = g.octaves;
    L.octaveAttenuation = g.octaveAttenuation;
    L.octaveContribution = g.octaveContribution;
    L.octaveEccentricity = g.octaveEccentricity;
    return L;
}

}  // namespace cb
