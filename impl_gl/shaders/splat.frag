#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "splat.glsl"
// Stage `render_splat`: one fragment of a point sprite. Keeps SPEC 8's
// coverage (px - s/2 <= x + 0.5 < px + s/2, likewise y) and gives the
// kernel-weighted alpha; blending (SRC_ALPHA, ONE_MINUS_SRC_ALPHA) composites.
// Unread: the fragment makes no splat (MakeSplat, which reads the table, is the vertex shader's).
float PhaseTableValue(uint i) { return 0.0; }

flat in vec4 colour;
flat in vec3 splat;
layout(location = 0) out vec4 result;

void main() {
    const vec2 pixel = gl_FragCoord.xy;  // (x + 0.5, y + 0.5), y counted from the top
    precise float halfSize = 0.5 * splat.z;
    if (!(splat.x - halfSize <= pixel.x && pixel.x < splat.x + halfSize && splat.y - halfSize <= pixel.y &&
          pixel.y < splat.y + halfSize))
        discard;
    const float a = SplatCoord(pixel.x, splat.x, splat.z), b = SplatCoord(pixel.y, splat.y, splat.z);
    result = vec4(colour.rgb, SplatAlpha(colour.a, a, b));
}
