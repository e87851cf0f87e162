#version 450
// Shafts of light (SPEC 18) over a renderer's frame: one invocation per pixel
// in 8 x 8 workgroups adds ShaftsPixel of core/math/shafts.glsl to the image.
#extension GL_GOOGLE_include_directive : require
#include "random.glsl"
#include "shading.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "march.glsl"
#include "shafts.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 0) readonly buffer Frame { ShaftsFrame shafts; };
layout(std430, binding = 1) readonly buffer D { float columnSum[]; };  // (nx, ny, 1)
layout(std430, binding = 2) buffer Image { float image[]; };           // (3, width, height)

float ShaftsFetchD(uint i, uint j) { return columnSum[i + shafts.gridX * j]; }
// march.glsl's inputs: never read here.
vec2 MarchFetchQT(uint paddedIndex) { return vec2(0.0); }
float MarchFetchSkyT(uint paddedIndex) { return 0.0; }
bool MarchBrickEmpty(uint brick) { return false; }
float PhaseTableValue(uint i) { return 0.0; }

void main() {
    const uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    if (x >= shafts.width || y >= shafts.height) return;
    const vec3 light = ShaftsPixel(shafts, x, y);
    const uint base = 3u * (x + shafts.width * y);
    for (uint c = 0u; c < 3u; ++c) {
        precise float sum = image[base + c] + light[c];
        image[base + c] = sum;
    }
}
