#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
#include "ground.glsl"
// The ground pass of stage `render_splat` (core/math/ground.glsl): the full-screen
// triangle writes each pixel's background, the lit ground where the pixel's ray
// meets it, before the splats blend over it. The fragment at gl_FragCoord
// (x + 0.5, y + 0.5) is the image's pixel (x, y), as in render_march.frag.
layout(std140, binding = 1) uniform GroundBlock { GroundGpu ground; };
layout(binding = 3) uniform sampler2DArray groundShadow;  // G, (nx, ny, 1)
layout(location = 0) out vec4 colour;

float GroundFetchG(uint i, uint j) { return texelFetch(groundShadow, ivec3(i, j, 0), 0).r; }

void main() {
    colour = vec4(GroundBackground(ground, uint(gl_FragCoord.x), uint(gl_FragCoord.y)), 1.0);
}
