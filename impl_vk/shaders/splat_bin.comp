#version 450
// Splat binning into screen tiles, keeping the splat order. mode 0: per chunk
// of splats, count the splats overlapping each tile (counts[chunk][tile],
// zeroed before by the host's fill, not here: a loop over every tile per
// invocation ran past lavapipe's 65535 loop iterations at 2176 x 1440);
// mode 1: per tile, turn its counts into per-chunk offsets within the tile and
// its total; mode 2: per chunk, write splat indices at tileBase[tile] + offset,
// in order. Every write is owned by one invocation, so no atomics and the
// result does not depend on scheduling.
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"
#include "splat.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 1) buffer Counts { uint counts[]; };   // chunks x tiles
layout(std430, binding = 2) buffer Totals { uint totals[]; };   // per tile (mode 1 writes)
layout(std430, binding = 3) readonly buffer Bases { uint bases[]; };  // per tile (mode 2 reads)
layout(std430, binding = 4) writeonly buffer List { uint list[]; };
layout(push_constant) uniform Params { uint mode, splatCount, chunkSize, chunks, tilesX, tilesY, tileSize; } pc;

void main() {
    const uint id = gl_GlobalInvocationID.x;
    const uint tiles = pc.tilesX * pc.tilesY;
    if (pc.mode == 1u) {
        if (id >= tiles) return;
        uint running = 0u;
        for (uint c = 0u; c < pc.chunks; ++c) {
            const uint n = counts[c * tiles + id];
            counts[c * tiles + id] = running;
            running += n;
        }
        totals[id] = running;
        return;
    }
    if (id >= pc.chunks) return;
    const uint first = id * pc.chunkSize, last = min(pc.splatCount, first + pc.chunkSize);
    for (uint n = first; n < last; ++n) {
        const Splat s = splats[n];
        if (s.x0 > s.x1 || s.y0 > s.y1) continue;
        for (uint ty = uint(s.y0) / pc.tileSize; ty <= uint(s.y1) / pc.tileSize; ++ty)
            for (uint tx = uint(s.x0) / pc.tileSize; tx <= uint(s.x1) / pc.tileSize; ++tx) {
                const uint slot = id * tiles + tx + pc.tilesX * ty;
                if (pc.mode == 0u) counts[slot] += 1u;
                else list[bases[tx + pc.tilesX * ty] + counts[slot]++] = n;
            }
    }
}
