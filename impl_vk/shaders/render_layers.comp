#version 450
// Stage `render_layers` (SPEC 15), pass 2: one invocation per pixel in 8 x 8
// workgroups, LayersPixel of core/math/layers.glsl (the CPU's loop over the
// layers the pixel's ray crosses, back to front, then LOD0's billboards), over the padded (q_alpha, T)
// volume of pass 1 (march_volume.comp, wrapped with tiling). Writes linear RGB
// and adds the LayersStats counters (a reduction in shared memory, then one
// atomic per workgroup and counter).
#extension GL_GOOGLE_include_directive : require
#include "random.glsl"
#include "shading.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "march.glsl"
#include "layers.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 0) readonly buffer Frame { LayersGpu frame; };
layout(std430, binding = 1) readonly buffer Volume { vec2 volume[]; };  // (q_alpha, T)
layout(std430, binding = 2) readonly buffer Mie { float mieTable[]; };  // read only with phase Mie
layout(std430, binding = 3) writeonly buffer Image { float image[]; };
// Words 2 n, 2 n + 1: counter n (low, high) of fragments, drawn.
layout(std430, binding = 4) buffer Stats { uint stats[]; };
layout(std430, binding = 5) readonly buffer Map { float layersMap[]; };  // read with wang opacity only
layout(std430, binding = 6) readonly buffer Billboards { LayersBillboard billboards[]; };  // LOD0, back to front

vec2 MarchFetchQT(uint paddedIndex) { return volume[paddedIndex]; }
float PhaseTableValue(uint i) { return mieTable[i]; }
float LayersMapValue(uint i) { return layersMap[i]; }
LayersBillboard LayersBillboardAt(uint i) { return billboards[i]; }
bool MarchBrickEmpty(uint brick) { return false; }  // march.glsl's bricks: never read here

shared uint gCounts[2];

void AddCounter(uint n, uint v) {
    if (v == 0u) return;
    const uint before = atomicAdd(stats[2u * n], v);
    if (before + v < before) atomicAdd(stats[2u * n + 1u], 1u);
}

void main() {
    const uint local = gl_LocalInvocationIndex;
    if (local < 2u) gCounts[local] = 0u;
    barrier();
    const LayersGpu s = frame;
    const uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    if (x < s.width && y < s.height) {
        const LayersPixelResult r = LayersPixel(s, x, y);
        const uint pixel = x + s.width * y;
        image[3u * pixel] = r.color.x;
        image[3u * pixel + 1u] = r.color.y;
        image[3u * pixel + 2u] = r.color.z;
        atomicAdd(gCounts[0], r.fragments);
        atomicAdd(gCounts[1], r.drawn);
    }
    barrier();
    if (local < 2u) AddCounter(local, gCounts[local]);
}
