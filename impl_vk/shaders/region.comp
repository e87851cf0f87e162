#version 450
// Stage `region` (SPEC 2): one invocation per voxel, max over the ellipsoids
// that can reach its 16x16-voxel tile of its slice (the host's per-tile
// lists), then quantised once (quantising is monotone). A dispatch covers the
// voxels [first, end), the slices from k0 on (a share, SPEC 13); the host's
// lists start at slice k0.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_8bit_storage : require
#include "rules.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Ellipsoids { float ellipsoid[]; };  // 8 floats each
layout(std430, binding = 1) writeonly buffer Region { uint8_t region[]; };
layout(std430, binding = 2) readonly buffer TileStart { uint tileStart[]; };  // per tile, and one past the end
layout(std430, binding = 3) readonly buffer TileList { uint tileList[]; };    // ellipsoid indices
// kRanged: the share variant (GetPipeline's ranged), which also tests the lower end.
layout(constant_id = 0) const bool kRanged = false;
layout(push_constant) uniform Params { uint nx, ny, k0, first, end, tilesX, tilesY; } pc;

void main() {
    const uint v = gl_GlobalInvocationID.x;
    if (v >= pc.end || (kRanged && v < pc.first)) return;
    const uint i = v % pc.nx, j = (v / pc.nx) % pc.ny, k = v / (pc.nx * pc.ny);
    const vec3 p = vec3(float(i) + 0.5, float(j) + 0.5, float(k) + 0.5);
    const uint tile = i / 16u + pc.tilesX * (j / 16u + pc.tilesY * (k - pc.k0));
    float best = 0.0;
    for (uint entry = tileStart[tile]; entry < tileStart[tile + 1u]; ++entry) {
        const uint b = 8u * tileList[entry];
        const vec3 c = vec3(ellipsoid[b], ellipsoid[b + 1u], ellipsoid[b + 2u]);
        const vec3 axes = vec3(ellipsoid[b + 3u], ellipsoid[b + 4u], ellipsoid[b + 5u]);
        // Cheap rejection: outside the bounding cylinder (plus a voxel) w is 0.
        const float reach = max(axes.x, axes.y) + 1.0;
        if (abs(p.z - c.z) > axes.z + 1.0 || abs(p.x - c.x) > reach || abs(p.y - c.y) > reach) continue;
        best = max(best, EllipsoidWeight(c, axes, ellipsoid[b + 6u], ellipsoid[b + 7u], p));
    }
    region[v] = uint8_t(QuantizeRegion(best));
}
