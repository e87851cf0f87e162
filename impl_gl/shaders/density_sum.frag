#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `density` (SPEC 5), the thesis's way (section 7.2.2): slice `layer`
// of q is drawn into D with additive blending, slices in ascending k, so D
// accumulates the same sums in the same order as every other backend.
layout(binding = 0) uniform sampler2DArray q;
uniform int layer;
layout(location = 0) out float value;

void main() { value = texelFetch(q, ivec3(ivec2(gl_FragCoord.xy), layer), 0).r; }
