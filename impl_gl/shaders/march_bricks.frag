#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `render_march`, step 2 (impl_cpu/RenderMarchCpu.cpp step 2): brick
// (a, b) of layer c is empty (1) iff q_alpha = 0 over the brick grown by one
// voxel, padded indices a B .. (a + 1) B + 1 (clamped to the padded volume).
// Each empty brick adds 1 to counters[8] (MarchStats.emptyBricks).
layout(binding = 0) uniform sampler2DArray volume;  // the padded (q_alpha, T) volume
layout(std430, binding = 3) buffer MarchBrickCounters { uint counters[]; };
uniform int layer;
uniform int brick;       // B
uniform ivec3 padded;    // px, py, pz
layout(location = 0) out uint empty;

void main() {
    const ivec3 lo = ivec3(ivec2(gl_FragCoord.xy), layer) * brick;
    const ivec3 hi = min(lo + brick + 1, padded - 1);
    bool isEmpty = true;
    for (int k = lo.z; k <= hi.z && isEmpty; ++k)
        for (int j = lo.y; j <= hi.y && isEmpty; ++j)
            for (int i = lo.x; i <= hi.x; ++i)
                if (texelFetch(volume, ivec3(i, j, k), 0).r != 0.0) {
                    isEmpty = false;
                    break;
                }
    empty = isEmpty ? 1u : 0u;
    if (isEmpty) atomicAdd(counters[8], 1u);
}
