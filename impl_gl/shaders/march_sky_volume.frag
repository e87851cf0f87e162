#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// The sky light's padded T_sky volume (march.glsl's MarchFetchSkyT; impl_cpu/PaddedVolumeCpu.h), layer k, as
// march_volume.frag forms the (q_alpha, T) one: one fragment per padded (i, j), voxel (i - 1, j - 1, k - 1)
// inside the grid, else the border 1, or with `wrap` (tiling) the opposite edge's voxel in x and y (core/math/March.h
// PaddedSourceVoxel).
layout(binding = 0) uniform sampler2DArray skyTransmittance;
uniform int layer;
uniform ivec3 grid;  // nx, ny, nz
uniform int wrap;
layout(location = 0) out float tSky;

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
        tSky = 1.0;
        return;
    }
    tSky = texelFetch(skyTransmittance, v, 0).r;
}
