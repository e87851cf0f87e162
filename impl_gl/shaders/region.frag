#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `region`: the quantised weight of one ellipsoid at the voxel centre,
// written as r/255 into an R8 UNORM slice (exactly r again) where MAX
// blending keeps the largest (quantising is monotone, so this is SPEC 2's
// quantised maximum).
layout(std430, binding = 0) readonly buffer Ellipsoids { float ellipsoid[]; };
flat in int instance;
flat in int slice;
layout(location = 0) out float region;

void main() {
    const int b = 8 * instance;
    const vec3 c = vec3(ellipsoid[b], ellipsoid[b + 1], ellipsoid[b + 2]);
    const vec3 axes = vec3(ellipsoid[b + 3], ellipsoid[b + 4], ellipsoid[b + 5]);
    const vec3 p = vec3(floor(gl_FragCoord.xy) + 0.5, float(slice) + 0.5);
    region = float(QuantizeRegion(EllipsoidWeight(c, axes, ellipsoid[b + 6], ellipsoid[b + 7], p))) / 255.0;
}
