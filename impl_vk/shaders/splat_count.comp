#version 450
// Splat pass 1: per chunk of ranks, how many splats it makes and how many
// voxels it visits (boxes not culled or skipped).
#extension GL_GOOGLE_include_directive : require
#include "splat_ranks.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 6) writeonly buffer Counts { uint chunkSplats[]; };
layout(std430, binding = 7) writeonly buffer Visited { uint chunkVisited[]; };
layout(push_constant) uniform Params { uint chunks; } pc;

void main() {
    const uint c = gl_GlobalInvocationID.x;
    if (c >= pc.chunks) return;
    const uint first = c * F.grid.w, last = min(F.axes.w, first + F.grid.w);
    uint splats = 0u;
    for (uint r = first; r < last; ++r) {
        Splat s;
        if (MakeRankSplat(r, s)) ++splats;
    }
    chunkSplats[c] = splats;
    chunkVisited[c] = 0u;
}
