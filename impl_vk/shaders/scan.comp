#version 450
// Exclusive prefix sum of n counts by one invocation: out[i] = sum of in[0..i),
// out[n] = the total. Used over chunk and tile counts (thousands of entries).
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer In { uint counts[]; };
layout(std430, binding = 1) writeonly buffer Out { uint offsets[]; };
layout(push_constant) uniform Params { uint n; } pc;

void main() {
    uint sum = 0u;
    for (uint i = 0u; i < pc.n; ++i) {
        offsets[i] = sum;
        sum += counts[i];
    }
    offsets[pc.n] = sum;
}
