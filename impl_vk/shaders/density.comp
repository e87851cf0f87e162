#version 450
// Stage `density` (SPEC 5), columns: D = sum of q over k ascending (the order
// every backend sums in), and the cover count: columns with any cld = 1, or
// with D > 0 when the scene has no automaton (fromCld = 0; cld is then unused).
// One invocation per column: x = i, y = j; a dispatch covers the rows j of a
// share (SPEC 13) by its base workgroup.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Q { float q[]; };
layout(std430, binding = 1) readonly buffer Cld { uint cld[]; };
layout(std430, binding = 2) writeonly buffer D { float d[]; };
layout(std430, binding = 3) buffer Cover { uint covered; };
layout(push_constant) uniform Params { uint nx, ny, nz, words, fromCld; } pc;

void main() {
    const uint i = gl_GlobalInvocationID.x, j = gl_GlobalInvocationID.y;
    if (i >= pc.nx) return;
    const uint column = i + pc.nx * j;
    float sum = 0.0;
    uint any = 0u;
    for (uint k = 0u; k < pc.nz; ++k) {
        sum += q[column + pc.nx * pc.ny * k];
        if (pc.fromCld != 0u) any |= (cld[(i >> 5) + pc.words * (j + pc.ny * k)] >> (i & 31u)) & 1u;
    }
    if (pc.fromCld == 0u) any = sum > 0.0 ? 1u : 0u;
    d[column] = sum;
    if (any != 0u) atomicAdd(covered, 1u);
}
