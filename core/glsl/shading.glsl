// GLSL twin of core/Shading.h (SPEC 6-9): exp, storage rounding, phase
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

// Nearest half, ties to even (same bit arithmetic as core/Shading.h RoundToHalf).
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

float Bilinear(float t00, float t10, float t01, float t11, float fu, float fv) {
    precise float a = t00 * (1.0 - fu) + t10 * fu;
    precise float b = t01 * (1.0 - fu) + t11 * fu;
    precise float result = a * (1.0 - fv) + b * fv;
    return result;
}

// phase kind: 0 none, 1 Henyey-Greenstein, 2 Cornette-Shanks. Returns 4 pi p.
float PhaseValue(uint kind, float g, float cosTheta) {
    if (kind == 0u) return 1.0;
    precise float denom = 1.0 + g * g - 2.0 * g * cosTheta;
    precise float hg = (1.0 - g * g) / (denom * sqrt(denom));
    if (kind == 1u) return hg;
    precise float cs = 1.5 * (1.0 - g * g) / (2.0 + g * g) * (1.0 + cosTheta * cosTheta) / (denom * sqrt(denom));
    return cs;
}

// kappa = max(0, 1 - rho^2)^2 at splat coordinate (a, b) (core/Shading.h SplatKernel).
float SplatKernel(float a, float b) {
    precise float x = 2.0 * a - 1.0, y = 2.0 * b - 1.0;
    precise float t = max(0.0, 1.0 - (x * x + y * y));
    return t * t;
}

#endif
