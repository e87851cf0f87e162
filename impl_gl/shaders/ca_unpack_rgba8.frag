#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `ca`, the thesis's layout: RGBA8UI voxels back to the three packed
// R32UI fields the other stages read; one fragment per 32-voxel word. With
// SHIFTED defined (a share of a step with wind), the advection is folded in:
// voxel i of the word reads state (i - shift.x, j - shift.y), zero outside.
layout(binding = 0) uniform usampler2DArray state;
uniform int layer;
uniform ivec3 size;
#ifdef SHIFTED
uniform ivec2 shift;
#endif
layout(location = 0) out uint hum;
layout(location = 1) out uint act;
layout(location = 2) out uint cld;

void main() {
    const int i0 = 32 * int(gl_FragCoord.x), j = int(gl_FragCoord.y);
    const int count = min(32, size.x - i0);
    uvec3 bits = uvec3(0u);
#ifdef SHIFTED
    const int sj = j - shift.y;
    if (sj >= 0 && sj < size.y)
        for (int b = 0; b < count; ++b) {
            const int si = i0 + b - shift.x;
            if (si >= 0 && si < size.x) bits |= (texelFetch(state, ivec3(si, sj, layer), 0).rgb & 1u) << uint(b);
        }
#else
    for (int b = 0; b < count; ++b) bits |= (texelFetch(state, ivec3(i0 + b, j, layer), 0).rgb & 1u) << uint(b);
#endif
    hum = bits.x;
    act = bits.y;
    cld = bits.z;
}
