#version 450
// Exclusive prefix sum of n counts: out[i] = sum of in[0..i), out[n] = the
// total. In blocks of 256, so that no invocation loops long: lavapipe ends
// an invocation's loops, silently, after 65535 iterations in all, and a GPU
// runs a long serial loop slowly. mode 0: invocation b sums block b into
// sums[b]; mode 1: one invocation turns sums[0 .. blocks) into exclusive
// offsets and writes out[n]; mode 2: invocation b writes block b's offsets.
// n may be up to 256 x 65535 (the single loop of mode 1).
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { uint counts[]; };
layout(std430, binding = 1) writeonly buffer Out { uint offsets[]; };
layout(std430, binding = 2) buffer Sums { uint sums[]; };
layout(push_constant) uniform Params { uint n, mode; } pc;

const uint kBlock = 256u;

void main() {
    const uint b = gl_GlobalInvocationID.x, blocks = (pc.n + kBlock - 1u) / kBlock;
    if (pc.mode == 1u) {
        if (b != 0u) return;
        uint sum = 0u;
        for (uint i = 0u; i < blocks; ++i) {
            const uint s = sums[i];
            sums[i] = sum;
            sum += s;
        }
        offsets[pc.n] = sum;
        return;
    }
    if (b >= blocks) return;
    const uint first = b * kBlock, last = min(pc.n, first + kBlock);
    uint sum = pc.mode == 0u ? 0u : sums[b];
    for (uint i = first; i < last; ++i) {
        if (pc.mode == 2u) offsets[i] = sum;
        sum += counts[i];
    }
    if (pc.mode == 0u) sums[b] = sum;
}
