#version 450
// Exclusive prefix sum of n counts: out[i] = sum of in[0..i), out[n] = the
// total. In blocks of 256, so that no invocation loops long: lavapipe ends
// an invocation's loops, silently, after 65535 iterations in all, and a GPU
// runs a long serial loop at memory latency. mode 0: invocation b sums block
// b into sums[b]; mode 1: one workgroup turns sums[0 .. blocks) into
// exclusive offsets, 256 at a time (4 per invocation, then a scan of the 64
// partial sums in shared memory), and writes out[n]; mode 2: invocation b
// writes block b's offsets. Integer sums: the same bits in any order.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { uint counts[]; };
layout(std430, binding = 1) writeonly buffer Out { uint offsets[]; };
layout(std430, binding = 2) buffer Sums { uint sums[]; };
layout(push_constant) uniform Params { uint n, mode; } pc;

const uint kBlock = 256u;
shared uint partial[64];

void main() {
    const uint b = gl_GlobalInvocationID.x, blocks = (pc.n + kBlock - 1u) / kBlock;
    if (pc.mode == 1u) {
        if (gl_WorkGroupID.x != 0u) return;
        const uint lane = gl_LocalInvocationID.x;
        uint carry = 0u;  // the sums before this round
        for (uint base = 0u; base < blocks; base += 256u) {
            uint v[4], own = 0u;
            for (uint k = 0u; k < 4u; ++k) {
                const uint i = base + 4u * lane + k;
                v[k] = i < blocks ? sums[i] : 0u;
                own += v[k];
            }
            partial[lane] = own;
            barrier();
            for (uint d = 1u; d < 64u; d <<= 1u) {  // inclusive scan of the 64 lanes' sums
                const uint add = lane >= d ? partial[lane - d] : 0u;
                barrier();
                partial[lane] += add;
                barrier();
            }
            uint running = carry + (lane > 0u ? partial[lane - 1u] : 0u);
            for (uint k = 0u; k < 4u; ++k) {
                const uint i = base + 4u * lane + k;
                if (i < blocks) sums[i] = running;
                running += v[k];
            }
            carry += partial[63];
            barrier();  // every lane has read partial before the next round writes it
        }
        if (lane == 0u) offsets[pc.n] = carry;
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
