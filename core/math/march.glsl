// GLSL twin of core/math/March.h (SPEC 10): the ray of a pixel, the box clip, the
// step schedule, the padded trilinear sampler, the light march, the point
// light, the Mie table lookup and the per-ray kernel MarchRay. Must stay in
// step with the C++; the same operations in the same order, `precise` where
// the CPU (built with -ffp-contract=off) rounds each product.
//
// Include after random.glsl, shading.glsl, phase_table.glsl and light.glsl. The including shader declares
// the block that holds a MarchGpu (core/pipeline/MarchGpu.h) and DEFINES:
//   vec2  MarchFetchQT(uint paddedIndex);  // (q_alpha, T) of the padded volume:
//         (nx+2) x (ny+2) x (nz+2), voxel (i, j, k) at padded (i+1, j+1, k+1),
//         index i + px (j + py k); the border reads (0, 1)
//   bool  MarchBrickEmpty(uint brick);     // bx + Bx (by + By bz); skipping only
//   float PhaseTableValue(uint i);         // phase_table.glsl's; Mie only
#ifndef CLOUDBENCH_MARCH_GLSL
#define CLOUDBENCH_MARCH_GLSL

// core/pipeline/MarchGpu.h, member for member.
struct MarchGpu {
    vec3 eye;  // voxel units
    float focalPx;
    vec3 forward;
    float nearPlane;  // metres
    vec3 right;
    float farPlane;  // metres
    vec3 up;
    float voxelSize;  // h, metres
    vec3 size;        // the box
    float sigmaH;
    float baseStep;
    float kappa;
    float adaptiveStart;
    float epsilon;
    vec3 sun;  // toward the sun
    float powderC;
    vec3 background;
    uint flags;  // kMarch* bits
    uint width;
    uint height;
    uint seed;
    uint frame;
    uint lightSteps;
    uint brick;
    uint strideY;  // px
    uint strideZ;  // px * py
    uvec3 bricks;  // bricks along x, y, z
    uint unused;
    vec3 invSize;  // 1 / size: the tiling's wrap
    uint unused2;
    LightGpu light;  // light.glsl
};

const uint kMarchAdaptive = 1u;
const uint kMarchJitter = 2u;
const uint kMarchPowder = 4u;
const uint kMarchSkipping = 16u;
const uint kMarchLightMarch = 32u;
const uint kMarchGround = 64u;  // the background is the ground (core/math/ground.glsl), per pixel
const uint kMarchTiling = 128u;  // the volume repeats in x and y
const uint kMarchStreamOther = 3u;
const float kMarchFloatMax = 3.402823466e+38;

vec2 MarchFetchQT(uint paddedIndex);
// The sky light's T_sky in the same padded layout (border 1, or wrapped with tiling); read only with the sky light on.
float MarchFetchSkyT(uint paddedIndex);
bool MarchBrickEmpty(uint brick);

// ---- Rays ----

struct MarchRayGeometry {
    vec3 origin, dir;
    float tMin, tMax;
};

// The next float above x (std::nextafter(x, FLT_MAX)) for finite x.
float MarchNextUp(float x) {
    if (x == 0.0) return uintBitsToFloat(1u);
    const uint bits = floatBitsToUint(x);
    return uintBitsToFloat(x > 0.0 ? bits + 1u : bits - 1u);
}

vec3 MarchAlong(vec3 o, vec3 d, float t) {
    precise vec3 p = vec3(o.x + d.x * t, o.y + d.y * t, o.z + d.z * t);
    return p;
}

float MarchDot(vec3 a, vec3 b) {
    precise float r = a.x * b.x + a.y * b.y + a.z * b.z;
    return r;
}

// Clip of o + t d to the slab [0, size[a]] of axis a (core/math/March.h ClipRayToSlab).
void ClipRayToSlab(vec3 o, vec3 d, vec3 size, int a, inout float tMin, inout float tMax) {
    if (abs(d[a]) < 1e-20) {
        if (o[a] < 0.0 || o[a] > size[a]) {
            tMax = 0.0;
            tMin = 0.0;
        }
        return;
    }
    precise float inv = 1.0 / d[a];
    precise float t0 = (0.0 - o[a]) * inv;
    precise float t1 = (size[a] - o[a]) * inv;
    if (t0 > t1) {
        const float swap = t0;
        t0 = t1;
        t1 = swap;
    }
    tMin = max(tMin, t0);
    tMax = min(tMax, t1);
}

// Slab clip of o + t d to the box [0, size] (core/math/March.h ClipRayToBox).
void ClipRayToBox(vec3 o, vec3 d, vec3 size, inout float tMin, inout float tMax) {
    for (int a = 0; a < 3; ++a) ClipRayToSlab(o, d, size, a, tMin, tMax);
}

// The box, or with tiling the slab 0 <= z <= size.z (core/math/March.h ClipRayToVolume).
void ClipRayToVolume(vec3 o, vec3 d, vec3 size, bool tiling, inout float tMin, inout float tMax) {
    for (int a = tiling ? 2 : 0; a < 3; ++a) ClipRayToSlab(o, d, size, a, tMin, tMax);
}

// x reduced into [0, n] (core/math/March.h TileWrap).
float TileWrap(float x, float n, float invN) {
    precise float w = x - n * floor(x * invN);
    return w;
}

// The unit direction of the ray through the centre of pixel (x, y), row 0 at
// the top, and (cosForward) the cosine of its angle to the view axis
// (core/math/March.h PixelRayDirection).
vec3 PixelRayDirection(vec3 forward, vec3 right, vec3 up, float focal, uvec2 image, uint x, uint y,
                       out float cosForward) {
    precise float u = (float(x) + 0.5 - 0.5 * float(image.x)) / focal;
    precise float v = (0.5 * float(image.y) - (float(y) + 0.5)) / focal;
    precise vec3 d;
    for (int i = 0; i < 3; ++i) d[i] = forward[i] + u * right[i] + v * up[i];
    precise float inv = 1.0 / sqrt(MarchDot(d, d));
    cosForward = inv;
    precise vec3 unit = vec3(d.x * inv, d.y * inv, d.z * inv);
    return unit;
}

// The camera ray of pixel (x, y), row 0 at the top (core/math/March.h MakePixelRay).
MarchRayGeometry MakePixelRay(MarchGpu m, uint x, uint y) {
    float inv;
    MarchRayGeometry r;
    r.origin = m.eye;
    r.dir = PixelRayDirection(m.forward, m.right, m.up, m.focalPx, uvec2(m.width, m.height), x, y, inv);
    precise float perDepth = 1.0 / (m.voxelSize * inv);
    r.tMin = m.nearPlane * perDepth;
    r.tMax = m.farPlane * perDepth;
    ClipRayToVolume(r.origin, r.dir, m.size, (m.flags & kMarchTiling) != 0u, r.tMin, r.tMax);
    return r;
}

// ---- Sampling: the padded (q, T) volume (impl_cpu/RenderMarchCpu.cpp MarchPaddedVolume) ----

struct MarchTaps {
    uint base;
    vec3 w;
};

// The taps of a padded volume over the box [0, size] with strides px, pxy
// (render_march's and render_layers': MarchFetchQT reads it).
MarchTaps PaddedTapsAt(vec3 size, uint px, uint pxy, vec3 p) {
    precise float cx = clamp(p.x, 0.0, size.x) + 0.5;
    precise float cy = clamp(p.y, 0.0, size.y) + 0.5;
    precise float cz = clamp(p.z, 0.0, size.z) + 0.5;
    const uint i = uint(cx), j = uint(cy), k = uint(cz);
    MarchTaps t;
    t.base = i + px * j + pxy * k;
    precise vec3 w = vec3(cx - float(i), cy - float(j), cz - float(k));
    t.w = w;
    return t;
}

// p itself, or with tiling p wrapped into the first period (core/math/March.h MarchWrapped).
vec3 MarchWrapped(MarchGpu m, vec3 p) {
    if ((m.flags & kMarchTiling) == 0u) return p;
    return vec3(TileWrap(p.x, m.size.x, m.invSize.x), TileWrap(p.y, m.size.y, m.invSize.y), p.z);
}

MarchTaps MarchTapsAt(MarchGpu m, vec3 p) { return PaddedTapsAt(m.size, m.strideY, m.strideZ, MarchWrapped(m, p)); }

// Lerp per component, unfused (core/math/Shading.h Lerp).
vec2 MarchLerp2(vec2 a, vec2 b, float t) { return vec2(Lerp(a.x, b.x, t), Lerp(a.y, b.y, t)); }

// (q_alpha, T) trilinear at the taps of a padded volume with strides px, pxy.
vec2 PaddedBlend(uint px, uint pxy, MarchTaps t) {
    const uint a = t.base, b = t.base + pxy;
    const vec2 c00 = MarchLerp2(MarchFetchQT(a), MarchFetchQT(a + 1u), t.w.x);
    const vec2 c10 = MarchLerp2(MarchFetchQT(a + px), MarchFetchQT(a + px + 1u), t.w.x);
    const vec2 c01 = MarchLerp2(MarchFetchQT(b), MarchFetchQT(b + 1u), t.w.x);
    const vec2 c11 = MarchLerp2(MarchFetchQT(b + px), MarchFetchQT(b + px + 1u), t.w.x);
    return MarchLerp2(MarchLerp2(c00, c10, t.w.y), MarchLerp2(c01, c11, t.w.y), t.w.z);
}

vec2 MarchBlend(MarchGpu m, MarchTaps t) { return PaddedBlend(m.strideY, m.strideZ, t); }

// T_sky trilinear at the taps (the same order of operations as PaddedBlend's).
float PaddedBlendSky(uint px, uint pxy, MarchTaps t) {
    const uint a = t.base, b = t.base + pxy;
    const float c00 = Lerp(MarchFetchSkyT(a), MarchFetchSkyT(a + 1u), t.w.x);
    const float c10 = Lerp(MarchFetchSkyT(a + px), MarchFetchSkyT(a + px + 1u), t.w.x);
    const float c01 = Lerp(MarchFetchSkyT(b), MarchFetchSkyT(b + 1u), t.w.x);
    const float c11 = Lerp(MarchFetchSkyT(b + px), MarchFetchSkyT(b + px + 1u), t.w.x);
    return Lerp(Lerp(c00, c10, t.w.y), Lerp(c01, c11, t.w.y), t.w.z);
}

float MarchSampleQ(MarchGpu m, vec3 p) { return MarchBlend(m, MarchTapsAt(m, p)).x; }

// ---- Kernel formulas (core/math/March.h) ----

float SegmentTransmittance(float sigmaH, float q, float len) {
    precise float x = -(sigmaH * q) * len;
    return ExpNonPositive(x);
}

float MarchStepAt(MarchGpu m, float t) {
    precise float adaptive = m.baseStep + m.kappa * max(0.0, t - m.adaptiveStart);
    return (m.flags & kMarchAdaptive) != 0u ? adaptive : m.baseStep;
}

// MarchAdaptiveLanding (March.h): after a skip to tExit, the segment starts from t on by the recurrence to the first
// whose sample lies at or past tExit (or to tMax).
float MarchAdaptiveLanding(MarchGpu m, float t, float tMax, float xi, float tExit) {
    while (t < tMax) {
        precise float tAfter = t + MarchStepAt(m, t);
        if (!(tAfter > t)) tAfter = MarchNextUp(t);
        precise float sampleT = t + xi * (min(tAfter, tMax) - t);
        if (sampleT >= tExit) break;
        t = tAfter;
    }
    return t;
}

float MarchJitter(uint seed, uint frame, uint pixel) {
    return float(Rand24FromKey(StreamKey(seed, frame, kMarchStreamOther), pixel)) * (1.0 / 16777216.0);
}

float PowderTerm(float c, float lightT) { return 1.0 - pow(max(lightT, 0.0), c); }

// 1/d per component; FLT_MAX where d is (nearly) zero.
vec3 InverseDirection(vec3 d) {
    vec3 inv;
    for (int a = 0; a < 3; ++a) inv[a] = abs(d[a]) < 1e-20 ? kMarchFloatMax : 1.0 / d[a];
    return inv;
}

float RayExitFromBox(vec3 o, vec3 invD, vec3 lo, vec3 hi, float t) {
    float exit = kMarchFloatMax;
    for (int a = 0; a < 3; ++a) {
        precise float e = ((invD[a] >= 0.0 ? hi[a] : lo[a]) - o[a]) * invD[a];
        exit = min(exit, e);
    }
    return max(exit, t);
}

// T along the segment from p toward unit u over `len`: n midpoint samples.
float MarchTransmittance(MarchGpu m, vec3 p, vec3 u, float len, uint n) {
    if (!(len > 0.0) || n == 0u) return 1.0;
    precise float dl = len / float(n);
    precise float depth = 0.0;
    for (uint j = 0u; j < n; ++j) {
        precise float t = (float(j) + 0.5) * dl;
        depth += MarchSampleQ(m, MarchAlong(p, u, t));
    }
    precise float x = -(m.sigmaH * depth) * dl;
    return ExpNonPositive(x);
}

float SunLightMarch(MarchGpu m, vec3 p) {
    float t0 = 0.0, t1 = kMarchFloatMax;
    ClipRayToVolume(p, m.sun, m.size, (m.flags & kMarchTiling) != 0u, t0, t1);
    return t1 > t0 ? MarchTransmittance(m, p, m.sun, t1, m.lightSteps) : 1.0;
}

float PointLightMarch(MarchGpu m, vec3 p) {
    precise vec3 toLight =
        vec3(m.light.pointPosition.x - p.x, m.light.pointPosition.y - p.y, m.light.pointPosition.z - p.z);
    const float dist = sqrt(MarchDot(toLight, toLight));
    if (!(dist > 0.0)) return 1.0;
    precise float inv = 1.0 / dist;
    const vec3 u = vec3(toLight.x * inv, toLight.y * inv, toLight.z * inv);
    float t0 = 0.0, t1 = dist;
    ClipRayToVolume(p, u, m.size, (m.flags & kMarchTiling) != 0u, t0, t1);
    return t1 > t0 ? MarchTransmittance(m, p, u, t1, m.lightSteps) : 1.0;
}

// The brick that holds p, and with tiling the shift to p's period (core/math/March.h MarchBrickAt).
struct MarchBrickCell {
    bool inside;
    uint index;
    ivec3 b;
    float sx, sy;
};

MarchBrickCell MarchBrickAt(MarchGpu m, float invB, vec3 p) {
    MarchBrickCell c;
    precise float sx = 0.0, sy = 0.0;
    if ((m.flags & kMarchTiling) != 0u) {
        sx = m.size.x * floor(p.x * m.invSize.x);
        sy = m.size.y * floor(p.y * m.invSize.y);
    }
    c.sx = sx;
    c.sy = sy;
    precise vec3 s = vec3((p.x - sx) * invB, (p.y - sy) * invB, p.z * invB);
    c.b = ivec3(floor(s));
    c.inside = c.b.x >= 0 && c.b.y >= 0 && c.b.z >= 0 && uint(c.b.x) < m.bricks.x && uint(c.b.y) < m.bricks.y &&
               uint(c.b.z) < m.bricks.z;
    c.index = c.inside ? uint(c.b.x) + m.bricks.x * (uint(c.b.y) + m.bricks.y * uint(c.b.z)) : 0u;
    return c;
}

// The brick's box, cut at the period's end with tiling (core/math/March.h MarchBrickBox).
void MarchBrickBox(MarchGpu m, MarchBrickCell c, float B, out vec3 lo, out vec3 hi) {
    precise vec3 l = vec3(float(c.b.x) * B + c.sx, float(c.b.y) * B + c.sy, float(c.b.z) * B);
    precise vec3 h = vec3(l.x + B, l.y + B, l.z + B);
    if ((m.flags & kMarchTiling) != 0u) {
        precise float ex = min(float(c.b.x) * B + B, m.size.x) + c.sx;
        precise float ey = min(float(c.b.y) * B + B, m.size.y) + c.sy;
        h.x = ex;
        h.y = ey;
    }
    lo = l;
    hi = h;
}

// ---- The per-ray kernel (core/math/March.h MarchRay) ----

struct MarchRayResult {
    vec3 color;
    vec3 light;  // L alone (core/math/March.h MarchRayResult::light)
    float transmittance;
    uint samples, lightCalls, bricksSkipped;
};

MarchRayResult MarchRay(MarchGpu m, MarchRayGeometry ray, float xi) {
    MarchRayResult r;
    r.samples = 0u;
    r.lightCalls = 0u;
    r.bricksSkipped = 0u;
    precise float L0 = 0.0, L1 = 0.0, L2 = 0.0, T = 1.0;
    const bool adaptive = (m.flags & kMarchAdaptive) != 0u;
    const bool skipping = (m.flags & kMarchSkipping) != 0u;
    const bool lightMarch = (m.flags & kMarchLightMarch) != 0u;
    const bool pointOn = m.light.pointOn != 0u;
    const bool powder = (m.flags & kMarchPowder) != 0u;
    if (ray.tMin < ray.tMax) {
        const SunPhases sunPhases = MakeSunPhases(m.light, MarchDot(m.sun, ray.dir));
        const float skyPhase = SkyPhase(m.light, ray.dir);
        const float B = skipping ? float(m.brick) : 1.0;
        precise float invB = 1.0 / B;
        const vec3 invDir = InverseDirection(ray.dir);
        float tn = ray.tMin;
        uint n = 0u;
        while (tn < ray.tMax) {
            const float delta = MarchStepAt(m, tn);
            precise float tFixed = ray.tMin + float(n + 1u) * delta;
            precise float tAdaptive = tn + delta;
            float tNext = adaptive ? tAdaptive : tFixed;
            if (!(tNext > tn)) tNext = MarchNextUp(tn);
            precise float len = min(tNext, ray.tMax) - tn;
            precise float ts = tn + xi * len;
            const vec3 p = MarchAlong(ray.origin, ray.dir, ts);
            if (skipping) {
                const MarchBrickCell cell = MarchBrickAt(m, invB, p);
                if (cell.inside && MarchBrickEmpty(cell.index)) {
                    vec3 lo, hi;
                    MarchBrickBox(m, cell, B, lo, hi);
                    float tExit = RayExitFromBox(ray.origin, invDir, lo, hi, ts);
                    ++r.bricksSkipped;
                    while (tExit < ray.tMax) {
                        precise float tProbe = tExit + 0.01;
                        const MarchBrickCell next = MarchBrickAt(m, invB, MarchAlong(ray.origin, ray.dir, tProbe));
                        if (!next.inside || !MarchBrickEmpty(next.index)) break;
                        MarchBrickBox(m, next, B, lo, hi);
                        tExit = RayExitFromBox(ray.origin, invDir, lo, hi, tProbe);
                        ++r.bricksSkipped;
                    }
                    if (adaptive) {
                        tn = MarchAdaptiveLanding(m, tNext, ray.tMax, xi, tExit);
                    } else {
                        precise float mm = floor((tExit - ray.tMin) / delta - xi);
                        n = max(n + 1u, uint(clamp(mm, 0.0, 16777216.0)));
                        precise float tAt = ray.tMin + float(n) * delta;
                        tn = tAt;
                    }
                    continue;
                }
            }
            ++r.samples;
            const MarchTaps taps = MarchTapsAt(m, p);
            const vec2 qt = MarchBlend(m, taps);
            const float qa = qt.x;
            if (qa > 0.0) {
                ++r.lightCalls;
                const float tau = SegmentTransmittance(m.sigmaH, qa, len);
                const float lightSun = lightMarch ? SunLightMarch(m, p) : qt.y;
                precise float sunGain = SunGain(m.light, sunPhases, lightSun);
                if (powder) sunGain *= PowderTerm(m.powderC, lightSun);
                const float lightPoint = pointOn ? PointLightMarch(m, p) : 1.0;
                const float lightSky = m.light.skyOn != 0u ? PaddedBlendSky(m.strideY, m.strideZ, taps) : 1.0;
                precise float skyGain = lightSky * skyPhase;
                const vec3 inLight =
                    InScattered(m.light, LightSample(sunGain, lightSun, lightPoint, p, ray.dir, skyGain));
                precise float w = T * (1.0 - tau);
                L0 += w * inLight.x;
                L1 += w * inLight.y;
                L2 += w * inLight.z;
                T *= tau;
                if (T < m.epsilon || T == 0.0) break;
            }
            ++n;
            tn = tNext;
        }
    }
    r.transmittance = T;
    r.light = vec3(L0, L1, L2);
    precise vec3 c = vec3(L0 + T * m.background.x, L1 + T * m.background.y, L2 + T * m.background.z);
    r.color = c;
    return r;
}

// The whole pixel: its ray, its jitter and the march.
MarchRayResult MarchPixel(MarchGpu m, uint x, uint y) {
    const MarchRayGeometry ray = MakePixelRay(m, x, y);
    const float xi = (m.flags & kMarchJitter) != 0u ? MarchJitter(m.seed, m.frame, x + m.width * y) : 0.5;
    return MarchRay(m, ray, xi);
}

#endif
