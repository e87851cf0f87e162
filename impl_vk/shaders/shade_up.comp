#version 450
// Stage `shade` at resolution f > 1: full-resolution T read trilinearly from
// the coarse grid at (i + 0.5)/f - 0.5, clamped to the coarse cell centres.
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer C { float coarse[]; };
layout(std430, binding = 1) writeonly buffer T { float t[]; };
layout(push_constant) uniform Params { uint nx, ny, nz, cx, cy, cz, f; } pc;

void Tap(uint i, uint cells, out uint i0, out uint i1, out float w) {
    const float x = clamp((float(i) + 0.5) / float(pc.f) - 0.5, 0.0, float(cells - 1u));
    i0 = uint(x);
    i1 = min(i0 + 1u, cells - 1u);
    w = x - float(i0);
}
float At(uint x, uint y, uint z) { return coarse[x + pc.cx * (y + pc.cy * z)]; }

void main() {
    const uint v = gl_GlobalInvocationID.x;
    if (v >= pc.nx * pc.ny * pc.nz) return;
    const uint i = v % pc.nx, j = (v / pc.nx) % pc.ny, k = v / (pc.nx * pc.ny);
    uint x0, x1, y0, y1, z0, z1;
    float tx, ty, tz;
    Tap(i, pc.cx, x0, x1, tx);
    Tap(j, pc.cy, y0, y1, ty);
    Tap(k, pc.cz, z0, z1, tz);
    const float b0 = Bilinear(At(x0, y0, z0), At(x0, y1, z0), At(x0, y0, z1), At(x0, y1, z1), ty, tz);
    const float b1 = Bilinear(At(x1, y0, z0), At(x1, y1, z0), At(x1, y0, z1), At(x1, y1, z1), ty, tz);
    precise float value = b0 * (1.0 - tx) + b1 * tx;
    t[v] = value;
}
