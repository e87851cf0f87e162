#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "march.glsl"
#include "ground.glsl"
// Stage `render_march` (SPEC 10): one fragment per pixel, as Olajos's
// full-screen pass. The fragment at gl_FragCoord (x + 0.5, y + 0.5) is the
// image's pixel (x, y): the target's row y = 0 is the first row read back, so
// the canonical layout's row 0 (the top) needs no flip. MarchPixel of
// core/math/march.glsl (prepended) marches the ray; the volume, T_sky's volume,
// the bricks and the Mie table are storage buffers read by index (never a
// filtering sampler).
layout(std140, binding = 0) uniform MarchBlock { MarchGpu march; };
layout(std430, binding = 0) readonly buffer MarchVolume { vec2 marchQT[]; };
layout(std430, binding = 1) readonly buffer MarchBricks { uint marchBrickEmpty[]; };
layout(std430, binding = 2) readonly buffer MarchPhaseTable { float marchPhaseTable[]; };
// rays, samples, light samples, bricks skipped: 64-bit sums as (low, high) word pairs.
layout(std430, binding = 3) buffer MarchCounters { uint marchCounters[]; };
// The sky light's padded T_sky volume, read with the sky light on only.
layout(std430, binding = 4) readonly buffer MarchSkyVolume { float marchSkyT[]; };
// The ground (flag kMarchGround): its block and G, (nx, ny, 1).
layout(std140, binding = 1) uniform GroundBlock { GroundGpu ground; };
layout(binding = 3) uniform sampler2DArray groundShadow;
layout(location = 0) out vec4 colour;

vec2 MarchFetchQT(uint paddedIndex) { return marchQT[paddedIndex]; }
float MarchFetchSkyT(uint paddedIndex) { return marchSkyT[paddedIndex]; }
bool MarchBrickEmpty(uint brick) { return marchBrickEmpty[brick] != 0u; }
float PhaseTableValue(uint i) { return marchPhaseTable[i]; }
float GroundFetchG(uint i, uint j) { return texelFetch(groundShadow, ivec3(i, j, 0), 0).r; }

// Adds v to the 64-bit counter n; a carry out of the low word goes to the high one.
void MarchCount(uint n, uint v) {
    if (v == 0u) return;
    const uint before = atomicAdd(marchCounters[2u * n], v);
    if (before + v < before) atomicAdd(marchCounters[2u * n + 1u], 1u);
}

void main() {
    const uint x = uint(gl_FragCoord.x), y = uint(gl_FragCoord.y);
    // The option bits, the phase kind, the point light and the sky light are compile-time constants where the
    // host defines them (impl_gl/RenderMarchGL.cpp links a program per
    // combination): the compiler then drops the code of the options that are
    // off, which halves the time on llvmpipe.
    MarchGpu m = march;
#ifdef MARCH_FLAGS
    m.flags = MARCH_FLAGS;
    m.light.phaseKind = MARCH_PHASE;
    m.light.pointOn = MARCH_POINT;
    m.light.skyOn = MARCH_SKY;
#endif
    const MarchRayResult r = MarchPixel(m, x, y);
    if ((m.flags & kMarchGround) != 0u) {
        // C = L + T_view background with the pixel's own background (impl_cpu/RenderMarchCpu.cpp).
        const vec3 bg = GroundBackground(ground, x, y);
        precise vec3 c = vec3(r.light.x + r.transmittance * bg.x, r.light.y + r.transmittance * bg.y,
                              r.light.z + r.transmittance * bg.z);
        colour = vec4(c, 1.0);
    } else {
        colour = vec4(r.color, 1.0);
    }
    const MarchRayGeometry ray = MakePixelRay(m, x, y);
    MarchCount(0u, ray.tMin < ray.tMax ? 1u : 0u);
    MarchCount(1u, r.samples);
    MarchCount(2u, r.lightCalls);
    MarchCount(3u, r.bricksSkipped);
}
