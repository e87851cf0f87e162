// core/math's scalar helpers in SIMD lanes, each the scalar function's operations in its order, so that a lane
// gives the scalar result bit for bit (no FMA contraction: the build sets -ffp-contract=off): Lerp and
// ExpNonPositive (core/math/Shading.h), std::min, std::max and std::clamp with their rules for NaN (not the
// hardware's), and int(v). Shared by the ray march's and the layers' lanes.
// Per-target code (Highway's -inl.h form): included by a file that compiles itself once per SIMD target
// (impl_cpu/CpuIsa.h), after hwy/highway.h, so that each target has its own copy; no #pragma once.
#if defined(CB_IMPL_CPU_LANE_MATH_CPU_INL_H) == defined(HWY_TARGET_TOGGLE)
#ifdef CB_IMPL_CPU_LANE_MATH_CPU_INL_H
#undef CB_IMPL_CPU_LANE_MATH_CPU_INL_H
#else
#define CB_IMPL_CPU_LANE_MATH_CPU_INL_H
#endif

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {

#if HWY_TARGET != HWY_SCALAR

namespace hn = hwy::HWY_NAMESPACE;

// int(v) for v whose integer part fits in int32 (Highway's ConvertTo also mends values out of range, at four
// more instructions).
template <class V>
HWY_INLINE hn::Vec<hn::RebindToSigned<hn::DFromV<V>>> LaneTruncate(V v) {
    using VI = hn::Vec<hn::RebindToSigned<hn::DFromV<V>>>;
#if HWY_TARGET <= HWY_AVX3
    return VI{_mm512_maskz_cvttps_epi32(__mmask16(0xFFFF), v.raw)};  // maskz: no undefined source to warn of
#elif HWY_TARGET <= HWY_AVX2
    return VI{_mm256_cvttps_epi32(v.raw)};
#elif HWY_TARGET <= HWY_SSE4
    return VI{_mm_cvttps_epi32(v.raw)};
#else
    return hn::ConvertTo(hn::RebindToSigned<hn::DFromV<V>>(), v);
#endif
}

// std::min(a, b), std::max(a, b) and std::clamp(v, lo, hi).
template <class V>
HWY_INLINE V LaneMin(V a, V b) {
    return hn::IfThenElse(hn::Lt(b, a), b, a);
}
template <class V>
HWY_INLINE V LaneMax(V a, V b) {
    return hn::IfThenElse(hn::Lt(a, b), b, a);
}
template <class V>
HWY_INLINE V LaneClamp(V v, V lo, V hi) {
    return hn::IfThenElse(hn::Lt(v, lo), lo, hn::IfThenElse(hn::Lt(hi, v), hi, v));
}

// Lerp: a (1 - t) + b t.
template <class V>
HWY_INLINE V LaneLerp(V a, V b, V t) {
    const hn::DFromV<V> d;
    return hn::Add(hn::Mul(a, hn::Sub(hn::Set(d, 1.0f), t)), hn::Mul(b, t));
}

// ExpNonPositive, step for step.
template <class V>
HWY_INLINE V LaneExpNonPositive(V x) {
    const hn::DFromV<V> d;
    const hn::RebindToSigned<decltype(d)> di;
    const auto underflows = hn::Lt(x, hn::Set(d, -87.0f));
    x = LaneMax(x, hn::Set(d, -87.0f));
    const V k = hn::Round(hn::Mul(x, hn::Set(d, 1.44269504088896341f)));
    V r = hn::Sub(x, hn::Mul(k, hn::Set(d, 0.693145751953125f)));
    r = hn::Sub(r, hn::Mul(k, hn::Set(d, 1.42860682030941723212e-6f)));
    V p = hn::Set(d, 1.0f / 5040.0f);
    p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f / 720.0f));
    p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f / 120.0f));
    p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f / 24.0f));
    p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f / 6.0f));
    p = hn::Add(hn::Mul(p, r), hn::Set(d, 0.5f));
    p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f));
    p = hn::Add(hn::Mul(p, r), hn::Set(d, 1.0f));
    const auto bits = hn::ShiftLeft<23>(hn::Add(LaneTruncate(k), hn::Set(di, 127)));
    return hn::IfThenZeroElse(underflows, hn::Mul(p, hn::BitCast(d, bits)));
}

#endif  // HWY_TARGET != HWY_SCALAR

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // CB_IMPL_CPU_LANE_MATH_CPU_INL_H
