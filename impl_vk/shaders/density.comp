#version 450
// Stage `density` (SPEC 5) in one pass: one workgroup per tile. Each
// invocation takes columns of the tile (adjacent invocations, adjacent i: the
// reads of q coalesce) and sums each column serially over k ascending, the
// order every backend sums in, so D is bit-exact. The same read of q marks the
// bands with some q > 0 (a per-invocation mask of 32 bands, OR-ed into shared
// memory once per 32 bands), the tile flag is some D > 0, and the cover count
// (columns with any cld = 1, or with D > 0 when the scene has no automaton:
// fromCld = 0, cld then unused) is summed in shared memory and added to the
// global count once per workgroup. A dispatch covers the rows of tiles
// [ty0, ty0 + gl_NumWorkGroups.y) (a share, SPEC 13).
#extension GL_EXT_shader_8bit_storage : require
#extension GL_EXT_control_flow_attributes : require
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Q { float q[]; };
layout(std430, binding = 1) readonly buffer Cld { uint cld[]; };
layout(std430, binding = 2) writeonly buffer D { float d[]; };
layout(std430, binding = 3) buffer Cover { uint covered; };
layout(std430, binding = 4) writeonly buffer Tiles { uint8_t tiles[]; };
layout(std430, binding = 5) writeonly buffer Bands { uint8_t bands[]; };
layout(push_constant) uniform Params {
    uint nx, ny, nz, words, fromCld, tile, band, tilesX, tilesY, bandCount, ty0;
} pc;

const uint kGroup = 256u;
const uint kBatch = 8u;
const uint kBandWords = 64u;  // bands per tile: at most 32 * kBandWords (DensityVk checks)
shared uint sBands[kBandWords];
shared uint sCovered;
shared uint sTile;

void main() {
    const uint lid = gl_LocalInvocationIndex;
    const uint tx = gl_WorkGroupID.x, ty = pc.ty0 + gl_WorkGroupID.y;
    for (uint w = lid; w < (pc.bandCount + 31u) / 32u; w += kGroup) sBands[w] = 0u;
    if (lid == 0u) {
        sCovered = 0u;
        sTile = 0u;
    }
    memoryBarrierShared();
    barrier();
    const uint i0 = tx * pc.tile, j0 = ty * pc.tile;
    const uint width = min(pc.nx, i0 + pc.tile) - i0, height = min(pc.ny, j0 + pc.tile) - j0;
    const uint layer = pc.nx * pc.ny;
    uint cover = 0u;
    bool tileAny = false;
    for (uint c = lid; c < width * height; c += kGroup) {
        const uint i = i0 + c % width, j = j0 + c / width, column = i + pc.nx * j;
        float sum = 0.0;
        uint any = 0u, mask = 0u, b = 0u, bandEnd = min(pc.nz, pc.band);
        bool bandAny = false;
        // Slices in batches of kBatch: the batch's loads are issued before its
        // adds (more loads in flight per invocation); the adds stay in k order.
        for (uint k0 = 0u; k0 < pc.nz; k0 += kBatch) {
            float v[kBatch];
            [[unroll]] for (uint u = 0u; u < kBatch; ++u) v[u] = k0 + u < pc.nz ? q[column + layer * (k0 + u)] : 0.0;
            [[unroll]] for (uint u = 0u; u < kBatch; ++u) {
                const uint k = k0 + u;
                if (k >= pc.nz) break;
                sum += v[u];
                bandAny = bandAny || v[u] > 0.0;
                if (pc.fromCld != 0u) any |= (cld[(i >> 5) + pc.words * (j + pc.ny * k)] >> (i & 31u)) & 1u;
                if (k + 1u == bandEnd) {  // band b ends here
                    if (bandAny) mask |= 1u << (b & 31u);
                    if (((b & 31u) == 31u || bandEnd == pc.nz) && mask != 0u) {
                        atomicOr(sBands[b >> 5], mask);
                        mask = 0u;
                    }
                    bandAny = false;
                    ++b;
                    bandEnd = min(pc.nz, bandEnd + pc.band);
                }
            }
        }
        if (pc.fromCld == 0u) any = sum > 0.0 ? 1u : 0u;
        d[column] = sum;
        cover += any;
        tileAny = tileAny || sum > 0.0;
    }
    if (cover != 0u) atomicAdd(sCovered, cover);
    if (tileAny) atomicOr(sTile, 1u);
    memoryBarrierShared();
    barrier();
    for (uint b = lid; b < pc.bandCount; b += kGroup)
        bands[tx + pc.tilesX * (ty + pc.tilesY * b)] = uint8_t((sBands[b >> 5] >> (b & 31u)) & 1u);
    if (lid == 0u) {
        tiles[tx + pc.tilesX * ty] = uint8_t(sTile);
        if (sCovered != 0u) atomicAdd(covered, sCovered);
    }
}
