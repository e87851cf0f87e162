// GLSL twin of core/math/Shading.h (SPEC 6-9): exp, storage rounding, phase
// functions, bilinear blend. Must stay in step with the C++.
#ifndef CLOUDBENCH_SHADING_GLSL
#define CLOUDBENCH_SHADING_GLSL

const float kTransmittanceFloor = 1e-30;

// exp(x) for x <= 0, the same range reduction and polynomial as the CPU.
float ExpNonPositive(float xIn) {
    const bool underflows = xIn < -87.0;
    precise float x = max(xIn, -87.0);
    precise float k = roundEven(x * 1.44269504088896341);
    precise float r = x - k * 0.693145751953125;
    r = r - k * 1.42860682030941723212e-6;
    precise float p = 1.0 / 5040.0;
    p = p * r + 1.0 / 720.0;
    p = p * r + 1.0 / 120.0;
    p = p * r + 1.0 / 24.0;
    p = p * r + 1.0 / 6.0;
    p = p * r + 0.5;
    p = p * r + 1.0;
    p = p * r + 1.0;
    precise float result = p * uintBitsToFloat(uint(int(k) + 127) << 23);
    return underflows ? 0.0 : result;
}

// Nearest half, ties to even (same bit arithmetic as core/math/Shading.h RoundToHalf).
float RoundToHalf(float value) {
    const uint bits = floatBitsToUint(value);
    const uint sign = bits & 0x80000000u;
    const uint magnitude = bits & 0x7fffffffu;
    if (magnitude >= 0x477ff000u) return uintBitsToFloat(sign | 0x7f800000u);
    if (magnitude < 0x38800000u) {
        const float scaled = roundEven(abs(value) * 16777216.0);
        return sign != 0u ? -scaled / 16777216.0 : scaled / 16777216.0;
    }
    const uint lsb = (magnitude >> 13) & 1u;
    const uint rounded = (magnitude + 0x0fffu + lsb) & ~0x1fffu;
    return uintBitsToFloat(sign | rounded);
}

float RoundToUnorm8(float value) { return roundEven(clamp(value, 0.0, 1.0) * 255.0) / 255.0; }

// storage: 0 fp32, 1 fp16, 2 unorm8.
float RoundToStorage(uint storage, float value) {
    if (storage == 1u) return RoundToHalf(value);
    if (storage == 2u) return RoundToUnorm8(value);
    return value;
}

// a (1 - t) + b t, unfused (core/math/Shading.h Lerp).
float Lerp(float a, float b, float t) {
    precise float result = a * (1.0 - t) + b * t;
    return result;
}

// t00 at (0,0), t10 at (1,0), t01 at (0,1), t11 at (1,1) (core/math/Shading.h Bilinear).
float Bilinear(float t00, float t10, float t01, float t11, float fu, float fv) {
    return Lerp(Lerp(t00, t10, fu), Lerp(t01, t11, fu), fv);
}

// The factor by which light is multiplied crossing a slice of density q (SPEC 6),
// clamped to [0, 1] (core/math/Shading.h SliceFactor). beer: 1 beer, 0 thesis.
float SliceFactor(uint beer, float depthPerQ, float thesisAr, float scatterGain, float q) {
    precise float tau = depthPerQ * q;
    precise float a = beer != 0u ? ExpNonPositive(-tau) : 1.0 - (1.0 - thesisAr) * q;
    precise float result = clamp(a + scatterGain * tau, 0.0, 1.0);
    return result;
}

// T of a slice as stored: the product rounded to its storage, and 0 below the
// floor (core/math/Shading.h StoreTransmittance).
float StoreTransmittance(uint storage, float previousT, float factor) {
    precise float product = previousT * factor;
    const float value = RoundToStorage(storage, product);
    return value < kTransmittanceFloor ? 0.0 : value;
}

// Ground shadow G from the column sum D along the sun (SPEC 7, core/math/Shading.h GroundShadow).
float GroundShadow(uint beer, float opticalDepthPerD, float kappa, float d) {
    precise float depth = -opticalDepthPerD * d;
    precise float thesis = 1.0 - clamp(kappa * d, 0.0, 1.0);
    return beer != 0u ? ExpNonPositive(depth) : thesis;
}

// Wang's ground shadow, Wang, Ji and Zhang, eq. 19 (core/math/Shading.h WangShadow): T_S is the
// column's opacity along the sun, T_2D = 0, C = coverage, D_w = densityFactor.
float WangShadow(float opticalDepthPerD, float coverage, float densityFactor, float d) {
    precise float depth = -opticalDepthPerD * d;
    precise float shadowTexture = 1.0 - ExpNonPositive(depth);
    const float modulation = 0.0;
    precise float excess = max(shadowTexture - (modulation + 1.0 - coverage), 0.0);
    precise float s = 1.0 - densityFactor * excess;
    return s;
}

// Where fine voxel i reads a grid of `cells` coarse cells (f fine voxels each):
// coordinate (i + 0.5)/f - 0.5 clamped to the centres, taps i0 and i1, weight w
// (core/math/Shading.h UpsampleTap).
void UpsampleTap(int i, int f, int cells, out int i0, out int i1, out float w) {
    precise float x = clamp((float(i) + 0.5) / float(f) - 0.5, 0.0, float(cells - 1));
    i0 = int(x);
    i1 = min(i0 + 1, cells - 1);
    w = x - float(i0);
}

// core/math/Shading.h HenyeyGreenstein: (1 - g^2) / (1 + g^2 - 2 g cos)^1.5.
float HenyeyGreenstein(float g, float cosTheta) {
    precise float denom = 1.0 + g * g - 2.0 * g * cosTheta;
    precise float hg = (1.0 - g * g) / (denom * sqrt(denom));
    return hg;
}

// core/math/Shading.h PhaseValue's dual lobe: (1 - blend) HG(gForward) + blend HG(gBackward), through Lerp.
float DualLobePhase(float gForward, float gBackward, float blend, float cosTheta) {
    return Lerp(HenyeyGreenstein(gForward, cosTheta), HenyeyGreenstein(gBackward, cosTheta), blend);
}

// phase kind: 0 none, 1 Henyey-Greenstein, 2 Cornette-Shanks (the dual lobe, 4, is DualLobePhase and Mie, 3,
// phase_table.glsl's). Returns 4 pi p.
float PhaseValue(uint kind, float g, float cosTheta) {
    if (kind == 0u) return 1.0;
    precise float denom = 1.0 + g * g - 2.0 * g * cosTheta;
    precise float hg = (1.0 - g * g) / (denom * sqrt(denom));
    if (kind == 1u) return hg;
    precise float cs = 1.5 * (1.0 - g * g) / (2.0 + g * g) * (1.0 + cosTheta * cosTheta) / (denom * sqrt(denom));
    return cs;
}

// arccos(x), x in [-1, 1] (core/math/Shading.h ArcCos: Abramowitz & Stegun 4.4.46).
float ArcCos(float x) {
    const float a = abs(x);
    precise float p = -0.0012624911;
    p = p * a + 0.0066700901;
    p = p * a - 0.0170881256;
    p = p * a + 0.0308918810;
    p = p * a - 0.0501743046;
    p = p * a + 0.0889789874;
    p = p * a - 0.2145988016;
    p = p * a + 1.5707963050;
    precise float r = sqrt(1.0 - a) * p;
    precise float result = x < 0.0 ? 3.14159265358979 - r : r;
    return result;
}

// Wang, Ji and Zhang's eq. 16 (core/math/Shading.h CoverageModulate).
float CoverageModulate(float v, float m, float coverage, float density) {
    precise float excess = v - (m + 1.0 - coverage);
    precise float r = density * (excess > 0.0 ? excess : 0.0);
    return r < 1.0 ? r : 1.0;  // std::min(r, 1)
}

// kappa = max(0, 1 - rho^2)^2 at splat coordinate (a, b) (core/math/Shading.h SplatKernel).
float SplatKernel(float a, float b) {
    precise float x = 2.0 * a - 1.0, y = 2.0 * b - 1.0;
    precise float t = max(0.0, 1.0 - (x * x + y * y));
    return t * t;
}

#endif
