#version 450
// Splat compositing: one invocation per pixel walks its screen tile's splats
// in the shared back-to-front order: C <- alpha c + (1 - alpha) C, from the
// flat background, or with `ground` from the pixel's ground (ground.glsl).
// One workgroup per 8 x 8 screen tile (tileSize must be 8; workgroup (i, j)
// is tile (i, j)), so that all its invocations walk the same list: the same
// loads and the same trip count.
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "splat.glsl"
#include "ground.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 1) readonly buffer Bases { uint bases[]; };
layout(std430, binding = 2) readonly buffer List { uint list[]; };
layout(std430, binding = 3) writeonly buffer Image { float image[]; };
layout(std430, binding = 4) readonly buffer Ground { GroundGpu ground; };  // read only with pc.ground
layout(std430, binding = 5) readonly buffer GroundG { float groundG[]; };  // G, (nx, ny); likewise
layout(push_constant) uniform Params { uint width, height, tilesX, tileSize; vec3 background; uint ground; } pc;

float GroundFetchG(uint i, uint j) { return groundG[i + ground.gridX * j]; }

void main() {
    const uint tile = gl_WorkGroupID.x + pc.tilesX * gl_WorkGroupID.y, lane = gl_LocalInvocationID.x;
    const int x = int(pc.tileSize * gl_WorkGroupID.x + lane % pc.tileSize);
    const int y = int(pc.tileSize * gl_WorkGroupID.y + lane / pc.tileSize);
    if (uint(x) >= pc.width || uint(y) >= pc.height) return;
    const uint id = uint(x) + pc.width * uint(y);
    vec3 c = pc.ground != 0u ? GroundBackground(ground, uint(x), uint(y)) : pc.background;
    for (uint n = bases[tile]; n < bases[tile + 1u]; ++n) {
        const Splat s = splats[list[n]];
        if (x < s.x0 || x > s.x1 || y < s.y0 || y > s.y1) continue;
        const float a = SplatCoord(float(x) + 0.5, s.px, s.size), b = SplatCoord(float(y) + 0.5, s.py, s.size);
        const float alpha = SplatAlpha(s.alphaScale, a, b);
        c = vec3(Lerp(c.r, s.r, alpha), Lerp(c.g, s.g, alpha), Lerp(c.b, s.b, alpha));
    }
    image[3u * id] = c.r;
    image[3u * id + 1u] = c.g;
    image[3u * id + 2u] = c.b;
}
