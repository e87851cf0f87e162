#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `shade` at resolution f > 1: the mean of each f^3 block of q (partial
// blocks: of the voxels present); one fragment per coarse cell of layer K.
layout(binding = 0) uniform sampler2DArray q;
uniform int layer;
uniform ivec3 size;  // nx, ny, nz
uniform int f;
layout(location = 0) out float coarse;

void main() {
    const ivec3 c = ivec3(ivec2(gl_FragCoord.xy), layer);
    float sum = 0.0;
    int count = 0;
    for (int k = c.z * f; k < min(size.z, (c.z + 1) * f); ++k)
        for (int j = c.y * f; j < min(size.y, (c.y + 1) * f); ++j)
            for (int i = c.x * f; i < min(size.x, (c.x + 1) * f); ++i, ++count) sum += texelFetch(q, ivec3(i, j, k), 0).r;
    coarse = sum / float(count);
}
