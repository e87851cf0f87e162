#version 450
// Stage `smooth` (SPEC 4) in three separable passes, one invocation per voxel:
// pass 0 sums the bit field along x, pass 1 those sums along y, pass 2 those
// along z and scales by 1/W (a power of two: exact). The binomial weights are
// a product w(di) w(dj) w(dk) and the sums are integers, so this is the direct
// 27-tap (125 at r = 2) sum bit for bit, with 3 (5) reads a pass. A dispatch
// covers the voxels [first, end) (whole slices: a SPEC 13 share; SmoothVk.cpp).
#extension GL_GOOGLE_include_directive : require
#include "rules.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Cld { uint cld[]; };
layout(std430, binding = 1) buffer SumX { uint sumX[]; };
layout(std430, binding = 2) buffer SumXY { uint sumXY[]; };
layout(std430, binding = 3) writeonly buffer Q { float q[]; };
// kRanged: the share variant (GetPipeline's ranged), which also tests the lower end.
layout(constant_id = 0) const bool kRanged = false;
layout(push_constant) uniform Params { uint nx, ny, nz, words; int radius; float invW; uint pass, first, end; } pc;

void main() {
    const uint v = gl_GlobalInvocationID.x;
    if (v >= pc.end || (kRanged && v < pc.first)) return;
    const int i = int(v % pc.nx), j = int((v / pc.nx) % pc.ny), k = int(v / (pc.nx * pc.ny));
    const int r = pc.radius;
    uint sum = 0u;
    if (pc.pass == 0u) {
        const uint row = pc.words * (uint(j) + pc.ny * uint(k));
        for (int di = -r; di <= r; ++di) {
            const int x = i + di;
            if (x >= 0 && x < int(pc.nx)) sum += uint(SmoothWeight(r, di)) * ((cld[row + uint(x >> 5)] >> uint(x & 31)) & 1u);
        }
        sumX[v] = sum;
    } else if (pc.pass == 1u) {
        for (int dj = -r; dj <= r; ++dj) {
            const int y = j + dj;
            if (y >= 0 && y < int(pc.ny)) sum += uint(SmoothWeight(r, dj)) * sumX[uint(int(v) + dj * int(pc.nx))];
        }
        sumXY[v] = sum;
    } else {
        const int slice = int(pc.nx * pc.ny);
        for (int dk = -r; dk <= r; ++dk) {
            const int z = k + dk;
            if (z >= 0 && z < int(pc.nz)) sum += uint(SmoothWeight(r, dk)) * sumXY[uint(int(v) + dk * slice)];
        }
        q[v] = float(sum) * pc.invW;
    }
}
