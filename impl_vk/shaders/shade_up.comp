#version 450
// Stage `shade` at resolution f > 1: full-resolution T read trilinearly from
// the coarse grid at (i + 0.5)/f - 0.5, clamped to the coarse cell centres.
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer C { float coarse[]; };
layout(std430, binding = 1) writeonly buffer T { float t[]; };
layout(push_constant) uniform Params { uint nx, ny, nz, cx, cy, cz, f; } pc;

float At(int x, int y, int z) { return coarse[uint(x) + pc.cx * (uint(y) + pc.cy * uint(z))]; }

void main() {
    const uint v = gl_GlobalInvocationID.x;
    if (v >= pc.nx * pc.ny * pc.nz) return;
    const uint i = v % pc.nx, j = (v / pc.nx) % pc.ny, k = v / (pc.nx * pc.ny);
    int x0, x1, y0, y1, z0, z1;
    float tx, ty, tz;
    UpsampleTap(int(i), int(pc.f), int(pc.cx), x0, x1, tx);
    UpsampleTap(int(j), int(pc.f), int(pc.cy), y0, y1, ty);
    UpsampleTap(int(k), int(pc.f), int(pc.cz), z0, z1, tz);
    const float b0 = Bilinear(At(x0, y0, z0), At(x0, y1, z0), At(x0, y0, z1), At(x0, y1, z1), ty, tz);
    const float b1 = Bilinear(At(x1, y0, z0), At(x1, y1, z0), At(x1, y0, z1), At(x1, y1, z1), ty, tz);
    t[v] = Lerp(b0, b1, tx);
}
