#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `smooth`, third pass: the weighted sum along z of the xy sums, scaled
// by 1/W (exact: W is a power of two).
layout(binding = 0) uniform usampler2DArray sumXY;
uniform int layer;
uniform int radius;
uniform ivec3 size;
uniform float invW;
layout(location = 0) out float q;

void main() {
    const ivec2 p = ivec2(gl_FragCoord.xy);
    uint s = 0u;
    for (int dk = -radius; dk <= radius; ++dk) {
        const int k = layer + dk;
        if (k >= 0 && k < size.z) s += uint(SmoothWeight(radius, dk)) * texelFetch(sumXY, ivec3(p, k), 0).r;
    }
    q = float(s) * invW;
}
