#version 450
// Stage `ca` (SPEC 3): one invocation per 32-voxel word, bitwise rules
// (the thesis's section 9.2), random numbers only where an event can flip a bit.
// A dispatch covers the words [first, end) (whole slices: a share, SPEC 13).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_8bit_storage : require
#include "random.glsl"
#include "automaton.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer HumIn { uint humIn[]; };
layout(std430, binding = 1) readonly buffer ActIn { uint actIn[]; };
layout(std430, binding = 2) readonly buffer CldIn { uint cldIn[]; };
layout(std430, binding = 3) readonly buffer Region { uint8_t region[]; };
layout(std430, binding = 4) writeonly buffer HumOut { uint humOut[]; };
layout(std430, binding = 5) writeonly buffer ActOut { uint actOut[]; };
layout(std430, binding = 6) writeonly buffer CldOut { uint cldOut[]; };
// kRanged: the share variant (GetPipeline's ranged), which also tests the lower end.
layout(constant_id = 0) const bool kRanged = false;
layout(push_constant) uniform Params { uint nx, ny, nz, words, seed, step, qExt, qHum, qAct, first, end; } pc;

uint ActRow(uint w, int j, int k) {
    if (j < 0 || k < 0 || j >= int(pc.ny) || k >= int(pc.nz)) return 0u;
    return actIn[w + pc.words * (uint(j) + pc.ny * uint(k))];
}

void main() {
    const uint id = gl_GlobalInvocationID.x;
    if (id >= pc.end || (kRanged && id < pc.first)) return;
    const uint w = id % pc.words, row = id / pc.words;
    const int j = int(row % pc.ny), k = int(row / pc.ny);

    const uint a = actIn[id];
    const uint prev = w > 0u ? actIn[id - 1u] : 0u;
    const uint next = w + 1u < pc.words ? actIn[id + 1u] : 0u;
    uint f = CaRowNeighbours(a, prev, next);
    f |= ActRow(w, j + 1, k) | ActRow(w, j - 1, k) | ActRow(w, j + 2, k) | ActRow(w, j - 2, k);
    f |= ActRow(w, j, k + 1) | ActRow(w, j, k - 1) | ActRow(w, j, k - 2);

    const uvec3 grown = CaGrowth(uvec3(humIn[id], a, cldIn[id]), f);

    const CaEvents events = MakeCaEvents(pc.seed, pc.step, pc.qExt, pc.qHum, pc.qAct);
    const uint i0 = 32u * w, count = min(32u, pc.nx - i0), v0 = i0 + pc.nx * row;
    uvec3 s = uvec3(0u);  // bits past nx stay 0
    for (uint b = 0u; b < count; ++b) s |= CaVoxelEvents((grown >> b) & 1u, uint(region[v0 + b]), v0 + b, events) << b;
    humOut[id] = s.x;
    actOut[id] = s.y;
    cldOut[id] = s.z;
}
