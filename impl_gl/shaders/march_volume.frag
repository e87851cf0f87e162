#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `render_march`, step 1 (impl_cpu/RenderMarchCpu.cpp step 1): layer k
// of the padded (q_alpha, T) volume, one fragment per padded (i, j): voxel
// (i - 1, j - 1, k - 1) inside the grid, else the border (0, 1), or with `wrap`
// (tiling) the opposite edge's voxel in x and y (core/math/March.h
// PaddedSourceVoxel).
layout(binding = 0) uniform sampler2DArray qPrev;
layout(binding = 1) uniform sampler2DArray qCur;
layout(binding = 2) uniform sampler2DArray transmittance;  // read only when hasT != 0
uniform int layer;
uniform ivec3 grid;  // nx, ny, nz
uniform float alpha;
uniform int hasT;
uniform int wrap;
layout(location = 0) out vec2 qt;

void main() {
    ivec3 v = ivec3(ivec2(gl_FragCoord.xy), layer) - 1;
    if (wrap != 0) {
        // Padded 0 and n + 1 stand for voxels n - 1 and 0.
        if (v.x == -1) v.x = grid.x - 1;
        if (v.x == grid.x) v.x = 0;
        if (v.y == -1) v.y = grid.y - 1;
        if (v.y == grid.y) v.y = 0;
    }
    if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, grid))) {
        qt = vec2(0.0, 1.0);
        return;
    }
    const float q = Lerp(texelFetch(qPrev, v, 0).r, texelFetch(qCur, v, 0).r, alpha);
    qt = vec2(q, hasT != 0 ? texelFetch(transmittance, v, 0).r : 1.0);
}
