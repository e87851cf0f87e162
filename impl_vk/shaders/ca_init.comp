#version 450
// Stage `ca`, initial state (SPEC 3): one invocation per 32-voxel word.
#extension GL_GOOGLE_include_directive : require
#include "random.glsl"
#include "automaton.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) writeonly buffer Hum { uint hum[]; };
layout(std430, binding = 1) writeonly buffer Act { uint act[]; };
layout(std430, binding = 2) writeonly buffer Cld { uint cld[]; };
layout(push_constant) uniform Params { uint nx, ny, nz, words, seed, qHum0, qAct0; } pc;

void main() {
    const uint id = gl_GlobalInvocationID.x;
    if (id >= pc.words * pc.ny * pc.nz) return;
    const uint w = id % pc.words, row = id / pc.words;
    const uint keyHum = StreamKey(pc.seed, 0xFFFFFFFFu, 1u), keyAct = StreamKey(pc.seed, 0xFFFFFFFFu, 2u);
    const uint i0 = 32u * w, count = min(32u, pc.nx - i0), v0 = i0 + pc.nx * row;
    uvec3 s = uvec3(0u);
    for (uint b = 0u; b < count; ++b) s |= CaInitialVoxel(keyHum, keyAct, pc.qHum0, pc.qAct0, v0 + b) << b;
    hum[id] = s.x;
    act[id] = s.y;
    cld[id] = s.z;
}
