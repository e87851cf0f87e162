#version 450
// Stage `ca` (SPEC 3): one invocation per 32-voxel word, bitwise rules
// (the thesis's section 9.2), random numbers only where an event can flip a bit.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_8bit_storage : require
#include "random.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer HumIn { uint humIn[]; };
layout(std430, binding = 1) readonly buffer ActIn { uint actIn[]; };
layout(std430, binding = 2) readonly buffer CldIn { uint cldIn[]; };
layout(std430, binding = 3) readonly buffer Region { uint8_t region[]; };
layout(std430, binding = 4) writeonly buffer HumOut { uint humOut[]; };
layout(std430, binding = 5) writeonly buffer ActOut { uint actOut[]; };
layout(std430, binding = 6) writeonly buffer CldOut { uint cldOut[]; };
layout(push_constant) uniform Params { uint nx, ny, nz, words, seed, step, qExt, qHum, qAct; } pc;

uint ActRow(uint w, int j, int k) {
    if (j < 0 || k < 0 || j >= int(pc.ny) || k >= int(pc.nz)) return 0u;
    return actIn[w + pc.words * (uint(j) + pc.ny * uint(k))];
}

void main() {
    const uint id = gl_GlobalInvocationID.x;
    if (id >= pc.words * pc.ny * pc.nz) return;
    const uint w = id % pc.words, row = id / pc.words;
    const int j = int(row % pc.ny), k = int(row / pc.ny);

    const uint a = actIn[id];
    const uint prev = w > 0u ? actIn[id - 1u] : 0u;
    const uint next = w + 1u < pc.words ? actIn[id + 1u] : 0u;
    uint f = ((a << 1) | (prev >> 31)) | ((a >> 1) | (next << 31)) | ((a << 2) | (prev >> 30)) | ((a >> 2) | (next << 30));
    f |= ActRow(w, j + 1, k) | ActRow(w, j - 1, k) | ActRow(w, j + 2, k) | ActRow(w, j - 2, k);
    f |= ActRow(w, j, k + 1) | ActRow(w, j, k - 1) | ActRow(w, j, k - 2);

    const uint h = humIn[id], c = cldIn[id];
    const uint hum1 = h & ~a, cld1 = c | a, act1 = ~a & h & f;

    const uint keyExt = StreamKey(pc.seed, pc.step, 0u);
    const uint keyHum = StreamKey(pc.seed, pc.step, 1u);
    const uint keyAct = StreamKey(pc.seed, pc.step, 2u);
    const uint i0 = 32u * w, count = min(32u, pc.nx - i0), v0 = i0 + pc.nx * row;
    uint inRegion = 0u, ext = 0u, hum = 0u, act = 0u;
    for (uint b = 0u; b < count; ++b) {
        const uint r = uint(region[v0 + b]);
        if (r == 0u) continue;  // P_hum = P_act = 0 and cld is cleared: nothing to draw
        const uint bit = 1u << b;
        inRegion |= bit;
        if ((cld1 & bit) != 0u && pc.qExt != 0u && RegionEventFires(Rand24FromKey(keyExt, v0 + b), 255u - r, pc.qExt)) ext |= bit;
        if ((hum1 & bit) == 0u && pc.qHum != 0u && RegionEventFires(Rand24FromKey(keyHum, v0 + b), r, pc.qHum)) hum |= bit;
        if ((act1 & bit) == 0u && pc.qAct != 0u && RegionEventFires(Rand24FromKey(keyAct, v0 + b), r, pc.qAct)) act |= bit;
    }
    humOut[id] = hum1 | hum;
    actOut[id] = act1 | act;
    cldOut[id] = cld1 & inRegion & ~ext;
}
