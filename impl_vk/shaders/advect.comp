#version 450
// Stage `ca`, advection (SPEC 3 step 4): X'(i, j, k) = X(i - sx[k], j - sy[k], k), zero fill.
// A dispatch covers the words [first, end) (whole slices: a share, SPEC 13).
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In0 { uint in0[]; };
layout(std430, binding = 1) readonly buffer In1 { uint in1[]; };
layout(std430, binding = 2) readonly buffer In2 { uint in2[]; };
layout(std430, binding = 3) writeonly buffer Out0 { uint out0[]; };
layout(std430, binding = 4) writeonly buffer Out1 { uint out1[]; };
layout(std430, binding = 5) writeonly buffer Out2 { uint out2[]; };
layout(std430, binding = 6) readonly buffer Shifts { ivec2 shift[]; };  // (sx, sy) per slice
// kRanged: the share variant (GetPipeline's ranged), which also tests the lower end.
layout(constant_id = 0) const bool kRanged = false;
layout(push_constant) uniform Params { uint nx, ny, words, first, end; } pc;

uint WordAt(uint field, int row, int w) {
    if (w < 0 || w >= int(pc.words)) return 0u;
    const uint index = uint(w) + pc.words * uint(row);
    return field == 0u ? in0[index] : (field == 1u ? in1[index] : in2[index]);
}

// Bits [start, start + 32) of a source row; 0 outside.
uint BitsAt(uint field, int row, int start) {
    const int word = start >> 5;  // floor division
    const int shift = start & 31;
    if (shift == 0) return WordAt(field, row, word);
    return (WordAt(field, row, word) >> shift) | (WordAt(field, row, word + 1) << (32 - shift));
}

void main() {
    const uint id = gl_GlobalInvocationID.x;
    if (id >= pc.end || (kRanged && id < pc.first)) return;
    const uint w = id % pc.words, row = id / pc.words;
    const uint j = row % pc.ny, k = row / pc.ny;
    const ivec2 s = shift[k];
    const int sourceJ = int(j) - s.y;
    const uint rem = pc.nx % 32u;
    const uint mask = (w + 1u == pc.words && rem != 0u) ? ((1u << rem) - 1u) : 0xFFFFFFFFu;
    uint o0 = 0u, o1 = 0u, o2 = 0u;
    if (sourceJ >= 0 && sourceJ < int(pc.ny)) {
        const int sourceRow = sourceJ + int(pc.ny * k);
        const int start = int(32u * w) - s.x;
        o0 = BitsAt(0u, sourceRow, start) & mask;
        o1 = BitsAt(1u, sourceRow, start) & mask;
        o2 = BitsAt(2u, sourceRow, start) & mask;
    }
    out0[id] = o0;
    out1[id] = o1;
    out2[id] = o2;
}
