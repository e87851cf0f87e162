#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `ca` (SPEC 3), packed layout (the thesis's section 9.2): one fragment
// per 32-voxel word of slice `layer`; bitwise rules, random numbers drawn only
// where an event can flip a bit. Reads the step-t textures, writes step t+1
// (before advection) into three R32UI targets.
layout(binding = 0) uniform usampler2DArray humIn;
layout(binding = 1) uniform usampler2DArray actIn;
layout(binding = 2) uniform usampler2DArray cldIn;
layout(binding = 3) uniform usampler2DArray region;  // R8UI, one texel per voxel
uniform int layer;
uniform ivec3 size;   // nx, ny, nz
uniform int words;    // ceil(nx / 32)
uniform uint seed, step, qExt, qHum, qAct;
layout(location = 0) out uint humOut;
layout(location = 1) out uint actOut;
layout(location = 2) out uint cldOut;

uint ActWord(int w, int j, int k) {
    if (w < 0 || w >= words || j < 0 || k < 0 || j >= size.y || k >= size.z) return 0u;
    return texelFetch(actIn, ivec3(w, j, k), 0).r;
}

void main() {
    const int w = int(gl_FragCoord.x), j = int(gl_FragCoord.y), k = layer;
    const uint a = ActWord(w, j, k);
    uint f = CaRowNeighbours(a, ActWord(w - 1, j, k), ActWord(w + 1, j, k));
    f |= ActWord(w, j + 1, k) | ActWord(w, j - 1, k) | ActWord(w, j + 2, k) | ActWord(w, j - 2, k);
    f |= ActWord(w, j, k + 1) | ActWord(w, j, k - 1) | ActWord(w, j, k - 2);

    const uint h = texelFetch(humIn, ivec3(w, j, k), 0).r, c = texelFetch(cldIn, ivec3(w, j, k), 0).r;
    const uvec3 grown = CaGrowth(uvec3(h, a, c), f);

    const CaEvents events = MakeCaEvents(seed, step, qExt, qHum, qAct);
    const uint i0 = 32u * uint(w), count = min(32u, uint(size.x) - i0);
    const uint v0 = i0 + uint(size.x) * (uint(j) + uint(size.y) * uint(k));
    uvec3 next = uvec3(0u);  // bits past nx stay 0
    for (uint b = 0u; b < count; ++b) {
        const uint r = texelFetch(region, ivec3(int(i0 + b), j, k), 0).r;
        next |= CaVoxelEvents((grown >> b) & 1u, r, v0 + b, events) << b;
    }
    humOut = next.x;
    actOut = next.y;
    cldOut = next.z;
}
