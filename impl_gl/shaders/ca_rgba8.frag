#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `ca` (SPEC 3), the thesis's layout: one fragment per voxel, one 8-bit
// channel per bit (R = hum, G = act, B = cld), the rules evaluated per voxel
// as the thesis's shader does; the same random draws as the packed layout.
layout(binding = 0) uniform usampler2DArray state;   // RGBA8UI
layout(binding = 1) uniform usampler2DArray region;  // R8UI
uniform int layer;
uniform ivec3 size;
uniform uint seed, step, qExt, qHum, qAct;
layout(location = 0) out uvec4 next;

uint Act(int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= size.x || j >= size.y || k >= size.z) return 0u;
    return texelFetch(state, ivec3(i, j, k), 0).g;
}

void main() {
    const int i = int(gl_FragCoord.x), j = int(gl_FragCoord.y), k = layer;
    const uint f = Act(i + 1, j, k) | Act(i - 1, j, k) | Act(i + 2, j, k) | Act(i - 2, j, k) | Act(i, j + 1, k) |
                   Act(i, j - 1, k) | Act(i, j + 2, k) | Act(i, j - 2, k) | Act(i, j, k + 1) | Act(i, j, k - 1) |
                   Act(i, j, k - 2);
    const uvec3 grown = CaGrowth(texelFetch(state, ivec3(i, j, k), 0).rgb, f);
    const uint r = texelFetch(region, ivec3(i, j, k), 0).r;
    const uint v = uint(i) + uint(size.x) * (uint(j) + uint(size.y) * uint(k));
    next = uvec4(CaVoxelEvents(grown, r, v, MakeCaEvents(seed, step, qExt, qHum, qAct)), 0u);
}
