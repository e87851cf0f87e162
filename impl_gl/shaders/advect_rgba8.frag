#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `ca`, advection (SPEC 3 step 4), the thesis's layout:
// X'(i, j, k) = X(i - shift.x, j - shift.y, k), zero fill; one fragment per voxel.
layout(binding = 0) uniform usampler2DArray state;
uniform int layer;
uniform ivec3 size;
uniform ivec2 shift;
layout(location = 0) out uvec4 next;

void main() {
    const ivec2 source = ivec2(gl_FragCoord.xy) - shift;
    const bool inside = source.x >= 0 && source.y >= 0 && source.x < size.x && source.y < size.y;
    next = inside ? texelFetch(state, ivec3(source, layer), 0) : uvec4(0u);
}
