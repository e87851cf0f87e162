#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `ca`, the thesis's layout (its Figure 4.1 texel): the three packed
// R32UI fields into one RGBA8UI texel per voxel, R = hum, G = act, B = cld.
layout(binding = 0) uniform usampler2DArray hum;
layout(binding = 1) uniform usampler2DArray act;
layout(binding = 2) uniform usampler2DArray cld;
uniform int layer;
layout(location = 0) out uvec4 state;

void main() {
    const ivec2 p = ivec2(gl_FragCoord.xy);
    const ivec3 word = ivec3(p.x >> 5, p.y, layer);
    const uint bit = uint(p.x & 31);
    state = uvec4((texelFetch(hum, word, 0).r >> bit) & 1u, (texelFetch(act, word, 0).r >> bit) & 1u,
                  (texelFetch(cld, word, 0).r >> bit) & 1u, 0u);
}
