#version 450
// The sky light's T_sky as render_march and render_layers read it (impl_vk/SkyVolumeVk.h): the padded volume,
// (nx+2) x (ny+2) x (nz+2) floats in march_volume.comp's layout, one invocation per padded voxel. Voxel
// (i, j, k) sits at padded (i+1, j+1, k+1) and holds its T_sky; the border holds 1, or with `wrap` (tiling)
// the opposite edge's voxels in x and y.
#extension GL_GOOGLE_include_directive : require
#include "padded_volume.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer SkyT { float skyT[]; };
layout(std430, binding = 1) writeonly buffer Volume { float volume[]; };
layout(push_constant) uniform Params { uint nx, ny, nz, wrap; } pc;

void main() {
    const uint px = pc.nx + 2u, py = pc.ny + 2u;
    const uint i = gl_GlobalInvocationID.x, j = gl_GlobalInvocationID.y, k = gl_GlobalInvocationID.z;
    if (i >= px) return;
    const int vi = PaddedSource(i, pc.nx, pc.wrap != 0u), vj = PaddedSource(j, pc.ny, pc.wrap != 0u);
    const int vk = PaddedSource(k, pc.nz, false);
    float t = 1.0;
    if (vi >= 0 && vj >= 0 && vk >= 0) t = skyT[uint(vi) + pc.nx * (uint(vj) + pc.ny * uint(vk))];
    volume[i + px * (j + py * k)] = t;
}
