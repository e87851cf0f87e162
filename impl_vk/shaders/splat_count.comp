#version 450
// Splat pass 1: per chunk of ranks (F.ranksPerChunk, a multiple of 32), how many
// splats it makes, how many (screen tile, splat) pairs they make, and which
// ranks make one: a bit per rank, 32 to a word (splat_write.comp walks them).
// Also SplatStats' voxels visited (ranks whose box is visible) and fragments
// (covered pixels summed over splats), added into one of 64 slots of (visited,
// fragments' low word, high word) after the totals' first two words (zeroed by
// the host, which sums the slots).
#extension GL_GOOGLE_include_directive : require
#include "splat_ranks.glsl"
#include "splat_tiles.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 6) writeonly buffer Counts { uint chunkSplats[]; };
layout(std430, binding = 7) writeonly buffer Pairs { uint chunkPairs[]; };
layout(std430, binding = 8) writeonly buffer Candidates { uint candidates[]; };
layout(std430, binding = 9) buffer Totals { uint totals[]; };  // splats, pairs, 64 x (visited, fragments low, high)
layout(push_constant) uniform Params { uint chunks, tileSize; } pc;

void main() {
    const uint c = gl_GlobalInvocationID.x;
    if (c >= pc.chunks) return;
    const uint first = c * F.ranksPerChunk, last = min(F.voxelCount, first + F.ranksPerChunk);
    const uint nMid = AxisSize(F.axes.y), nIn = AxisSize(F.axes.z);
    uint splats = 0u, pairs = 0u, word = 0u, visited = 0u, fragments = 0u;  // a chunk's fragments: < 2^32
    // Run by run along the inner axis: the outer and middle entries hold for a run.
    uvec3 cursor = RankCursor(first);
    for (uint r = first; r < last;) {
        const uvec4 outer = rankPart[F.orderBase.x + cursor.x], mid = rankPart[F.orderBase.y + cursor.y];
        const uint runEnd = min(last, r + (nIn - cursor.z));
        for (uint i = F.orderBase.z + cursor.z; r < runEnd; ++r, ++i) {
            const uvec4 inner = rankPart[i];
            Splat s;
            if (PartsBoxVisible(outer, mid, inner)) {
                ++visited;
                if (MakePartsSplat(outer, mid, inner, s)) {
                    ++splats;
                    pairs += SplatTileCount(s, pc.tileSize);
                    if (s.x0 <= s.x1 && s.y0 <= s.y1) fragments += uint(s.x1 - s.x0 + 1) * uint(s.y1 - s.y0 + 1);
                    word |= 1u << (r % 32u);
                }
            }
            if (r % 32u == 31u || r + 1u == last) {
                candidates[r / 32u] = word;
                word = 0u;
            }
        }
        cursor.z = 0u;
        if (++cursor.y == nMid) {
            cursor.y = 0u;
            ++cursor.x;
        }
    }
    chunkSplats[c] = splats;
    chunkPairs[c] = pairs;
    const uint slot = 2u + 3u * (c % 64u);
    if (visited != 0u) atomicAdd(totals[slot], visited);
    if (fragments != 0u && atomicAdd(totals[slot + 1u], fragments) + fragments < fragments)
        atomicAdd(totals[slot + 2u], 1u);  // the low word wrapped
}
