#version 450
// Stage `render_march`, pass 1 (impl_cpu/RenderMarchCpu.cpp step 1): the
// padded volume, (nx+2) x (ny+2) x (nz+2), one invocation per padded voxel.
// Voxel (i, j, k) sits at padded (i+1, j+1, k+1) and holds q_alpha =
// Lerp(q_prev, q_cur, alpha) and, with the light source "shade", T; the border
// holds (0, 1), or with `wrap` (tiling) the opposite edge's voxels
// in x and y (core/math/March.h PaddedSourceVoxel). With "shade" the volume is
// (q, T) pairs, else q alone.
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"
#include "padded_volume.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer QPrev { float qPrev[]; };
layout(std430, binding = 1) readonly buffer QCur { float qCur[]; };
layout(std430, binding = 2) readonly buffer Shade { float shadeT[]; };  // read only with hasT
layout(std430, binding = 3) writeonly buffer Volume { float volume[]; };
layout(push_constant) uniform Params { uint nx, ny, nz, hasT; float alpha; uint wrap; } pc;

void main() {
    const uint px = pc.nx + 2u, py = pc.ny + 2u;
    const uint i = gl_GlobalInvocationID.x, j = gl_GlobalInvocationID.y, k = gl_GlobalInvocationID.z;
    if (i >= px) return;
    const uint padded = i + px * (j + py * k);
    float q = 0.0, t = 1.0;
    const int vi = PaddedSource(i, pc.nx, pc.wrap != 0u), vj = PaddedSource(j, pc.ny, pc.wrap != 0u);
    const int vk = PaddedSource(k, pc.nz, false);
    if (vi >= 0 && vj >= 0 && vk >= 0) {
        const uint v = uint(vi) + pc.nx * (uint(vj) + pc.ny * uint(vk));
        q = Lerp(qPrev[v], qCur[v], pc.alpha);
        if (pc.hasT != 0u) t = shadeT[v];
    }
    if (pc.hasT != 0u) {
        volume[2u * padded] = q;
        volume[2u * padded + 1u] = t;
    } else {
        volume[padded] = q;
    }
}
