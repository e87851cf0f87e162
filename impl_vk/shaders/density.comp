#version 450
// Stage `density` (SPEC 5), columns: D = sum of q over k ascending (the order
// every backend sums in), and the cover count: columns with any cld = 1, or
// with D > 0 when the scene has no automaton (fromCld = 0; cld is then unused).
// A dispatch covers the columns [first, end) (whole rows j: a share, SPEC 13).
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Q { float q[]; };
layout(std430, binding = 1) readonly buffer Cld { uint cld[]; };
layout(std430, binding = 2) writeonly buffer D { float d[]; };
layout(std430, binding = 3) buffer Cover { uint covered; };
// kRanged: the share variant (GetPipeline's ranged), which also tests the lower end.
layout(constant_id = 0) const bool kRanged = false;
layout(push_constant) uniform Params { uint nx, ny, nz, words, fromCld, first, end; } pc;

void main() {
    const uint column = gl_GlobalInvocationID.x;
    if (column >= pc.end || (kRanged && column < pc.first)) return;
    const uint i = column % pc.nx, j = column / pc.nx;
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
