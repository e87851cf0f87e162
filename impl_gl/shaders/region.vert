#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `region` (SPEC 2), the thesis's way: every ellipsoid that reaches
// slice `layer` is drawn as one quad (a 4-vertex strip, one instance per
// ellipsoid) over its bounding square in that slice, plus a voxel; the
// fragment pass evaluates the weight and MAX blending keeps the largest.
// LAYERED (with GL_ARB_shader_viewport_layer_array): one draw for slices
// layer0, layer0 + 1, ...: instance = (k - layer0) * count + ellipsoid, and the
// vertex stage picks layer k of the layered target.
layout(std430, binding = 0) readonly buffer Ellipsoids { float ellipsoid[]; };  // 8 floats each
#ifdef LAYERED
uniform int layer0;
uniform int count;  // ellipsoids
#else
uniform int layer;
#endif
uniform ivec2 size;  // nx, ny
flat out int instance;
flat out int slice;

void main() {
#ifdef LAYERED
    const int k = layer0 + gl_InstanceID / count, id = gl_InstanceID % count;
    gl_Layer = k;
#else
    const int k = layer, id = gl_InstanceID;
#endif
    const int b = 8 * id;
    const vec3 c = vec3(ellipsoid[b], ellipsoid[b + 1], ellipsoid[b + 2]);
    const vec3 axes = vec3(ellipsoid[b + 3], ellipsoid[b + 4], ellipsoid[b + 5]);
    instance = id;
    slice = k;
    if (abs(float(k) + 0.5 - c.z) > axes.z + 1.0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume: no fragments
        return;
    }
    const float reach = max(axes.x, axes.y) + 1.0;
    const vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
    const vec2 p = c.xy + corner * reach;
    gl_Position = vec4(p / vec2(size) * 2.0 - 1.0, 0.0, 1.0);
}
