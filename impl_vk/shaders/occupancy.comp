#version 450
// Stage `density` (SPEC 5), occupancy: one invocation per tile x band (bands:
// some q > 0 in the tile's columns within the band) and, for band == nb, per
// tile (some D > 0 in the tile). A dispatch covers the rows of tiles
// [ty0, ty0 + tileRows) (a share, SPEC 13).
#extension GL_EXT_shader_8bit_storage : require
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Q { float q[]; };
layout(std430, binding = 1) readonly buffer D { float d[]; };
layout(std430, binding = 2) writeonly buffer Tiles { uint8_t tiles[]; };
layout(std430, binding = 3) writeonly buffer Bands { uint8_t bands[]; };
// kRanged: the share variant (GetPipeline's ranged), which also tests the lower end.
layout(constant_id = 0) const bool kRanged = false;
layout(push_constant) uniform Params { uint nx, ny, nz, tile, band, tilesX, tilesY, bandCount, ty0, tileRows; } pc;

void main() {
    // The whole call (kRanged false) indexes as tile x band directly; a share maps
    // its rows' tiles onto them.
    const uint local = gl_GlobalInvocationID.x;
    const uint rows = kRanged ? pc.tileRows : pc.tilesY, shareLayer = pc.tilesX * rows;
    if (local >= shareLayer * (pc.bandCount + 1u)) return;
    const uint tx = local % pc.tilesX, ty = (kRanged ? pc.ty0 : 0u) + (local / pc.tilesX) % rows, b = local / shareLayer;
    const uint id = kRanged ? tx + pc.tilesX * (ty + pc.tilesY * b) : local;
    const uint i0 = tx * pc.tile, i1 = min(pc.nx, i0 + pc.tile);
    const uint j0 = ty * pc.tile, j1 = min(pc.ny, j0 + pc.tile);
    bool any = false;
    if (b == pc.bandCount) {
        for (uint j = j0; j < j1 && !any; ++j)
            for (uint i = i0; i < i1; ++i) any = any || d[i + pc.nx * j] > 0.0;
        tiles[tx + pc.tilesX * ty] = uint8_t(any ? 1u : 0u);
    } else {
        const uint k1 = min(pc.nz, (b + 1u) * pc.band);
        for (uint k = b * pc.band; k < k1 && !any; ++k)
            for (uint j = j0; j < j1; ++j)
                for (uint i = i0; i < i1; ++i) any = any || q[i + pc.nx * (j + pc.ny * k)] > 0.0;
        bands[id] = uint8_t(any ? 1u : 0u);
    }
}
