#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `shade`: full-resolution T of slice `layer` from the w-major volume of
// the shaded grid, read trilinearly at (i + 0.5)/f - 0.5 clamped to the cell
// centres; at f = 1 each voxel's own value.
layout(binding = 0) uniform sampler2DArray shaded;  // layer = w index, texel = (u, v)
uniform int layer;
uniform ivec3 cells;   // shaded grid size in (x, y, z)
uniform ivec3 axes;    // u, v, w as axis numbers (0 x, 1 y, 2 z)
uniform int f;
layout(location = 0) out float T;

float At(int x, int y, int z) {
    const int c[3] = int[3](x, y, z);
    return texelFetch(shaded, ivec3(c[axes.x], c[axes.y], c[axes.z]), 0).r;
}

void main() {
    if (f == 1) {  // the same voxel: a copy (the trilinear weights would all be 0)
        T = At(int(gl_FragCoord.x), int(gl_FragCoord.y), layer);
        return;
    }
    int x0, x1, y0, y1, z0, z1;
    float tx, ty, tz;
    UpsampleTap(int(gl_FragCoord.x), f, cells.x, x0, x1, tx);
    UpsampleTap(int(gl_FragCoord.y), f, cells.y, y0, y1, ty);
    UpsampleTap(layer, f, cells.z, z0, z1, tz);
    const float b0 = Bilinear(At(x0, y0, z0), At(x0, y1, z0), At(x0, y0, z1), At(x0, y1, z1), ty, tz);
    const float b1 = Bilinear(At(x1, y0, z0), At(x1, y1, z0), At(x1, y0, z1), At(x1, y1, z1), ty, tz);
    T = Lerp(b0, b1, tx);
}
