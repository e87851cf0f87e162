// The CPU ray march's rays made in SIMD lanes (impl_cpu/MarchLanesCpu-inl.h takes them): MakePixelRay,
// InverseDirection and MarchRay's phases for a tile of pixels, operation for operation, so that every lane starts
// where the scalar kernel would.
// Per-target code (Highway's -inl.h form): included by a file that compiles itself once per SIMD target
// (impl_cpu/CpuIsa.h), after hwy/highway.h, so that each target has its own copy; no #pragma once.
#if defined(CB_IMPL_CPU_MARCH_PIXEL_RAYS_CPU_INL_H) == defined(HWY_TARGET_TOGGLE)
#ifdef CB_IMPL_CPU_MARCH_PIXEL_RAYS_CPU_INL_H
#undef CB_IMPL_CPU_MARCH_PIXEL_RAYS_CPU_INL_H
#else
#define CB_IMPL_CPU_MARCH_PIXEL_RAYS_CPU_INL_H
#endif

#include <hwy/highway.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "core/math/Camera.h"
#include "core/math/March.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {

#if HWY_TARGET != HWY_SCALAR  // the scalar target marches one ray at a time (MarchRay)
namespace hn = hwy::HWY_NAMESPACE;

// The rays of up to kMarchTilePixels pixels, as MarchRay starts them (SoA): MakePixelRay's direction and
// [tMin, tMax], InverseDirection, the jitter xi and the sun's and sky light's phases; `pixel` the image index.
inline constexpr size_t kMarchTilePixels = 16 * 16;
struct MarchPixelRays {
    alignas(64) float dx[kMarchTilePixels], dy[kMarchTilePixels], dz[kMarchTilePixels];
    alignas(64) float ix[kMarchTilePixels], iy[kMarchTilePixels], iz[kMarchTilePixels];
    alignas(64) float tMin[kMarchTilePixels], tMax[kMarchTilePixels], xi[kMarchTilePixels];
    alignas(64) float sunPhase[kMarchTilePixels], skyPhase[kMarchTilePixels];
    alignas(64) uint32_t pixel[kMarchTilePixels];
    size_t count = 0;
};

// PhaseValue at cos theta, per lane, operation for operation (Mie's table and the dual lobe through the scalar
// function: once a ray, not a sample).
template <class D>
hn::Vec<D> PhaseInLanes(D d, const PhaseParams& phase, hn::Vec<D> cosTheta) {
    using V = hn::Vec<D>;
    const float g = phase.g;
    switch (phase.kind) {
        case PhaseKind::None:
            return hn::Set(d, 1.0f);
        case PhaseKind::HenyeyGreenstein: {
            const V denom = hn::Sub(hn::Set(d, 1.0f + g * g), hn::Mul(hn::Set(d, 2.0f * g), cosTheta));
            return hn::Div(hn::Set(d, 1.0f - g * g), hn::Mul(denom, hn::Sqrt(denom)));
        }
        case PhaseKind::CornetteShanks: {
            const V denom = hn::Sub(hn::Set(d, 1.0f + g * g), hn::Mul(hn::Set(d, 2.0f * g), cosTheta));
            const V rise = hn::Add(hn::Set(d, 1.0f), hn::Mul(cosTheta, cosTheta));
            return hn::Div(hn::Mul(hn::Set(d, 1.5f * (1.0f - g * g) / (2.0f + g * g)), rise),
                           hn::Mul(denom, hn::Sqrt(denom)));
        }
        case PhaseKind::Mie:
        case PhaseKind::DualLobe:
            break;
    }
    alignas(64) float c[16];
    hn::Store(cosTheta, d, c);
    for (size_t i = 0; i < hn::Lanes(d); ++i) c[i] = PhaseValue(phase, c[i]);
    return hn::Load(d, c);
}

// The rays of pixels (x[i], y[i]), i < count <= kMarchTilePixels, Lanes(d) at a time: MakePixelRay,
// InverseDirection and MarchRay's two phases operation for operation (Mie's table and the jitter per lane).
template <class D>
void MakePixelRaysInLanes(D d, const MarchSetup& s, const CameraFrame& c, const Vec3& origin, const uint32_t* x,
                          const uint32_t* y, size_t count, bool jitter, uint32_t seed, uint32_t frame,
                          MarchPixelRays& rays) {
    using V = hn::Vec<D>;
    using M = hn::Mask<D>;
    using DI = hn::RebindToSigned<D>;
    constexpr size_t kMax = 16;
    // std::min and std::max with their own rules for NaN.
    const auto Min = [](V a, V b) { return hn::IfThenElse(hn::Lt(b, a), b, a); };
    const auto Max = [](V a, V b) { return hn::IfThenElse(hn::Lt(a, b), b, a); };
    const size_t N = hn::Lanes(d);
    const DI di;
    rays.count = count;
    for (size_t b = 0; b < count; b += N) {
        alignas(64) int32_t xs[kMax] = {}, ys[kMax] = {};
        for (size_t i = 0; i < N && b + i < count; ++i) xs[i] = int32_t(x[b + i]), ys[i] = int32_t(y[b + i]);
        const V fx = hn::ConvertTo(d, hn::Load(di, xs)), fy = hn::ConvertTo(d, hn::Load(di, ys));
        const V focal = hn::Set(d, c.focalPx), half = hn::Set(d, 0.5f);
        const V u = hn::Div(hn::Sub(hn::Add(fx, half), hn::Set(d, 0.5f * float(c.width))), focal);
        const V v = hn::Div(hn::Sub(hn::Set(d, 0.5f * float(c.height)), hn::Add(fy, half)), focal);
        V dir[3];
        for (int a = 0; a < 3; ++a)
            dir[a] = hn::Add(hn::Add(hn::Set(d, c.forward[a]), hn::Mul(u, hn::Set(d, c.right[a]))),
                             hn::Mul(v, hn::Set(d, c.upVector[a])));
        const V dot = hn::Add(hn::Add(hn::Mul(dir[0], dir[0]), hn::Mul(dir[1], dir[1])), hn::Mul(dir[2], dir[2]));
        const V inv = hn::Div(hn::Set(d, 1.0f), hn::Sqrt(dot));
        for (int a = 0; a < 3; ++a) dir[a] = hn::Mul(dir[a], inv);
        const V perDepth = hn::Div(hn::Set(d, 1.0f), hn::Mul(hn::Set(d, s.voxelSize), inv));
        V t0 = hn::Mul(hn::Set(d, c.nearPlane), perDepth), t1 = hn::Mul(hn::Set(d, c.farPlane), perDepth);
        V invDir[3];
        for (int a = 0; a < 3; ++a) {
            // ClipRayToSlab and InverseDirection: a (nearly) zero component keeps the interval where the eye
            // lies inside that slab and empties it otherwise.
            const M tiny = hn::Lt(hn::Abs(dir[a]), hn::Set(d, 1e-20f));
            const V inverse = hn::Div(hn::Set(d, 1.0f), dir[a]);
            invDir[a] = hn::IfThenElse(tiny, hn::Set(d, std::numeric_limits<float>::max()), inverse);
            if (a < (s.tiling ? 2 : 0)) continue;
            const V lo0 = hn::Mul(hn::Set(d, 0.0f - origin[a]), inverse);
            const V hi0 = hn::Mul(hn::Set(d, s.size[a] - origin[a]), inverse);
            const M swap = hn::Gt(lo0, hi0);
            const V clipMin = Max(t0, hn::IfThenElse(swap, hi0, lo0));
            const V clipMax = Min(t1, hn::IfThenElse(swap, lo0, hi0));
            const bool outside = origin[a] < 0.0f || origin[a] > s.size[a];
            t0 = hn::IfThenElse(tiny, outside ? hn::Zero(d) : t0, clipMin);
            t1 = hn::IfThenElse(tiny, outside ? hn::Zero(d) : t1, clipMax);
        }
        const V sunCos = hn::Add(hn::Add(hn::Mul(hn::Set(d, s.sun[0]), dir[0]), hn::Mul(hn::Set(d, s.sun[1]), dir[1])),
                                 hn::Mul(hn::Set(d, s.sun[2]), dir[2]));
        const V sunPhase = PhaseInLanes(d, s.light.phase, sunCos);
        V skyPhase = hn::Zero(d);
        if (s.light.skyOn) {
            const Vec3& k = s.light.skyDirection;
            skyPhase =
                PhaseInLanes(d, s.light.phase,
                             hn::Add(hn::Add(hn::Mul(hn::Set(d, k[0]), dir[0]), hn::Mul(hn::Set(d, k[1]), dir[1])),
                                     hn::Mul(hn::Set(d, k[2]), dir[2])));
        }
        hn::StoreU(dir[0], d, rays.dx + b), hn::StoreU(dir[1], d, rays.dy + b), hn::StoreU(dir[2], d, rays.dz + b);
        hn::StoreU(invDir[0], d, rays.ix + b), hn::StoreU(invDir[1], d, rays.iy + b);
        hn::StoreU(invDir[2], d, rays.iz + b);
        hn::StoreU(t0, d, rays.tMin + b), hn::StoreU(t1, d, rays.tMax + b);
        hn::StoreU(sunPhase, d, rays.sunPhase + b), hn::StoreU(skyPhase, d, rays.skyPhase + b);
        for (size_t i = 0; i < N && b + i < count; ++i) {
            rays.pixel[b + i] = x[b + i] + c.width * y[b + i];
            rays.xi[b + i] = jitter ? MarchJitter(seed, frame, rays.pixel[b + i]) : 0.5f;
        }
    }
}

#endif  // HWY_TARGET != HWY_SCALAR

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // CB_IMPL_CPU_MARCH_PIXEL_RAYS_CPU_INL_H
