#version 450
// Splat pass 3: per chunk of ranks, write its splats at the chunk's offset, in order.
#extension GL_GOOGLE_include_directive : require
#include "splat_ranks.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 6) readonly buffer Offsets { uint chunkOffset[]; };
layout(std430, binding = 7) writeonly buffer Splats { Splat splats[]; };
layout(push_constant) uniform Params { uint chunks; } pc;

void main() {
    const uint c = gl_GlobalInvocationID.x;
    if (c >= pc.chunks) return;
    const uint first = c * F.grid.w, last = min(F.axes.w, first + F.grid.w);
    uint slot = chunkOffset[c];
    for (uint r = first; r < last; ++r) {
        Splat s;
        if (MakeRankSplat(r, s)) splats[slot++] = s;
    }
}
