#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `density`, cover: one fragment per column; a column with any cloud
// bit counts once in the atomic counter, or, in a scene without an automaton
// (fromCld = 0, cld unused), a column with D > 0. The colour output is the
// column's flag.
layout(binding = 0) uniform usampler2DArray cld;
layout(binding = 1) uniform sampler2DArray columnSum;
layout(binding = 0, offset = 0) uniform atomic_uint covered;
uniform int fromCld;
uniform ivec3 size;
layout(location = 0) out uint flag;

void main() {
    const ivec2 p = ivec2(gl_FragCoord.xy);
    uint any = 0u;
    if (fromCld != 0) {
        for (int k = 0; k < size.z; ++k) any |= (texelFetch(cld, ivec3(p.x >> 5, p.y, k), 0).r >> uint(p.x & 31)) & 1u;
    } else {
        any = texelFetch(columnSum, ivec3(p, 0), 0).r > 0.0 ? 1u : 0u;
    }
    if (any != 0u) atomicCounterIncrement(covered);
    flag = any;
}
