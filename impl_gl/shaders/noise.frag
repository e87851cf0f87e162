#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
#include "noise_words.glsl"
#include "noise.glsl"
// Stage `noise` (SPEC 10a): one fragment per voxel of slice `layer`, q =
// NoiseForm::Q by core/math/noise.glsl (prepended), reading the scene's data
// block (core/math/NoiseGpu.h) from a storage buffer and the step's offsets.
layout(std430, binding = 0) readonly buffer Data { uint data[]; };
uniform int layer;
uniform float offsets[8];
layout(location = 0) out float q;

uint NoiseWord(uint index) { return data[index]; }

void main() {
    float o[8];
    for (int n = 0; n < 8; ++n) o[n] = offsets[n];
    q = NoiseQ(o, uint(gl_FragCoord.x), uint(gl_FragCoord.y), uint(layer));
}
