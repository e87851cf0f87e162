#version 450
// One pass of a stable least-significant-digit radix sort of (key, value)
// pairs on the 8-bit digit (key >> shift) & 255. Invocation b owns the block
// of pairs [b * block, (b + 1) * block) and column b of counts (digit-major:
// counts[digit * blocks + b]), and walks its block in order, so the sort is
// stable and deterministic with no atomics. mode 0: count the block's digits
// into binding 2; the host then scans them (scan.comp) into each (digit,
// block)'s first output slot; mode 1, with that scan at binding 2: scatter
// the block's pairs from those slots on.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer KeysIn { uint keysIn[]; };
layout(std430, binding = 1) readonly buffer ValuesIn { uint valuesIn[]; };
layout(std430, binding = 2) buffer Counts { uint counts[]; };  // 256 x blocks (+ 1 scanned)
layout(std430, binding = 3) writeonly buffer KeysOut { uint keysOut[]; };
layout(std430, binding = 4) writeonly buffer ValuesOut { uint valuesOut[]; };
layout(push_constant) uniform Params { uint n, shift, block, blocks, mode; } pc;

void main() {
    const uint b = gl_GlobalInvocationID.x;
    if (b >= pc.blocks) return;
    const uint first = b * pc.block, last = min(pc.n, first + pc.block);
    if (pc.mode == 0u) {
        for (uint d = 0u; d < 256u; ++d) counts[d * pc.blocks + b] = 0u;
        for (uint i = first; i < last; ++i) counts[((keysIn[i] >> pc.shift) & 255u) * pc.blocks + b] += 1u;
        return;
    }
    for (uint i = first; i < last; ++i) {
        const uint key = keysIn[i], slot = ((key >> pc.shift) & 255u) * pc.blocks + b;
        const uint to = counts[slot];
        counts[slot] = to + 1u;
        keysOut[to] = key;
        valuesOut[to] = valuesIn[i];
    }
}
