#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "march.glsl"
#include "shafts.glsl"
// Shafts of light (SPEC 18) over a renderer's frame: the full-screen triangle,
// one fragment per pixel, writes the frame's pixel plus ShaftsPixel of
// core/math/shafts.glsl. The fragment at gl_FragCoord (x + 0.5, y + 0.5) is
// the image's pixel (x, y), as in render_march.frag.
layout(std140, binding = 0) uniform ShaftsBlock { ShaftsFrame shafts; };
layout(binding = 3) uniform sampler2DArray columnSum;  // D, (nx, ny, 1)
layout(binding = 4) uniform sampler2DArray frame;      // the renderer's (3, width, height) image
layout(location = 0) out vec4 colour;

float ShaftsFetchD(uint i, uint j) { return texelFetch(columnSum, ivec3(i, j, 0), 0).r; }
// march.glsl's inputs: never read here.
vec2 MarchFetchQT(uint paddedIndex) { return vec2(0.0); }
float MarchFetchSkyT(uint paddedIndex) { return 0.0; }
bool MarchBrickEmpty(uint brick) { return false; }
float PhaseTableValue(uint i) { return 0.0; }

void main() {
    const uint x = uint(gl_FragCoord.x), y = uint(gl_FragCoord.y);
    const vec3 light = ShaftsPixel(shafts, x, y);
    precise vec3 sum;
    for (int c = 0; c < 3; ++c) sum[c] = texelFetch(frame, ivec3(c, x, y), 0).r + light[c];
    colour = vec4(sum, 1.0);
}
