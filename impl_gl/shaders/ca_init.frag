#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `ca`, initial state (SPEC 3), packed layout: one fragment per 32-voxel
// word of slice `layer`, the three fields as three R32UI targets.
uniform int layer;
uniform ivec3 size;
uniform uint seed, qHum0, qAct0;
layout(location = 0) out uint hum;
layout(location = 1) out uint act;
layout(location = 2) out uint cld;

void main() {
    const uint w = uint(gl_FragCoord.x), row = uint(gl_FragCoord.y) + uint(size.y) * uint(layer);
    const uint keyHum = StreamKey(seed, 0xFFFFFFFFu, 1u), keyAct = StreamKey(seed, 0xFFFFFFFFu, 2u);
    const uint i0 = 32u * w, count = min(32u, uint(size.x) - i0), v0 = i0 + uint(size.x) * row;
    uvec3 s = uvec3(0u);
    for (uint b = 0u; b < count; ++b) s |= CaInitialVoxel(keyHum, keyAct, qHum0, qAct0, v0 + b) << b;
    hum = s.x;
    act = s.y;
    cld = s.z;
}
