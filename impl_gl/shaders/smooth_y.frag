#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `smooth`, second pass: the weighted sum along y of the x sums.
layout(binding = 0) uniform usampler2DArray sumX;
uniform int layer;
uniform int radius;
uniform ivec3 size;
layout(location = 0) out uint sum;  // R16UI: at most 256

void main() {
    const ivec2 p = ivec2(gl_FragCoord.xy);
    uint s = 0u;
    for (int dj = -radius; dj <= radius; ++dj) {
        const int j = p.y + dj;
        if (j >= 0 && j < size.y) s += uint(SmoothWeight(radius, dj)) * texelFetch(sumX, ivec3(p.x, j, layer), 0).r;
    }
    sum = s;
}
