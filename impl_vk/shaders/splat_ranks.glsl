// Shared by the splat passes that walk ranks (SPEC 8): the bindings, and the
// splat of the voxel of a given rank in the shared back-to-front order
// (core/math/splat.glsl MakeSplat). A rank is (o, m, i): its positions in the
// outer, middle and inner axis orders, r = (o nMid + m) nIn + i.
#ifndef CLOUDBENCH_SPLAT_RANKS_GLSL
#define CLOUDBENCH_SPLAT_RANKS_GLSL
#extension GL_EXT_shader_8bit_storage : require
#include "shading.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "splat.glsl"

layout(std430, binding = 0) readonly buffer QPrev { float qPrev[]; };
layout(std430, binding = 1) readonly buffer QCur { float qCur[]; };
layout(std430, binding = 2) readonly buffer Transmittance { float transmittance[]; };
// Per position of each axis order, from F.orderBase (RenderSplatVk.cpp
// MakeRankParts): the voxel coordinate along the axis, and that coordinate's
// share of the voxel index and of the box index, so a rank's voxel and box
// are sums, with no division.
layout(std430, binding = 3) readonly buffer RankParts { uvec4 rankPart[]; };
layout(std430, binding = 4) readonly buffer Boxes { uint8_t boxVisible[]; };
// grid.w: voxels per chunk of ranks; image.zw: screen tiles across and down.
layout(std430, binding = 5) readonly buffer Frame { SplatFrame F; };
// Read with phase Mie only: kMieCloudTable's values (F.light.mieIndexPerRadian, F.light.mieCount).
layout(std430, binding = 10) readonly buffer PhaseTable { float phaseTable[]; };
float PhaseTableValue(uint i) { return phaseTable[i]; }
// The sky light's T_sky, a grid like transmittance; read only with the sky light on (F.light.skyOn).
layout(std430, binding = 11) readonly buffer SkyTransmittance { float skyTransmittance[]; };

uint AxisSize(uint axis) { return axis == 0u ? F.grid.x : (axis == 1u ? F.grid.y : F.grid.z); }

// (o, m, i) of a rank: divisions, so once per chunk or per splat.
uvec3 RankCursor(uint rank) {
    const uint nMid = AxisSize(F.axes.y), nIn = AxisSize(F.axes.z);
    const uint rest = rank % (nMid * nIn);
    return uvec3(rank / (nMid * nIn), rest / nIn, rest % nIn);
}

// Whether the box of the voxel with these rankPart entries is visible (not culled or skipped).
bool PartsBoxVisible(uvec4 outer, uvec4 mid, uvec4 inner) {
    return uint(boxVisible[outer.z + mid.z + inner.z]) != 0u;
}

// The splat of the voxel whose positions in the outer, middle and inner axis
// orders have these rankPart entries, whose box is visible; false when
// MakeSplat makes none.
bool MakePartsSplat(uvec4 outer, uvec4 mid, uvec4 inner, out Splat s) {
    const uint v = outer.y + mid.y + inner.y;
    uvec3 idx;
    idx[F.axes.x] = outer.x;
    idx[F.axes.y] = mid.x;
    idx[F.axes.z] = inner.x;
    const float tSky = F.light.skyOn != 0u ? skyTransmittance[v] : 1.0;
    return MakeSplat(F, idx, SplatQ(qPrev[v], qCur[v], F.alpha), transmittance[v], tSky, s);
}

// The splat of the voxel at cursor c (RankCursor), whose box is visible.
bool MakeRankSplat(uvec3 c, out Splat s) {
    return MakePartsSplat(rankPart[F.orderBase.x + c.x], rankPart[F.orderBase.y + c.y],
                          rankPart[F.orderBase.z + c.z], s);
}

#endif
