#version 450
// Stage `noise` (SPEC 10a), one invocation per voxel: q = NoiseForm::Q by
// core/math/noise.glsl, reading the scene's data block (core/math/NoiseGpu.h) and
// the step's offsets.
#extension GL_GOOGLE_include_directive : require
#include "random.glsl"
#include "shading.glsl"
#include "noise_words.glsl"
#include "noise.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Data { uint data[]; };
layout(std430, binding = 1) writeonly buffer Q { float q[]; };
layout(push_constant) uniform Params { float offsets[8]; } pc;

uint NoiseWord(uint index) { return data[index]; }

void main() {
    const uint v = gl_GlobalInvocationID.x;
    const uint nx = data[kNoiseNx], ny = data[kNoiseNy], nz = data[kNoiseNz];
    if (v >= nx * ny * nz) return;
    float offsets[8];
    for (int n = 0; n < 8; ++n) offsets[n] = pc.offsets[n];
    q[v] = NoiseQ(offsets, v % nx, (v / nx) % ny, v / (nx * ny));
}
