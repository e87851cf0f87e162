// Stage `region` (SPEC 2), the thesis's way: every ellipsoid that reaches
// slice `layer` is drawn as one quad (a 4-vertex strip, one instance per
// ellipsoid) over its bounding square in that slice, plus a voxel; the
// fragment pass evaluates the weight and MAX blending keeps the largest.
layout(std430, binding = 0) readonly buffer Ellipsoids { float ellipsoid[]; };  // 8 floats each
uniform int layer;
uniform ivec2 size;  // nx, ny
flat out int instance;

void main() {
    const int b = 8 * gl_InstanceID;
    const vec3 c = vec3(ellipsoid[b], ellipsoid[b + 1], ellipsoid[b + 2]);
    const vec3 axes = vec3(ellipsoid[b + 3], ellipsoid[b + 4], ellipsoid[b + 5]);
    instance = gl_InstanceID;
    if (abs(float(layer) + 0.5 - c.z) > axes.z + 1.0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume: no fragments
        return;
    }
    const float reach = max(axes.x, axes.y) + 1.0;
    const vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
    const vec2 p = c.xy + corner * reach;
    gl_Position = vec4(p / vec2(size) * 2.0 - 1.0, 0.0, 1.0);
}
