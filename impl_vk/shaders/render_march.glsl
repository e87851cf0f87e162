// The body of render_march.comp (light "shade": the volume holds (q_alpha, T) pairs) and
// render_march_q.comp (light "march": q_alpha alone), which define MARCH_WITH_T 1 or 0 and include it:
// two pipelines, so that no tap branches on the light source.
#include "random.glsl"
#include "shading.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "march.glsl"
#include "ground.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 0) readonly buffer Frame { MarchGpu frame; };
#if MARCH_WITH_T
layout(std430, binding = 1) readonly buffer Volume { vec2 volume[]; };  // (q_alpha, T)
#else
layout(std430, binding = 1) readonly buffer Volume { float volume[]; };  // q_alpha
#endif
layout(std430, binding = 2) readonly buffer Bricks { uint brickEmpty[]; };  // read only when skipping
layout(std430, binding = 3) readonly buffer Mie { float mieTable[]; };     // read only with phase Mie
layout(std430, binding = 4) writeonly buffer Image { float image[]; };
// Words 2 n, 2 n + 1: counter n (low, high) of rays, samples, light samples, bricks skipped.
layout(std430, binding = 5) buffer Stats { uint stats[]; };
// The ground (flag kMarchGround): its block and G, (nx, ny); read only with the flag.
layout(std430, binding = 6) readonly buffer Ground { GroundGpu ground; };
layout(std430, binding = 7) readonly buffer GroundG { float groundG[]; };
// The sky light's T_sky, padded like the volume (sky_volume.comp); read only with the sky light on.
layout(std430, binding = 8) readonly buffer SkyVolume { float skyVolume[]; };

#if MARCH_WITH_T
vec2 MarchFetchQT(uint paddedIndex) { return volume[paddedIndex]; }
#else
vec2 MarchFetchQT(uint paddedIndex) { return vec2(volume[paddedIndex], 1.0); }
#endif
float MarchFetchSkyT(uint paddedIndex) { return skyVolume[paddedIndex]; }
bool MarchBrickEmpty(uint brick) { return brickEmpty[brick] != 0u; }
float PhaseTableValue(uint i) { return mieTable[i]; }
float GroundFetchG(uint i, uint j) { return groundG[i + ground.gridX * j]; }

shared uint gCounts[4];

// Adds v to the 64-bit counter at words (2 n, 2 n + 1).
void AddCounter(uint n, uint v) {
    if (v == 0u) return;
    const uint before = atomicAdd(stats[2u * n], v);
    if (before + v < before) atomicAdd(stats[2u * n + 1u], 1u);
}

void main() {
    const uint local = gl_LocalInvocationIndex;
    if (local < 4u) gCounts[local] = 0u;
    barrier();
    const MarchGpu m = frame;
    const uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    if (x < m.width && y < m.height) {
        const MarchRayResult r = MarchPixel(m, x, y);
        const uint pixel = x + m.width * y;
        vec3 c = r.color;
        if ((m.flags & kMarchGround) != 0u) {
            // C = L + T_view background with the pixel's own background (impl_cpu/RenderMarchCpu.cpp).
            const vec3 bg = GroundBackground(ground, x, y);
            precise vec3 lit = vec3(r.light.x + r.transmittance * bg.x, r.light.y + r.transmittance * bg.y,
                                    r.light.z + r.transmittance * bg.z);
            c = lit;
        }
        image[3u * pixel] = c.x;
        image[3u * pixel + 1u] = c.y;
        image[3u * pixel + 2u] = c.z;
        const MarchRayGeometry ray = MakePixelRay(m, x, y);
        if (ray.tMin < ray.tMax) atomicAdd(gCounts[0], 1u);
        atomicAdd(gCounts[1], r.samples);
        atomicAdd(gCounts[2], r.lightCalls);
        atomicAdd(gCounts[3], r.bricksSkipped);
    }
    barrier();
    if (local < 4u) AddCounter(local, gCounts[local]);
}
