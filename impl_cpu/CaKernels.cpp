#include "impl_cpu/CaKernels.h"

#include <immintrin.h>

#include "core/math/Random.h"
#include "core/math/Rules.h"

namespace cb::cpu {

uint64_t EventBitsScalar(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert) {
    uint64_t bits = 0;
    for (uint32_t b = 0; b < 64; ++b) {
        uint32_t region = invert ? 255u - r[b] : r[b];
        bool fires = Rand24FromKey(key, v0 + b) < RegionProbability(region, q);
        bits |= uint64_t(fires) << b;
    }
    return bits;
}

uint64_t NonZeroMaskScalar(const uint8_t* r) {
    uint64_t bits = 0;
    for (uint32_t b = 0; b < 64; ++b) bits |= uint64_t(r[b] != 0) << b;
    return bits;
}

#if defined(__x86_64__) && defined(__GNUC__)
// GCC 12 reports its own AVX-512 headers' undefined-value idiom as "may be
// used uninitialized" once inlined here; the warning is about the header.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#define CB_VECTOR_TARGET __attribute__((target("avx512f,avx512bw")))

namespace {

CB_VECTOR_TARGET inline __m512i LowBias32x16(__m512i x) {
    x = _mm512_xor_si512(x, _mm512_srli_epi32(x, 16));
    x = _mm512_mullo_epi32(x, _mm512_set1_epi32(0x7feb352d));
    x = _mm512_xor_si512(x, _mm512_srli_epi32(x, 15));
    x = _mm512_mullo_epi32(x, _mm512_set1_epi32(int(0x846ca68bu)));
    x = _mm512_xor_si512(x, _mm512_srli_epi32(x, 16));
    return x;
}

CB_VECTOR_TARGET uint64_t EventBitsAvx512(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert) {
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512i keyV = _mm512_set1_epi32(int(key));
    const __m512i qV = _mm512_set1_epi32(int(q));
    const __m512i c255 = _mm512_set1_epi32(255);
    const __m512i c127 = _mm512_set1_epi32(127);
    const __m512i one = _mm512_set1_epi32(1);
    uint64_t bits = 0;
    for (uint32_t chunk = 0; chunk < 4; ++chunk) {
        __m512i v = _mm512_add_epi32(_mm512_set1_epi32(int(v0 + 16 * chunk)), lane);
        __m512i rnd = _mm512_srli_epi32(LowBias32x16(_mm512_xor_si512(v, keyV)), 8);
        __m512i region = _mm512_cvtepu8_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(r + 16 * chunk)));
        if (invert) region = _mm512_sub_epi32(c255, region);
        // rand24 < (R*q + 127)/255  <=>  255*(rand24 + 1) <= R*q + 127  (core/math/Rules.h)
        __m512i lhs = _mm512_mullo_epi32(_mm512_add_epi32(rnd, one), c255);
        __m512i rhs = _mm512_add_epi32(_mm512_mullo_epi32(region, qV), c127);
        __mmask16 fires = _mm512_cmple_epu32_mask(lhs, rhs);
        bits |= uint64_t(fires) << (16 * chunk);
    }
    return bits;
}

CB_VECTOR_TARGET uint64_t NonZeroMaskAvx512(const uint8_t* r) {
    __m512i v = _mm512_loadu_si512(r);
    return _mm512_test_epi8_mask(v, v);
}

bool DetectVector() {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw");
}

}  // namespace

bool HasVectorKernels() {
    static const bool has = DetectVector();
    return has;
}

uint64_t EventBitsVector(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert) {
    return HasVectorKernels() ? EventBitsAvx512(key, v0, r, q, invert) : EventBitsScalar(key, v0, r, q, invert);
}

uint64_t NonZeroMaskVector(const uint8_t* r) {
    return HasVectorKernels() ? NonZeroMaskAvx512(r) : NonZeroMaskScalar(r);
}

#else

bool HasVectorKernels() { return false; }
uint64_t EventBitsVector(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert) {
    return EventBitsScalar(key, v0, r, q, invert);
}
uint64_t NonZeroMaskVector(const uint8_t* r) { return NonZeroMaskScalar(r); }

#endif

const char* CaKernelName() { return HasVectorKernels() ? "AVX-512 CA kernels" : "scalar CA kernels"; }

}  // namespace cb::cpu
