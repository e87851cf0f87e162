// GLSL twin of core/math/Light.h: the light a sample scatters toward the eye,
// one function (InScattered) for every renderer, and the block LightGpu that
// MarchGpu, LayersGpu and SplatFrame nest as their member `light`. The same
// operations in the same order as the C++, `precise` where the CPU (built
// with -ffp-contract=off) rounds each product. Include after shading.glsl
// (ExpNonPositive) and phase_table.glsl (PhaseOf).
#ifndef CLOUDBENCH_LIGHT_GLSL
#define CLOUDBENCH_LIGHT_GLSL

// core/math/Light.h LightGpu, member for member.
struct LightGpu {
    vec3 sunRadiance;
    uint phaseKind;
    vec3 ambient;
    float phaseG;
    vec3 pointPosition;
    float pointMinDistance2;
    vec3 pointRadiance;
    uint pointOn;
    float voxelSize;
    float mieIndexPerRadian;
    uint mieCount;
    uint unused;
    float phaseGForward;
    float phaseGBackward;
    float phaseBlend;
    uint phaseUnused;
    vec3 glowColor;
    uint glowOn;
    float glowFade;
    float invThickness;
    uint glowBlobCount;
    uint glowUnused;
    vec4 glowBlobs[4];  // kMaxGlowBlobs: (cx, cy, k, strength)
    vec3 sunDirection;
    uint eyeOn;
    float eyeIntensity;
    float eyeCosCone;
    float eyeInvOneMinusCos;
    float eyeHeightGain;
    vec3 skyRadiance;
    uint skyOn;
    vec3 skyDirection;
    uint skyUnused;
    uint octaves;
    float octaveAttenuation;
    float octaveContribution;
    float octaveEccentricity;
};

// core/math/Light.h kMaxOctaves and SunPhases.
const uint kMaxOctaves = 8u;
struct SunPhases {
    float value[kMaxOctaves];
};

// core/math/Light.h LightSample.
struct LightSample {
    float sunGain;
    float sunT;
    float pointT;
    vec3 position;
    vec3 dir;
    float skyGain;
};

// P^(cos theta) of the scene's phase function (core/math/Shading.h PhaseValue).
float LightPhase(LightGpu L, float cosTheta) {
    return PhaseOf(L.phaseKind, L.phaseG, vec3(L.phaseGForward, L.phaseGBackward, L.phaseBlend), L.mieIndexPerRadian,
                   L.mieCount, cosTheta);
}

// core/math/Light.h MakeSunPhases.
SunPhases MakeSunPhases(LightGpu L, float cosTheta) {
    SunPhases p;
    for (uint i = 0u; i < kMaxOctaves; ++i) p.value[i] = 0.0;
    p.value[0] = LightPhase(L, cosTheta);
    precise float g = L.phaseG, gForward = L.phaseGForward, gBackward = L.phaseGBackward;
    for (uint i = 1u; i < L.octaves; ++i) {
        g *= L.octaveEccentricity;
        gForward *= L.octaveEccentricity;
        gBackward *= L.octaveEccentricity;
        p.value[i] = PhaseOf(L.phaseKind, g, vec3(gForward, gBackward, L.phaseBlend), L.mieIndexPerRadian, L.mieCount,
                             cosTheta);
    }
    return p;
}

// core/math/Light.h SunGain.
float SunGain(LightGpu L, SunPhases p, float T) {
    precise float gain = T * p.value[0];
    precise float contribution = 1.0, attenuation = 1.0;
    for (uint i = 1u; i < L.octaves; ++i) {
        contribution *= L.octaveContribution;
        attenuation *= L.octaveAttenuation;
        gain += (contribution * p.value[i]) * pow(T, attenuation);
    }
    return gain;
}

// core/math/Light.h SkyPhase.
float SkyPhase(LightGpu L, vec3 d) {
    if (L.skyOn == 0u) return 0.0;
    precise float cosSky = L.skyDirection.x * d.x + L.skyDirection.y * d.y + L.skyDirection.z * d.z;
    return LightPhase(L, cosSky);
}

// 1 / max(d2, r0^2) (core/math/Light.h PointLightFalloff).
float PointLightFalloff(float distance2, float minDistance2) { return 1.0 / max(distance2, minDistance2); }

// core/math/Light.h GlowMap.
float GlowMap(LightGpu L, float x, float y) {
    precise float g = 0.0;
    for (uint i = 0u; i < L.glowBlobCount; ++i) {
        precise float dx = x - L.glowBlobs[i].x;
        precise float dy = y - L.glowBlobs[i].y;
        precise float d2k = (dx * dx + dy * dy) * L.glowBlobs[i].z;
        g += L.glowBlobs[i].w * ExpNonPositive(-d2k);
    }
    return g;
}

// core/math/Light.h InScattered.
vec3 InScattered(LightGpu L, LightSample s) {
    precise float c0 = L.sunRadiance.x * s.sunGain + L.ambient.x;
    precise float c1 = L.sunRadiance.y * s.sunGain + L.ambient.y;
    precise float c2 = L.sunRadiance.z * s.sunGain + L.ambient.z;
    if (L.skyOn != 0u) {
        c0 += L.skyRadiance.x * s.skyGain;
        c1 += L.skyRadiance.y * s.skyGain;
        c2 += L.skyRadiance.z * s.skyGain;
    }
    if (L.pointOn != 0u) {
        precise vec3 toLight = vec3(L.pointPosition.x - s.position.x, L.pointPosition.y - s.position.y,
                                    L.pointPosition.z - s.position.z);
        precise float d2v = toLight.x * toLight.x + toLight.y * toLight.y + toLight.z * toLight.z;
        precise float d2 = d2v * L.voxelSize * L.voxelSize;
        precise float dotDir = toLight.x * s.dir.x + toLight.y * s.dir.y + toLight.z * s.dir.z;
        precise float cosL = d2v > 0.0 ? dotDir / sqrt(d2v) : 1.0;
        precise float g = s.pointT * PointLightFalloff(d2, L.pointMinDistance2) * LightPhase(L, cosL);
        c0 += L.pointRadiance.x * g;
        c1 += L.pointRadiance.y * g;
        c2 += L.pointRadiance.z * g;
    }
    if (L.glowOn != 0u) {
        precise float height = clamp(L.glowFade * (s.position.z * L.invThickness), 0.0, 1.0);
        precise float glow = GlowMap(L, s.position.x, s.position.y) * (1.0 - height);
        c0 += L.glowColor.x * glow;
        c1 += L.glowColor.y * glow;
        c2 += L.glowColor.z * glow;
    }
    if (L.eyeOn != 0u) {
        precise float cosE = s.dir.x * L.sunDirection.x + s.dir.y * L.sunDirection.y + s.dir.z * L.sunDirection.z;
        precise float cone = max(0.0, (cosE - L.eyeCosCone) * L.eyeInvOneMinusCos);
        precise float rise = L.eyeHeightGain * clamp(s.position.z * L.invThickness, 0.0, 1.0) + 1.0;
        precise float eye = s.sunT * ((L.eyeIntensity * cone) * rise);
        c0 += L.sunRadiance.x * eye;
        c1 += L.sunRadiance.y * eye;
        c2 += L.sunRadiance.z * eye;
    }
    return vec3(c0, c1, c2);
}

#endif
