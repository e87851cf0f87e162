#version 450
// Stage `smooth` (SPEC 4): one invocation per voxel, the integer binomial sum
// over the neighbourhood, scaled by 1/W (a power of two: exact).
#extension GL_GOOGLE_include_directive : require
#include "rules.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Cld { uint cld[]; };
layout(std430, binding = 1) writeonly buffer Q { float q[]; };
layout(push_constant) uniform Params { uint nx, ny, nz, words; int radius; float invW; } pc;

uint Bit(int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= int(pc.nx) || j >= int(pc.ny) || k >= int(pc.nz)) return 0u;
    const uint word = cld[uint(i >> 5) + pc.words * (uint(j) + pc.ny * uint(k))];
    return (word >> uint(i & 31)) & 1u;
}

void main() {
    const uint v = gl_GlobalInvocationID.x;
    if (v >= pc.nx * pc.ny * pc.nz) return;
    const int i = int(v % pc.nx), j = int((v / pc.nx) % pc.ny), k = int(v / (pc.nx * pc.ny));
    const int r = pc.radius;
    int sum = 0;
    for (int dk = -r; dk <= r; ++dk)
        for (int dj = -r; dj <= r; ++dj) {
            const int wjk = SmoothWeight(r, dj) * SmoothWeight(r, dk);
            for (int di = -r; di <= r; ++di) sum += wjk * SmoothWeight(r, di) * int(Bit(i + di, j + dj, k + dk));
        }
    q[v] = float(sum) * pc.invW;
}
