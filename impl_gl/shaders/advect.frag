#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `ca`, advection (SPEC 3 step 4), packed layout:
// X'(i, j, k) = X(i - shift.x, j - shift.y, k), zero fill; one fragment per word.
layout(binding = 0) uniform usampler2DArray in0;
layout(binding = 1) uniform usampler2DArray in1;
layout(binding = 2) uniform usampler2DArray in2;
uniform int layer;
uniform ivec3 size;
uniform int words;
uniform ivec2 shift;  // (sx, sy) of this slice
layout(location = 0) out uint out0;
layout(location = 1) out uint out1;
layout(location = 2) out uint out2;

uvec3 WordsAt(int j, int w) {
    if (w < 0 || w >= words) return uvec3(0u);
    const ivec3 p = ivec3(w, j, layer);
    return uvec3(texelFetch(in0, p, 0).r, texelFetch(in1, p, 0).r, texelFetch(in2, p, 0).r);
}

void main() {
    const int w = int(gl_FragCoord.x), j = int(gl_FragCoord.y);
    const int sourceJ = j - shift.y;
    const uint rem = uint(size.x) % 32u;
    const uint mask = (w + 1 == words && rem != 0u) ? ((1u << rem) - 1u) : 0xFFFFFFFFu;
    uvec3 o = uvec3(0u);
    if (sourceJ >= 0 && sourceJ < size.y) {
        const int start = 32 * w - shift.x;
        const int word = start >> 5;  // floor division
        const int bitShift = start & 31;
        o = WordsAt(sourceJ, word);
        if (bitShift != 0) o = (o >> uint(bitShift)) | (WordsAt(sourceJ, word + 1) << uint(32 - bitShift));
        o &= uvec3(mask);
    }
    out0 = o.x;
    out1 = o.y;
    out2 = o.z;
}
