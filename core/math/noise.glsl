// GLSL twin of core/math/Noise.h (SPEC 10a): Perlin, simplex and Worley noise, fBm,
// and the forming of q (height distribution, towers, detail erosion, threshold
// or coverage). Needs random.glsl, shading.glsl (CoverageModulate) and noise_words.glsl
// (the header's words). Line by line the same operations as the C++
// (built with -ffp-contract=off), written `precise` so nothing is fused.
//
// The shader that includes this defines NoiseWord(index): word `index` of the
// stage's data block (core/math/NoiseGpu.h: a header, the permutation tables, HD per
// slice, the towers, the detail volume), made once per scene on the host.
#ifndef CLOUDBENCH_NOISE_GLSL
#define CLOUDBENCH_NOISE_GLSL

uint NoiseWord(uint index);
float NoiseFloat(uint index) { return uintBitsToFloat(NoiseWord(index)); }

// i mod n in [0, n) for any sign of i (n > 0); GLSL leaves % of negatives undefined.
int NoiseWrapIndex(int i, int n) {
    if (uint(i) < uint(n)) return i;
    if (i >= n && i - n < n) return i - n;
    if (i >= 0) return int(uint(i) % uint(n));
    return n - 1 - int(uint(-(i + 1)) % uint(n));
}

// perm[perm[perm[a] + b] + c], indices mod 256, in the table at word `table`.
uint NoiseLatticeHash(uint table, int a, int b, int c) {
    return NoiseWord(table + ((NoiseWord(table + ((NoiseWord(table + (uint(a) & 255u)) + uint(b)) & 255u)) + uint(c)) & 255u));
}

float NoiseFade(float t) {
    precise float r = t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    return r;
}

float NoiseLerp(float t, float a, float b) {
    precise float r = a + t * (b - a);
    return r;
}

// Perlin's 16 gradients (core/math/Noise.h PerlinGradient's table; Gustavson's 12
// are its first 12), each component c stored as c + 1 in two bits of a word
// per axis: a constant array indexed per invocation costs lavapipe a copy.
const uvec3 kNoiseGradBits = uvec3(0x46552222u, 0x2222550au, 0x190a0a55u);

float NoiseGradientDot(uint entry, float x, float y, float z) {
    const uvec3 c = (kNoiseGradBits >> (2u * entry)) & 3u;
    precise float r = float(int(c.x) - 1) * x + float(int(c.y) - 1) * y + float(int(c.z) - 1) * z;
    return r;
}

float NoisePerlinGradient(uint hash, float x, float y, float z) { return NoiseGradientDot(hash & 15u, x, y, z); }

// The lattice index of a coordinate wrapped to the period (.x) and the next one, wrapped (.y).
ivec2 NoiseWrapCell(int fl, int period) {
    const int lo = NoiseWrapIndex(fl, period);
    return ivec2(lo, lo + 1 == period ? 0 : lo + 1);
}

float NoisePerlin(uint table, float x, float y, float z, ivec3 period) {
    const float fx = floor(x), fy = floor(y), fz = floor(z);
    const ivec2 X = NoiseWrapCell(int(fx), period.x), Y = NoiseWrapCell(int(fy), period.y),
                Z = NoiseWrapCell(int(fz), period.z);
    precise float xf = x - fx, yf = y - fy, zf = z - fz;
    const float u = NoiseFade(xf), v = NoiseFade(yf), w = NoiseFade(zf);
    precise float xm = xf - 1.0, ym = yf - 1.0, zm = zf - 1.0;
    const float n000 = NoisePerlinGradient(NoiseLatticeHash(table, X.x, Y.x, Z.x), xf, yf, zf);
    const float n100 = NoisePerlinGradient(NoiseLatticeHash(table, X.y, Y.x, Z.x), xm, yf, zf);
    const float n010 = NoisePerlinGradient(NoiseLatticeHash(table, X.x, Y.y, Z.x), xf, ym, zf);
    const float n110 = NoisePerlinGradient(NoiseLatticeHash(table, X.y, Y.y, Z.x), xm, ym, zf);
    const float n001 = NoisePerlinGradient(NoiseLatticeHash(table, X.x, Y.x, Z.y), xf, yf, zm);
    const float n101 = NoisePerlinGradient(NoiseLatticeHash(table, X.y, Y.x, Z.y), xm, yf, zm);
    const float n011 = NoisePerlinGradient(NoiseLatticeHash(table, X.x, Y.y, Z.y), xf, ym, zm);
    const float n111 = NoisePerlinGradient(NoiseLatticeHash(table, X.y, Y.y, Z.y), xm, ym, zm);
    return NoiseLerp(w, NoiseLerp(v, NoiseLerp(u, n000, n100), NoiseLerp(u, n010, n110)),
                     NoiseLerp(v, NoiseLerp(u, n001, n101), NoiseLerp(u, n011, n111)));
}

float NoiseSimplexGradient(uint hash, float x, float y, float z) { return NoiseGradientDot(hash % 12u, x, y, z); }

uint NoiseSimplexLatticeHash(uint table, int a, int b, int c, ivec3 period) {
    const int u = NoiseWrapIndex(5 * a - b - c, 6 * period.x);
    const int v = NoiseWrapIndex(5 * b - a - c, 6 * period.y);
    const int w = NoiseWrapIndex(5 * c - a - b, 6 * period.z);
    return NoiseLatticeHash(table, (4 * u + v + w) / 18, (4 * v + u + w) / 18, (4 * w + u + v) / 18);
}

// One corner's kernel (0.6 - r^2)^4 times its gradient dot product.
float NoiseSimplexCorner(uint table, int a, int b, int c, ivec3 period, float cx, float cy, float cz) {
    precise float r = 0.6 - cx * cx - cy * cy - cz * cz;
    if (r < 0.0) return 0.0;
    precise float r2 = r * r;
    precise float result = r2 * r2 * NoiseSimplexGradient(NoiseSimplexLatticeHash(table, a, b, c, period), cx, cy, cz);
    return result;
}

float NoiseSimplex(uint table, float x, float y, float z, ivec3 period) {
    const float F3 = 0.3333333432674408;  // float(1/3), as the C++ computes Real(1) / Real(3)
    const float G3 = 0.1666666716337204;  // float(1/6)
    const float G3x2 = 0.3333333432674408, G3x3 = 0.5;  // float(2 * G3) (exact), float(3 * G3)
    precise float s = (x + y + z) * F3;
    precise float xs = x + s, ys = y + s, zs = z + s;
    const float fi = floor(xs), fj = floor(ys), fk = floor(zs);
    precise float t = (fi + fj + fk) * G3;
    precise float x0 = x - (fi - t), y0 = y - (fj - t), z0 = z - (fk - t);
    int i1, j1, k1, i2, j2, k2;
    if (x0 >= y0) {
        if (y0 >= z0) {
            i1 = 1, j1 = 0, k1 = 0, i2 = 1, j2 = 1, k2 = 0;
        } else if (x0 >= z0) {
            i1 = 1, j1 = 0, k1 = 0, i2 = 1, j2 = 0, k2 = 1;
        } else {
            i1 = 0, j1 = 0, k1 = 1, i2 = 1, j2 = 0, k2 = 1;
        }
    } else {
        if (y0 < z0) {
            i1 = 0, j1 = 0, k1 = 1, i2 = 0, j2 = 1, k2 = 1;
        } else if (x0 < z0) {
            i1 = 0, j1 = 1, k1 = 0, i2 = 0, j2 = 1, k2 = 1;
        } else {
            i1 = 0, j1 = 1, k1 = 0, i2 = 1, j2 = 1, k2 = 0;
        }
    }
    precise float x1 = x0 - float(i1) + G3, y1 = y0 - float(j1) + G3, z1 = z0 - float(k1) + G3;
    precise float x2 = x0 - float(i2) + G3x2, y2 = y0 - float(j2) + G3x2, z2 = z0 - float(k2) + G3x2;
    precise float x3 = x0 - 1.0 + G3x3, y3 = y0 - 1.0 + G3x3, z3 = z0 - 1.0 + G3x3;
    const int a = int(fi), b = int(fj), c = int(fk);
    precise float n = NoiseSimplexCorner(table, a, b, c, period, x0, y0, z0) +
                      NoiseSimplexCorner(table, a + i1, b + j1, c + k1, period, x1, y1, z1) +
                      NoiseSimplexCorner(table, a + i2, b + j2, c + k2, period, x2, y2, z2) +
                      NoiseSimplexCorner(table, a + 1, b + 1, c + 1, period, x3, y3, z3);
    precise float result = 32.0 * n;
    return result;
}

// The feature point of Worley cell (cx, cy, cz), an offset in [0, 1)^3.
vec3 NoiseWorleyFeature(uint seed, int cx, int cy, int cz) {
    const uint key = LowBias32(uint(cx) + LowBias32(uint(cy) + LowBias32(uint(cz) + LowBias32(seed))));
    const float kScale = 1.0 / 16777216.0;  // 2^-24, exact
    return vec3(float(LowBias32(key) >> 8) * kScale, float(LowBias32(key + 1u) >> 8) * kScale,
                float(LowBias32(key + 2u) >> 8) * kScale);
}

float NoiseClamp01(float x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }

float NoiseWorley(uint seed, float xIn, float yIn, float zIn, ivec3 period) {
    const float fx = floor(xIn), fy = floor(yIn), fz = floor(zIn);
    const int X = int(fx), Y = int(fy), Z = int(fz);
    precise float x = xIn - fx, y = yIn - fy, z = zIn - fz;
    float best = 3.0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const vec3 f = NoiseWorleyFeature(seed, NoiseWrapIndex(X + dx, period.x), NoiseWrapIndex(Y + dy, period.y),
                                                  NoiseWrapIndex(Z + dz, period.z));
                precise float ex = float(dx) + f.x - x, ey = float(dy) + f.y - y, ez = float(dz) + f.z - z;
                precise float d = ex * ex + ey * ey + ez * ez;
                best = d < best ? d : best;
            }
    precise float r = 1.0 - sqrt(best) * 0.57735026918962576;
    return NoiseClamp01(r);
}

const uint kNoisePerlin = 0u, kNoiseSimplex = 1u, kNoiseWorley = 2u;

// The basis: a permutation table at word `table` (Perlin, simplex) or a seed (Worley).
float NoiseBasis(uint basis, uint table, uint seed, float x, float y, float z, ivec3 period) {
    if (basis == kNoisePerlin) return NoisePerlin(table, x, y, z, period);
    if (basis == kNoiseSimplex) return NoiseSimplex(table, x, y, z, period);
    return NoiseWorley(seed, x, y, z, period);
}

float NoiseFbm(uint basis, uint table, uint seed, uint octaves, float gain, uint lacunarity, bool turbulence, float x,
               float y, float z, ivec3 period) {
    precise float sum = 0.0, amplitude = 1.0;
    int m = 1;
    for (uint o = 0u; o < octaves; ++o) {
        const float fm = float(m);
        precise float xm = x * fm, ym = y * fm, zm = z * fm;
        const float n = NoiseBasis(basis, table, seed, xm, ym, zm, period * m);
        sum += amplitude * (turbulence ? abs(n) : n);
        amplitude *= gain;
        m *= int(lacunarity);
    }
    return sum;
}

float NoiseFbmNorm(uint octaves, float gain) {
    precise float norm = 0.0, amplitude = 1.0;
    for (uint o = 0u; o < octaves; ++o) norm += amplitude, amplitude *= gain;
    return norm;
}

float NoiseFbm01FromSum(uint basis, uint octaves, float gain, bool turbulence, float sum) {
    precise float f = sum / NoiseFbmNorm(octaves, gain);
    precise float g = 0.5 + 0.5 * f;
    return NoiseClamp01(turbulence || basis == kNoiseWorley ? f : g);
}

// Olajos's HD(h) = (1 - e^{-a h}) e^{-b h}. exp is the device's (the stage reads HD per slice from the host).
float NoiseHeightDistribution(float h, float a, float b) {
    precise float r = (1.0 - exp(-a * h)) * exp(-b * h);
    return r;
}

float NoiseThreshold(float v, float c) {
    precise float r = (v - c) / (1.0 - c);
    return NoiseClamp01(r);
}

float NoiseErode(float v, float d, float strength) {
    precise float e = strength * d;
    precise float r = (v - e) / (1.0 - e);
    return r;
}

// std::round: halves away from zero (GLSL's round leaves halves to the implementation).
float NoiseRound(float x) {
    const float t = trunc(x);
    precise float frac = x - t;  // exact
    return abs(frac) >= 0.5 ? t + sign(x) : t;
}

// One Gaussian tower at (x, y, z): centre c, inverse squared sigmas is, amplitude; periodic in x and y on (nx, ny).
float NoiseTower(vec3 c, vec3 is, float amplitude, float x, float y, float z, float nx, float ny) {
    precise float dx = x - c.x, dy = y - c.y;
    dx -= nx * NoiseRound(dx / nx);
    dy -= ny * NoiseRound(dy / ny);
    precise float dz = z - c.z;
    precise float r = amplitude * exp(-0.5 * (dx * dx * is.x + dy * dy * is.y + dz * dz * is.z));
    return r;
}

// ---- The stage: q at voxel (i, j, k), NoiseForm::Q's operations (core/math/NoiseGpu.h lays out the words). ----
// The header's words kNoise<Name> (noise_words.glsl, included before this file; the C++ reads the same list).
#define CB_NOISE_WORD_CONST(name, index) const uint kNoise##name = index;
CB_NOISE_WORDS(CB_NOISE_WORD_CONST)
#undef CB_NOISE_WORD_CONST

// offsets: base[3], detail[3], map[2] of the step (core/math/Noise.h StepOffsets).
float NoiseDetailAt(float offsets[8], uint i, uint j, uint k) {
    const int s = int(NoiseWord(kNoiseDetailSize));
    const uint at = NoiseWord(kNoiseDetail);
    precise float p[3] = float[3](float(i) + offsets[3], float(j) + offsets[4], float(k) + offsets[5]);
    int i0[3], i1[3];
    float t[3];
    for (int a = 0; a < 3; ++a) {
        const float f = floor(p[a]);
        precise float ta = p[a] - f;
        t[a] = ta;
        i0[a] = NoiseWrapIndex(int(f), s);
        i1[a] = i0[a] + 1 == s ? 0 : i0[a] + 1;
    }
#define NOISE_DETAIL(a, b, c) NoiseFloat(at + uint(a) + uint(s) * (uint(b) + uint(s) * uint(c)))
    const float c00 = NoiseLerp(t[0], NOISE_DETAIL(i0[0], i0[1], i0[2]), NOISE_DETAIL(i1[0], i0[1], i0[2]));
    const float c10 = NoiseLerp(t[0], NOISE_DETAIL(i0[0], i1[1], i0[2]), NOISE_DETAIL(i1[0], i1[1], i0[2]));
    const float c01 = NoiseLerp(t[0], NOISE_DETAIL(i0[0], i0[1], i1[2]), NOISE_DETAIL(i1[0], i0[1], i1[2]));
    const float c11 = NoiseLerp(t[0], NOISE_DETAIL(i0[0], i1[1], i1[2]), NOISE_DETAIL(i1[0], i1[1], i1[2]));
#undef NOISE_DETAIL
    return NoiseLerp(t[2], NoiseLerp(t[1], c00, c10), NoiseLerp(t[1], c01, c11));
}

float NoiseMapAt(float offsets[8], uint i, uint j) {
    precise float x = (float(i) + 0.5) * NoiseFloat(kNoiseMapScale) + offsets[6];
    precise float y = (float(j) + 0.5) * NoiseFloat(kNoiseMapScale + 1u) + offsets[7];
    const uint octaves = NoiseWord(kNoiseMapOctaves);
    const float gain = NoiseFloat(kNoiseMapGain);
    const ivec3 period = ivec3(int(NoiseWord(kNoiseMapPeriod)), int(NoiseWord(kNoiseMapPeriod + 1u)), 1);
    const float sum = NoiseFbm(kNoisePerlin, NoiseWord(kNoiseMapPerm), 0u, octaves, gain, 2u, false, x, y, 0.5, period);
    const float f = NoiseFbm01FromSum(kNoisePerlin, octaves, gain, false, sum);
    precise float m = 2.0 * f - 1.0;
    return max(m, 0.0);
}

float NoiseTowersAt(uint i, uint j, uint k) {
    const uint count = NoiseWord(kNoiseTowerCount), at = NoiseWord(kNoiseTowers);
    const float nx = float(NoiseWord(kNoiseNx)), ny = float(NoiseWord(kNoiseNy));
    precise float sum = 0.0;
    for (uint n = 0u; n < count; ++n) {
        const uint w = at + 7u * n;
        sum += NoiseTower(vec3(NoiseFloat(w), NoiseFloat(w + 1u), NoiseFloat(w + 2u)),
                          vec3(NoiseFloat(w + 3u), NoiseFloat(w + 4u), NoiseFloat(w + 5u)), NoiseFloat(w + 6u),
                          float(i) + 0.5, float(j) + 0.5, float(k) + 0.5, nx, ny);
    }
    return sum;
}

float NoiseQ(float offsets[8], uint i, uint j, uint k) {
    precise float px = (float(i) + 0.5) * NoiseFloat(kNoiseScale) + offsets[0];
    precise float py = (float(j) + 0.5) * NoiseFloat(kNoiseScale + 1u) + offsets[1];
    precise float pz = (float(k) + 0.5) * NoiseFloat(kNoiseScale + 2u) + offsets[2];
    const uint basis = NoiseWord(kNoiseBasis), octaves = NoiseWord(kNoiseOctaves);
    const float gain = NoiseFloat(kNoiseGain);
    const bool turbulence = NoiseWord(kNoiseTurbulence) != 0u;
    const ivec3 period = ivec3(int(NoiseWord(kNoisePeriod)), int(NoiseWord(kNoisePeriod + 1u)), int(NoiseWord(kNoisePeriod + 2u)));
    const float sum = NoiseFbm(basis, NoiseWord(kNoiseBasePerm), NoiseWord(kNoiseSeed), octaves, gain,
                               NoiseWord(kNoiseLacunarity), turbulence, px, py, pz, period);
    const float base = NoiseFbm01FromSum(basis, octaves, gain, turbulence, sum);
    precise float v = base * NoiseFloat(NoiseWord(kNoiseHeights) + k) + NoiseTowersAt(i, j, k);
    if (NoiseWord(kNoiseDetailOn) != 0u) v = NoiseErode(v, NoiseDetailAt(offsets, i, j, k), NoiseFloat(kNoiseStrength));
    if (NoiseWord(kNoiseCoverageOn) != 0u)
        return CoverageModulate(v, NoiseMapAt(offsets, i, j), NoiseFloat(kNoiseCoverage), NoiseFloat(kNoiseDensity));
    return NoiseThreshold(v, NoiseFloat(kNoiseThreshold));
}

#endif
