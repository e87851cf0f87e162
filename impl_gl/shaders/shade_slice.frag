#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
// Stage `shade` (SPEC 6): one slice m of the inverse shear-warp, one fragment
// per (u, v). T_{m-1} comes from a 2-D texture and T_m goes to the other
// (the thesis's ping-pong, its Figure 4.3) and to layer w of a w-major volume.
// Taps outside the previous slice read T = 1, q = 0.
layout(binding = 0) uniform sampler2D previousT;
layout(binding = 1) uniform sampler2DArray q;  // z-layered (the grid being shaded)
uniform ivec3 axisU, axisV;  // unit vectors of u and v in (x, y, z)
uniform ivec3 previousW;     // the previous slice's w index times the unit vector of w
uniform ivec2 sliceSize;     // nu, nv
uniform ivec2 tapOffset;     // u0, v0
uniform vec2 tapFraction;    // fu, fv
uniform int first;           // 1: the slice nearest the sun (T = 1)
uniform int beer;            // 1: beer, 0: thesis
uniform float depthPerQ, thesisAr, scatterGain;
uniform uint storage;
layout(location = 0) out float nextT;
layout(location = 1) out float volumeT;

float TapT(int a, int b) {
    if (a < 0 || b < 0 || a >= sliceSize.x || b >= sliceSize.y) return 1.0;
    return texelFetch(previousT, ivec2(a, b), 0).r;
}
float TapQ(int a, int b) {
    if (a < 0 || b < 0 || a >= sliceSize.x || b >= sliceSize.y) return 0.0;
    return texelFetch(q, a * axisU + b * axisV + previousW, 0).r;
}

void main() {
    if (first != 0) {
        nextT = 1.0;
        volumeT = 1.0;
        return;
    }
    const int ua = int(gl_FragCoord.x) + tapOffset.x, vb = int(gl_FragCoord.y) + tapOffset.y;
    const float fu = tapFraction.x, fv = tapFraction.y;
    const float tt = Bilinear(TapT(ua, vb), TapT(ua + 1, vb), TapT(ua, vb + 1), TapT(ua + 1, vb + 1), fu, fv);
    const float qs = Bilinear(TapQ(ua, vb), TapQ(ua + 1, vb), TapQ(ua, vb + 1), TapQ(ua + 1, vb + 1), fu, fv);
    nextT = StoreTransmittance(storage, tt, SliceFactor(uint(beer), depthPerQ, thesisAr, scatterGain, qs));
    volumeT = nextT;
}
