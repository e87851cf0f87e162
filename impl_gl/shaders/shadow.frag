#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `shadow` (SPEC 7): one fragment per ground cell; D read bilinearly at
// the cell plus the offset to mid-height along the sun (0 outside).
layout(binding = 0) uniform sampler2DArray d;
uniform ivec2 size;
uniform ivec2 base;      // floor of the offset
uniform vec2 fraction;   // its fraction
uniform int form;        // ShadowForm: 0 beer exp(-k D), 1 thesis 1 - clamp(kappa D), 2 wang (Wang, Ji and Zhang, eq. 19)
uniform float opticalDepthPerD;
uniform float kappa;
uniform float coverage, densityFactor;  // wang
uniform int noSun;       // 1: G = 1
layout(location = 0) out float g;

float TapD(int i, int j) {
    if (i < 0 || j < 0 || i >= size.x || j >= size.y) return 0.0;
    return texelFetch(d, ivec3(i, j, 0), 0).r;
}

void main() {
    if (noSun != 0) {
        g = 1.0;
        return;
    }
    const ivec2 p = ivec2(gl_FragCoord.xy) + base;
    const float dd = Bilinear(TapD(p.x, p.y), TapD(p.x + 1, p.y), TapD(p.x, p.y + 1), TapD(p.x + 1, p.y + 1), fraction.x,
                              fraction.y);
    g = form == 2 ? WangShadow(opticalDepthPerD, coverage, densityFactor, dd)
                  : GroundShadow(form == 0 ? 1u : 0u, opticalDepthPerD, kappa, dd);
}
