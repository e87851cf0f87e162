// Shared by the splat passes that walk ranks (SPEC 8): the bindings and
// MakeRankSplat, which turns the voxel of a given rank in the shared
// back-to-front order into a splat (core/glsl/splat.glsl MakeSplat).
#ifndef CLOUDBENCH_SPLAT_RANKS_GLSL
#define CLOUDBENCH_SPLAT_RANKS_GLSL
#extension GL_EXT_shader_8bit_storage : require
#include "shading.glsl"
#include "splat.glsl"

layout(std430, binding = 0) readonly buffer QPrev { float qPrev[]; };
layout(std430, binding = 1) readonly buffer QCur { float qCur[]; };
layout(std430, binding = 2) readonly buffer Transmittance { float transmittance[]; };
layout(std430, binding = 3) readonly buffer Order { uint orderIndex[]; };  // outer, middle, inner axis orders
layout(std430, binding = 4) readonly buffer Boxes { uint8_t boxVisible[]; };
// grid.w: voxels per chunk of ranks; image.zw: screen tiles across and down.
layout(std430, binding = 5) readonly buffer Frame { SplatFrame F; };

uint AxisSize(uint axis) { return axis == 0u ? F.grid.x : (axis == 1u ? F.grid.y : F.grid.z); }

bool MakeRankSplat(uint rank, out Splat s) {
    s = Splat(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, -1, 0, -1);
    const uint nMid = AxisSize(F.axes.y), nIn = AxisSize(F.axes.z);
    const uint o = rank / (nMid * nIn), rest = rank % (nMid * nIn);
    uvec3 idx;
    idx[F.axes.x] = orderIndex[F.orderBase.x + o];
    idx[F.axes.y] = orderIndex[F.orderBase.y + rest / nIn];
    idx[F.axes.z] = orderIndex[F.orderBase.z + rest % nIn];
    const uint box = idx.x / F.boxes.x + F.boxes.z * (idx.y / F.boxes.x + F.boxes.w * (idx.z / F.boxes.y));
    if (uint(boxVisible[box]) == 0u) return false;
    const uint v = idx.x + F.grid.x * (idx.y + F.grid.y * idx.z);
    return MakeSplat(F, idx, SplatQ(qPrev[v], qCur[v], F.misc.y), transmittance[v], s);
}

#endif
