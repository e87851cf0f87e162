#version 450
// Stage `render_march` (SPEC 10), pass 3: one invocation per pixel in 8 x 8
// workgroups, MarchPixel of core/glsl/march.glsl, which twins core/March.h
// MarchRay line by line. Reads the padded volume of pass 1 (march_volume.comp),
// the bricks of pass 2 (march_bricks.comp) when skipping, the Mie table when
// the phase is Mie; writes linear HDR RGB and adds the MarchStats counters
// (a reduction in shared memory, then one atomic per workgroup and counter).
#extension GL_GOOGLE_include_directive : require
#include "random.glsl"
#include "shading.glsl"
#include "march.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 0) readonly buffer Frame { MarchGpu frame; };
layout(std430, binding = 1) readonly buffer Volume { float volume[]; };
layout(std430, binding = 2) readonly buffer Bricks { uint brickEmpty[]; };  // read only when skipping
layout(std430, binding = 3) readonly buffer Mie { float mieTable[]; };     // read only with phase Mie
layout(std430, binding = 4) writeonly buffer Image { float image[]; };
// Words 2 n, 2 n + 1: counter n (low, high) of rays, samples, light samples, bricks skipped.
layout(std430, binding = 5) buffer Stats { uint stats[]; };

bool gHasT;

vec2 MarchFetchQT(uint paddedIndex) {
    return gHasT ? vec2(volume[2u * paddedIndex], volume[2u * paddedIndex + 1u]) : vec2(volume[paddedIndex], 1.0);
}
bool MarchBrickEmpty(uint brick) { return brickEmpty[brick] != 0u; }
float MarchPhaseTableValue(uint i) { return mieTable[i]; }

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
    gHasT = (m.flags.x & kMarchLightMarch) == 0u;
    const uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    if (x < m.image.x && y < m.image.y) {
        const MarchRayResult r = MarchPixel(m, x, y);
        const uint pixel = x + m.image.x * y;
        image[3u * pixel] = r.color.x;
        image[3u * pixel + 1u] = r.color.y;
        image[3u * pixel + 2u] = r.color.z;
        const MarchRayGeometry ray = MakePixelRay(m, x, y);
        if (ray.tMin < ray.tMax) atomicAdd(gCounts[0], 1u);
        atomicAdd(gCounts[1], r.samples);
        atomicAdd(gCounts[2], r.lightCalls);
        atomicAdd(gCounts[3], r.bricksSkipped);
    }
    barrier();
    if (local < 4u) AddCounter(local, gCounts[local]);
}
