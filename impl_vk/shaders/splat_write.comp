#version 450
// Splat pass 2: per chunk of ranks, write its splats at the chunk's offset, in
// order, and how many screen tiles each covers. Only the ranks that
// splat_count.comp marked are made again.
#extension GL_GOOGLE_include_directive : require
#include "splat_ranks.glsl"
#include "splat_tiles.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 6) readonly buffer Offsets { uint chunkOffset[]; };
layout(std430, binding = 7) writeonly buffer Splats { Splat splats[]; };
layout(std430, binding = 8) writeonly buffer Tiles { uint splatTiles[]; };
layout(std430, binding = 9) readonly buffer Candidates { uint candidates[]; };
layout(push_constant) uniform Params { uint chunks, tileSize; } pc;

void main() {
    const uint c = gl_GlobalInvocationID.x;
    if (c >= pc.chunks) return;
    const uint first = c * F.ranksPerChunk, last = min(F.voxelCount, first + F.ranksPerChunk);
    uint slot = chunkOffset[c];
    for (uint w = first / 32u; w < (last + 31u) / 32u; ++w)
        for (uint word = candidates[w]; word != 0u; word &= word - 1u) {
            Splat s;
            MakeRankSplat(RankCursor(32u * w + uint(findLSB(word))), s);
            splatTiles[slot] = SplatTileCount(s, pc.tileSize);
            splats[slot++] = s;
        }
}
