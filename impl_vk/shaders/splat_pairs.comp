#version 450
// Splat pass 3: per splat, its (screen tile, splat) pairs at the splat's offset,
// tiles in raster order. The pairs are so in splat order, which the stable
// sort by tile (radix_sort.comp) keeps within each tile.
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "splat.glsl"
#include "splat_tiles.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 1) readonly buffer Offsets { uint pairOffset[]; };  // splat_write's counts, scanned
layout(std430, binding = 2) writeonly buffer Keys { uint keys[]; };           // screen tile
layout(std430, binding = 3) writeonly buffer Values { uint values[]; };       // splat index
layout(push_constant) uniform Params { uint splatCount, tilesX, tileSize; } pc;

void main() {
    const uint n = LinearInvocation();
    if (n >= pc.splatCount) return;
    const uvec4 r = SplatTileRect(splats[n], pc.tileSize);
    uint slot = pairOffset[n];
    for (uint ty = r.y; ty <= r.w && r.x <= r.z; ++ty)
        for (uint tx = r.x; tx <= r.z; ++tx) {
            keys[slot] = tx + pc.tilesX * ty;
            values[slot++] = n;
        }
}
