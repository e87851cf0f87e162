#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `density`, occupancy by max-downsampling (thesis section 7.2.2): one
// fragment per tile. mode 0: the tile's columns in band `layer` of q (bands);
// mode 1: the tile's columns of D (tiles).
layout(binding = 0) uniform sampler2DArray q;
layout(binding = 1) uniform sampler2DArray d;
uniform int layer;
uniform int mode;
uniform ivec3 size;
uniform ivec2 tileBand;  // tile edge in columns, slices per band
layout(location = 0) out uint flag;

void main() {
    const ivec2 t = ivec2(gl_FragCoord.xy);
    const int i0 = t.x * tileBand.x, i1 = min(size.x, i0 + tileBand.x);
    const int j0 = t.y * tileBand.x, j1 = min(size.y, j0 + tileBand.x);
    float m = 0.0;
    if (mode == 1) {
        for (int j = j0; j < j1; ++j)
            for (int i = i0; i < i1; ++i) m = max(m, texelFetch(d, ivec3(i, j, 0), 0).r);
    } else {
        const int k1 = min(size.z, (layer + 1) * tileBand.y);
        for (int k = layer * tileBand.y; k < k1; ++k)
            for (int j = j0; j < j1; ++j)
                for (int i = i0; i < i1; ++i) m = max(m, texelFetch(q, ivec3(i, j, k), 0).r);
    }
    flag = m > 0.0 ? 1u : 0u;
}
