#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `smooth` (SPEC 4), first of three separable passes (the binomial
// weights are a product w(di) w(dj) w(dk), and integer sums are exact, so the
// passes give the direct sum's result bit for bit): the weighted sum along x
// of the packed bit field (32 voxels per R32UI texel), one fragment per voxel.
layout(binding = 0) uniform usampler2DArray cld;
uniform int layer;
uniform int radius;
uniform ivec3 size;
layout(location = 0) out uint sum;  // R16UI: at most 16

void main() {
    const ivec2 p = ivec2(gl_FragCoord.xy);
    uint s = 0u;
    for (int di = -radius; di <= radius; ++di) {
        const int i = p.x + di;
        if (i < 0 || i >= size.x) continue;
        const uint bit = (texelFetch(cld, ivec3(i >> 5, p.y, layer), 0).r >> uint(i & 31)) & 1u;
        s += uint(SmoothWeight(radius, di)) * bit;
    }
    sum = s;
}
