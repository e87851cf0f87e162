// The CPU's ray march with rays in SIMD lanes: MarchRay (core/math/March.h) for a packet of Lanes(d) rays at
// once, each lane running its own ray operation for operation in MarchRay's order, so that every pixel and
// counter is the scalar kernel's, bit for bit. Control flow becomes masks: at each step a lane either samples,
// or skips empty bricks, or has finished; a finished lane takes the tile's next pixel at once, so rays that end
// early (termination, a short chord, a missed box) leave no lane idle until the tile runs dry. What is rare
// per sample (a step below the float spacing, powder's pow, the point light, city glow, eye scattering) runs
// per lane through the scalar functions themselves. The SCALAR target runs MarchRay per pixel instead: the
// reference the other targets are tested against (tests/CpuIsaTest.cpp).
// Per-target code (Highway's -inl.h form): included by a file that compiles itself once per SIMD target
// (impl_cpu/CpuIsa.h), after hwy/highway.h, so that each target has its own copy; no #pragma once.
#if defined(CB_IMPL_CPU_MARCH_LANES_CPU_INL_H) == defined(HWY_TARGET_TOGGLE)
#ifdef CB_IMPL_CPU_MARCH_LANES_CPU_INL_H
#undef CB_IMPL_CPU_MARCH_LANES_CPU_INL_H
#else
#define CB_IMPL_CPU_MARCH_LANES_CPU_INL_H
#endif

#include <hwy/highway.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/math/March.h"
#include "core/stages/render_march/RenderMarchTypes.h"
#include "impl_cpu/LaneMathCpu-inl.h"
#include "impl_cpu/MarchPixelRaysCpu-inl.h"
#include "impl_cpu/RenderMarchCpuState.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;

// Trilinear reads of the padded (q, T) volume; p in voxel units (wrapped with
// tiling, MarchWrapped) is clamped to the box [0, n], where the padded taps
// (p + 0.5 floored, and +1) stay inside.
struct MarchPaddedVolume {
    const MarchQT* v = nullptr;
    const float* sky = nullptr;  // T_sky's padded volume (the sky light on)
    size_t px = 0, pxy = 0;  // padded row and slice strides
    const MarchSetup* setup = nullptr;  // the box (size) and the tiling's wrap

    struct Taps {
        size_t base;
        float wx, wy, wz;
    };
    Taps TapsAt(const Vec3& point) const {
        const Vec3 p = MarchWrapped(*setup, point);
        const Vec3& size = setup->size;
        const float cx = std::clamp(p[0], 0.0f, size[0]) + 0.5f;
        const float cy = std::clamp(p[1], 0.0f, size[1]) + 0.5f;
        const float cz = std::clamp(p[2], 0.0f, size[2]) + 0.5f;
        const size_t i = size_t(cx), j = size_t(cy), k = size_t(cz);
        return {i + px * j + pxy * k, cx - float(i), cy - float(j), cz - float(k)};
    }
    template <float MarchQT::*Field>
    float Blend(const Taps& t) const {
        const MarchQT* a = v + t.base;
        const MarchQT* b = a + pxy;
        const float c00 = Lerp(a[0].*Field, a[1].*Field, t.wx);
        const float c10 = Lerp(a[px].*Field, a[px + 1].*Field, t.wx);
        const float c01 = Lerp(b[0].*Field, b[1].*Field, t.wx);
        const float c11 = Lerp(b[px].*Field, b[px + 1].*Field, t.wx);
        return Lerp(Lerp(c00, c10, t.wy), Lerp(c01, c11, t.wy), t.wz);
    }
    float Q(const Vec3& p) const { return Blend<&MarchQT::q>(TapsAt(p)); }
    // T_sky at the taps, blended as Blend blends a field.
    float SkyT(const Taps& t) const {
        const float* a = sky + t.base;
        const float* b = a + pxy;
        const float c00 = Lerp(a[0], a[1], t.wx);
        const float c10 = Lerp(a[px], a[px + 1], t.wx);
        const float c01 = Lerp(b[0], b[1], t.wx);
        const float c11 = Lerp(b[px], b[px + 1], t.wx);
        return Lerp(Lerp(c00, c10, t.wy), Lerp(c01, c11, t.wy), t.wz);
    }
};

#if HWY_TARGET != HWY_SCALAR  // the scalar target marches one ray at a time (MarchRay)
// The padded volumes and bricks as the lanes read them: q and T as floats (32-bit gathers) or as 64-bit (q, T)
// cells, T_sky as floats, the bricks as bytes (a 32-bit gather at a byte's offset).
struct MarchLaneVolume {
    const float* qt = nullptr;   // the padded (q, T) volume as floats: cell c's q at 2c, T at 2c + 1
    const float* sky = nullptr;  // T_sky's padded volume (the sky light on)
    int32_t px = 0, pxy = 0;     // padded row and slice strides, in cells
    const uint8_t* brickEmpty = nullptr;  // skipping: 1 per empty brick, three readable bytes past the last
    float brick = 1, invBrick = 1;
    float brickCount[3] = {0, 0, 0};
    int32_t brickStride[2] = {0, 0};  // count_x, count_x count_y
};

// Whether the lanes can index the volumes with 32-bit gathers (else the scalar kernel runs).
inline bool MarchLanesFit(size_t paddedCells) { return paddedCells <= size_t(std::numeric_limits<int32_t>::max() / 2 - 8); }

template <class D>
class MarchLanes {
    using V = hn::Vec<D>;
    using M = hn::Mask<D>;
    using DI = hn::RebindToSigned<D>;
    using VI = hn::Vec<DI>;
    static constexpr size_t kMax = 16;  // the widest target's float lanes (AVX-512)

  public:
    // Skipping is on where vol has bricks; shadeLight: the sun's light from T (else the light march of lightSteps
    // taps); scalarVolume: the same volume for the per-lane scalar functions.
    MarchLanes(D d, const MarchSetup& s, const MarchLaneVolume& vol, bool shadeLight, uint32_t lightSteps,
               const MarchPaddedVolume& scalarVolume)
        : d_(d),
          s_(s),
          vol_(vol),
          bricks_(vol.brickEmpty != nullptr),
          shadeLight_(shadeLight),
          nl_(lightSteps),
          scalarVolume_(scalarVolume) {
        HWY_DASSERT(hn::Lanes(d) <= kMax);
        rareLight_ = s.light.pointOn || s.light.glowOn || s.light.eyeOn;
    }

    // Marches `rays` with origin `origin` and hands each finished pixel to finish(index, L, T_view, depthSum).
    template <class Finish>
    void Run(const MarchPixelRays& rays, const Vec3& origin, Finish&& finish, MarchStats& counters) {
        const size_t N = hn::Lanes(d_);
        for (size_t i = 0; i < kMax; ++i) pixel_[i] = -1;
        size_t next = 0;
        for (size_t i = 0; i < kMax; ++i) ox_[i] = origin[0], oy_[i] = origin[1], oz_[i] = origin[2];
        for (size_t i = 0; i < N; ++i) Refill(i, rays, next, finish, counters);
        Load();
        const DI di;
        while (true) {
            const M active = hn::RebindMask(d_, hn::Gt(hn::Load(di, pixel_), hn::Set(di, -1)));
            if (hn::AllFalse(d_, active)) break;
            counters.laneSlots += N;
            counters.laneSteps += hn::CountTrue(d_, active);
            const M finished = Step(active, counters);
            if (!hn::AllFalse(d_, finished)) {
                Store();
                alignas(64) int32_t done[kMax];
                hn::Store(hn::VecFromMask(di, hn::RebindMask(di, finished)), di, done);
                for (size_t i = 0; i < N; ++i)
                    if (done[i]) {
                        finish(uint32_t(pixel_[i]), Vec3{L0_[i], L1_[i], L2_[i]}, T_[i], depthSum_[i]);
                        pixel_[i] = -1;
                        Refill(i, rays, next, finish, counters);
                    }
                Load();
            }
        }
    }

  private:
    // Lane i takes rays until one passes through the volume; a pixel without one is finished at once.
    template <class Finish>
    void Refill(size_t i, const MarchPixelRays& rays, size_t& next, Finish& finish, MarchStats& counters) {
        for (; next < rays.count; ++next) {
            const size_t r = next;
            if (!(rays.tMin[r] < rays.tMax[r])) {
                finish(rays.pixel[r], Vec3{0, 0, 0}, 1.0f, 0.0f);
                continue;
            }
            ++counters.rays;
            dx_[i] = rays.dx[r], dy_[i] = rays.dy[r], dz_[i] = rays.dz[r];
            ix_[i] = rays.ix[r], iy_[i] = rays.iy[r], iz_[i] = rays.iz[r];
            tMin_[i] = rays.tMin[r], tMax_[i] = rays.tMax[r], xi_[i] = rays.xi[r];
            sunPhase_[i] = rays.sunPhase[r], skyPhase_[i] = rays.skyPhase[r];
            tn_[i] = rays.tMin[r], n_[i] = 0, tExit_[i] = 0.0f, walking_[i] = 0;
            T_[i] = 1.0f, L0_[i] = L1_[i] = L2_[i] = depthSum_[i] = 0.0f;
            pixel_[i] = int32_t(rays.pixel[r]);
            ++next;
            return;
        }
    }

    // The state lives in registers during a step and in the arrays across a refill.
    void Load() {
        ox = hn::Load(d_, ox_), oy = hn::Load(d_, oy_), oz = hn::Load(d_, oz_);
        dx = hn::Load(d_, dx_), dy = hn::Load(d_, dy_), dz = hn::Load(d_, dz_);
        ix = hn::Load(d_, ix_), iy = hn::Load(d_, iy_), iz = hn::Load(d_, iz_);
        tMin = hn::Load(d_, tMin_), tMax = hn::Load(d_, tMax_), xi = hn::Load(d_, xi_);
        tn = hn::Load(d_, tn_), T = hn::Load(d_, T_);
        L0 = hn::Load(d_, L0_), L1 = hn::Load(d_, L1_), L2 = hn::Load(d_, L2_), depthSum = hn::Load(d_, depthSum_);
        sunPhase = hn::Load(d_, sunPhase_), skyPhase = hn::Load(d_, skyPhase_);
        n = hn::Load(DI(), n_);
        tExit = hn::Load(d_, tExit_);
        walking = hn::RebindMask(d_, hn::MaskFromVec(hn::Load(DI(), walking_)));
    }
    void Store() {
        hn::Store(tn, d_, tn_), hn::Store(T, d_, T_);
        hn::Store(L0, d_, L0_), hn::Store(L1, d_, L1_), hn::Store(L2, d_, L2_), hn::Store(depthSum, d_, depthSum_);
        hn::Store(n, DI(), n_);
        hn::Store(tExit, d_, tExit_);
        hn::Store(hn::VecFromMask(DI(), hn::RebindMask(DI(), walking)), DI(), walking_);
    }

    // core/math's helpers in lanes (LaneMathCpu-inl.h).
    static VI Truncate(V v) { return LaneTruncate(v); }
    static V Min(V a, V b) { return LaneMin(a, b); }
    static V Max(V a, V b) { return LaneMax(a, b); }
    static V Clamp(V v, V lo, V hi) { return LaneClamp(v, lo, hi); }
    V Lerp(V a, V b, V t) const { return LaneLerp(a, b, t); }
    V Exp(V x) const { return LaneExpNonPositive(x); }

    // MarchStepAt.
    V StepAt(V t) const {
        if (!s_.adaptive) return hn::Set(d_, s_.step);
        return hn::Add(hn::Set(d_, s_.step),
                       hn::Mul(hn::Set(d_, s_.kappa), Max(hn::Zero(d_), hn::Sub(t, hn::Set(d_, s_.adaptiveStart)))));
    }

    // `after` where it moves past t, else std::nextafter(t, FLT_MAX) (a step below the float spacing; rare, so
    // per lane).
    V Advance(V t, V after, M lanes) const {
        const M stalled = hn::AndNot(hn::Gt(after, t), lanes);
        if (HWY_LIKELY(hn::AllFalse(d_, stalled))) return after;
        alignas(64) float tv[kMax], av[kMax], sv[kMax];
        hn::Store(t, d_, tv), hn::Store(after, d_, av), hn::Store(hn::VecFromMask(d_, stalled), d_, sv);
        for (size_t i = 0; i < hn::Lanes(d_); ++i)
            if (sv[i] != 0.0f) av[i] = std::nextafter(tv[i], std::numeric_limits<float>::max());
        return hn::Load(d_, av);
    }

    // TileWrap of x with period `size`, where tiling is on.
    V Wrap(V x, float size, float invSize) const {
        return hn::Sub(x, hn::Mul(hn::Set(d_, size), hn::Floor(hn::Mul(x, hn::Set(d_, invSize)))));
    }

    // MarchBrickAt: `inside` where the point lies in a brick, its index, its coordinates and the tiling's shift.
    struct BrickCell {
        M inside;
        VI index;
        V b0, b1, b2, sx, sy;
    };
    BrickCell BrickAt(V px, V py, V pz) const {
        BrickCell c;
        c.sx = hn::Zero(d_), c.sy = hn::Zero(d_);
        if (s_.tiling) {
            c.sx = hn::Mul(hn::Set(d_, s_.size[0]), hn::Floor(hn::Mul(px, hn::Set(d_, s_.invSize[0]))));
            c.sy = hn::Mul(hn::Set(d_, s_.size[1]), hn::Floor(hn::Mul(py, hn::Set(d_, s_.invSize[1]))));
        }
        const V invB = hn::Set(d_, vol_.invBrick);
        c.b0 = hn::Floor(hn::Mul(hn::Sub(px, c.sx), invB));
        c.b1 = hn::Floor(hn::Mul(hn::Sub(py, c.sy), invB));
        c.b2 = hn::Floor(hn::Mul(pz, invB));
        // Compared as floats: the same verdict as MarchBrickAt's integers, and no conversion out of range.
        const V zero = hn::Zero(d_);
        c.inside = hn::And(hn::And(hn::Ge(c.b0, zero), hn::Ge(c.b1, zero)), hn::Ge(c.b2, zero));
        c.inside = hn::And(c.inside, hn::And(hn::Lt(c.b0, hn::Set(d_, vol_.brickCount[0])),
                                             hn::Lt(c.b1, hn::Set(d_, vol_.brickCount[1]))));
        c.inside = hn::And(c.inside, hn::Lt(c.b2, hn::Set(d_, vol_.brickCount[2])));
        const DI di;
        const VI i0 = Truncate(hn::IfThenElseZero(c.inside, c.b0));
        const VI i1 = Truncate(hn::IfThenElseZero(c.inside, c.b1));
        const VI i2 = Truncate(hn::IfThenElseZero(c.inside, c.b2));
        c.index = hn::Add(i0, hn::Add(hn::Mul(i1, hn::Set(di, vol_.brickStride[0])),
                                      hn::Mul(i2, hn::Set(di, vol_.brickStride[1]))));
        return c;
    }
    M Empty(const BrickCell& c, M lanes) const {
        const DI di;
        const M where = hn::And(lanes, c.inside);
        const VI index = hn::IfThenElseZero(hn::RebindMask(di, where), c.index);
        const VI word = hn::GatherOffset(di, reinterpret_cast<const int32_t*>(vol_.brickEmpty), index);
        return hn::And(where, hn::RebindMask(d_, hn::Ne(hn::And(word, hn::Set(di, 0xFF)), hn::Zero(di))));
    }
    // RayExitFromBox of MarchBrickBox(cell) from t.
    V BrickExit(const BrickCell& c, V t) const {
        const V B = hn::Set(d_, vol_.brick);
        const V lo0 = hn::Add(hn::Mul(c.b0, B), c.sx), lo1 = hn::Add(hn::Mul(c.b1, B), c.sy), lo2 = hn::Mul(c.b2, B);
        V hi0 = hn::Add(lo0, B), hi1 = hn::Add(lo1, B);
        const V hi2 = hn::Add(lo2, B);
        if (s_.tiling) {
            hi0 = hn::Add(Min(hn::Add(hn::Mul(c.b0, B), B), hn::Set(d_, s_.size[0])), c.sx);
            hi1 = hn::Add(Min(hn::Add(hn::Mul(c.b1, B), B), hn::Set(d_, s_.size[1])), c.sy);
        }
        const V zero = hn::Zero(d_);
        V exit = hn::Set(d_, std::numeric_limits<float>::max());
        exit = Min(exit, hn::Mul(hn::Sub(hn::IfThenElse(hn::Ge(ix, zero), hi0, lo0), ox), ix));
        exit = Min(exit, hn::Mul(hn::Sub(hn::IfThenElse(hn::Ge(iy, zero), hi1, lo1), oy), iy));
        exit = Min(exit, hn::Mul(hn::Sub(hn::IfThenElse(hn::Ge(iz, zero), hi2, lo2), oz), iz));
        return Max(exit, t);
    }

    // The trilinear taps of MarchPaddedVolume::TapsAt: the base cell and the weights.
    struct Taps {
        VI base;
        V wx, wy, wz;
    };
    // p is finite (a point o + d t of a ray within the far plane, or of a light march within the box), so
    // std::clamp is the hardware's max and min: they differ only in a zero's sign, which + 0.5 removes.
    Taps TapsAt(V px, V py, V pz, M lanes) const {
        if (s_.tiling) px = Wrap(px, s_.size[0], s_.invSize[0]), py = Wrap(py, s_.size[1], s_.invSize[1]);
        const V zero = hn::Zero(d_), half = hn::Set(d_, 0.5f);
        const V cx = hn::Add(hn::Min(hn::Max(px, zero), hn::Set(d_, s_.size[0])), half);
        const V cy = hn::Add(hn::Min(hn::Max(py, zero), hn::Set(d_, s_.size[1])), half);
        const V cz = hn::Add(hn::Min(hn::Max(pz, zero), hn::Set(d_, s_.size[2])), half);
        const DI di;
        // c >= 0.5: its integer part is its floor, and c - floor(c) the weight.
        const VI i = Truncate(cx), j = Truncate(cy), k = Truncate(cz);
        Taps t;
        t.base = hn::Add(i, hn::Add(hn::Mul(j, hn::Set(di, vol_.px)), hn::Mul(k, hn::Set(di, vol_.pxy))));
        t.base = hn::IfThenElseZero(hn::RebindMask(di, lanes), t.base);
        t.wx = hn::Sub(cx, hn::Floor(cx));
        t.wy = hn::Sub(cy, hn::Floor(cy));
        t.wz = hn::Sub(cz, hn::Floor(cz));
        return t;
    }
    // MarchPaddedVolume::Blend of the field at `field` floats into each cell of `stride` floats.
    V Blend(const float* field, int32_t stride, const Taps& t) const {
        const DI di;
        const VI a = hn::Mul(t.base, hn::Set(di, stride));
        const VI sx = hn::Set(di, stride), sy = hn::Set(di, vol_.px * stride), sz = hn::Set(di, vol_.pxy * stride);
        const VI b = hn::Add(a, sz);
        const V c00 = Lerp(hn::GatherIndex(d_, field, a), hn::GatherIndex(d_, field, hn::Add(a, sx)), t.wx);
        const V c10 = Lerp(hn::GatherIndex(d_, field, hn::Add(a, sy)),
                           hn::GatherIndex(d_, field, hn::Add(hn::Add(a, sy), sx)), t.wx);
        const V c01 = Lerp(hn::GatherIndex(d_, field, b), hn::GatherIndex(d_, field, hn::Add(b, sx)), t.wx);
        const V c11 = Lerp(hn::GatherIndex(d_, field, hn::Add(b, sy)),
                           hn::GatherIndex(d_, field, hn::Add(hn::Add(b, sy), sx)), t.wx);
        return Lerp(Lerp(c00, c10, t.wy), Lerp(c01, c11, t.wy), t.wz);
    }
    V Q(const Taps& t) const { return Blend(vol_.qt, 2, t); }

    // The eight taps' q and T, each (q, T) cell read by one 64-bit gather: half the elements of a gather of each.
    struct CellTaps {
        V q[8], t[8];
    };
    CellTaps GatherCells(const Taps& taps) const {
        const hn::Repartition<double, D> dd;  // half as many lanes
        const hn::RebindToSigned<decltype(dd)> dl;
        const hn::Half<DI> dh;
        const auto* cells = reinterpret_cast<const double*>(vol_.qt);
        const auto lo = hn::PromoteTo(dl, hn::LowerHalf(dh, taps.base));
        const auto hi = hn::PromoteTo(dl, hn::UpperHalf(dh, taps.base));
        const int64_t offset[8] = {
            0, 1, vol_.px, vol_.px + 1, vol_.pxy, vol_.pxy + 1, vol_.pxy + vol_.px, vol_.pxy + vol_.px + 1};
        CellTaps c;
        for (int i = 0; i < 8; ++i) {
            const auto o = hn::Set(dl, offset[i]);
            const V a = hn::BitCast(d_, hn::GatherIndex(dd, cells, hn::Add(lo, o)));
            const V b = hn::BitCast(d_, hn::GatherIndex(dd, cells, hn::Add(hi, o)));
            c.q[i] = hn::ConcatEven(d_, b, a);
            c.t[i] = hn::ConcatOdd(d_, b, a);
        }
        return c;
    }
    // Blend of taps v[0..7] in CellTaps's order (x fastest, then y, then z), as MarchPaddedVolume::Blend.
    V BlendTaps(const V* v, const Taps& t) const {
        const V c00 = Lerp(v[0], v[1], t.wx), c10 = Lerp(v[2], v[3], t.wx);
        const V c01 = Lerp(v[4], v[5], t.wx), c11 = Lerp(v[6], v[7], t.wx);
        return Lerp(Lerp(c00, c10, t.wy), Lerp(c01, c11, t.wy), t.wz);
    }

    // SunLightMarch with MarchPaddedVolume::Q as the density: ClipRayToVolume toward the (fixed) sun, then
    // MarchTransmittance.
    V SunLight(V px, V py, V pz, M lanes) const {
        V t0 = hn::Zero(d_), t1 = hn::Set(d_, std::numeric_limits<float>::max());
        const V p[3] = {px, py, pz};
        for (int a = s_.tiling ? 2 : 0; a < 3; ++a) {
            if (std::fabs(s_.sun[a]) < 1e-20f) {
                const M outside = hn::Or(hn::Lt(p[a], hn::Zero(d_)), hn::Gt(p[a], hn::Set(d_, s_.size[a])));
                t1 = hn::IfThenZeroElse(outside, t1), t0 = hn::IfThenZeroElse(outside, t0);
                continue;
            }
            const V inv = hn::Set(d_, 1.0f / s_.sun[a]);
            V a0 = hn::Mul(hn::Sub(hn::Zero(d_), p[a]), inv), a1 = hn::Mul(hn::Sub(hn::Set(d_, s_.size[a]), p[a]), inv);
            const M swap = hn::Gt(a0, a1);
            const V lo = hn::IfThenElse(swap, a1, a0), hi = hn::IfThenElse(swap, a0, a1);
            t0 = Max(t0, lo);
            t1 = Min(t1, hi);
        }
        // MarchTransmittance(p, sun, t1, n_l): 1 where the clip is empty, the length not positive or n_l = 0.
        const M marched = hn::And(lanes, hn::And(hn::Gt(t1, t0), hn::Gt(t1, hn::Zero(d_))));
        if (nl_ == 0 || hn::AllFalse(d_, marched)) return hn::Set(d_, 1.0f);
        const V dl = hn::Div(t1, hn::Set(d_, float(nl_)));
        V depth = hn::Zero(d_);
        for (uint32_t j = 0; j < nl_; ++j) {
            const V t = hn::Mul(hn::Set(d_, float(j) + 0.5f), dl);
            const V qx = hn::Add(px, hn::Mul(hn::Set(d_, s_.sun[0]), t));
            const V qy = hn::Add(py, hn::Mul(hn::Set(d_, s_.sun[1]), t));
            const V qz = hn::Add(pz, hn::Mul(hn::Set(d_, s_.sun[2]), t));
            depth = hn::Add(depth, Q(TapsAt(qx, qy, qz, marched)));
        }
        const V T = Exp(hn::Mul(hn::Neg(hn::Mul(hn::Set(d_, s_.sigmaH), depth)), dl));
        return hn::IfThenElse(marched, T, hn::Set(d_, 1.0f));
    }

    // One step of every active lane: MarchRay's loop body, or one brick of its walk through empty bricks (a lane
    // walks one brick a step, so one lane's long walk does not hold up the others). Returns the lanes whose ray
    // has ended.
    M Step(M active, MarchStats& counters) {
        const DI di;
        const V delta = StepAt(tn);
        V tNext = s_.adaptive ? hn::Add(tn, delta)
                              : hn::Add(tMin, hn::Mul(hn::ConvertTo(d_, hn::Add(n, hn::Set(di, 1))), delta));
        tNext = Advance(tn, tNext, active);
        const V len = hn::Sub(Min(tNext, tMax), tn);
        const V ts = hn::Add(tn, hn::Mul(xi, len));
        const V px = hn::Add(ox, hn::Mul(dx, ts)), py = hn::Add(oy, hn::Mul(dy, ts)), pz = hn::Add(oz, hn::Mul(dz, ts));

        // The taps are read before the brick is known, for every lane not walking: a lane whose brick is empty
        // reads q = 0 there for nothing, but no lane waits for the brick's byte before its taps are on their way.
        const M walkers = hn::And(active, walking);
        const M samplers = hn::AndNot(walkers, active);
        const Taps taps = TapsAt(px, py, pz, samplers);
        // With shade's T, q and T of the taps come together; the light march reads q alone.
        CellTaps cells;
        if (shadeLight_) cells = GatherCells(taps);
        M sample = samplers;
        M ended = hn::FirstN(d_, 0);
        if (bricks_) {
            // A sampling lane looks up its sample's brick; a walking lane the brick a hundredth of a voxel past its
            // last exit. Either way an empty brick moves tExit to that brick's exit.
            const V at = hn::IfThenElse(walkers, hn::Add(tExit, hn::Set(d_, 0.01f)), ts);
            const BrickCell cell =
                BrickAt(hn::Add(ox, hn::Mul(dx, at)), hn::Add(oy, hn::Mul(dy, at)), hn::Add(oz, hn::Mul(dz, at)));
            const M empty = Empty(cell, active);
            if (!hn::AllFalse(d_, hn::Or(empty, walkers))) {
                counters.bricksSkipped += hn::CountTrue(d_, empty);
                tExit = hn::IfThenElse(empty, BrickExit(cell, at), tExit);
                walking = hn::And(empty, hn::Lt(tExit, tMax));
                const M landing = hn::AndNot(walking, hn::Or(empty, walkers));
                if (!hn::AllFalse(d_, landing)) Land(landing, tNext, delta);
                ended = hn::And(landing, hn::Not(hn::Lt(tn, tMax)));
                sample = hn::AndNot(empty, samplers);
            }
        }
        if (hn::AllFalse(d_, sample)) return ended;
        counters.samples += hn::CountTrue(d_, sample);
        const V qa = shadeLight_ ? BlendTaps(cells.q, taps) : Q(taps);
        const M lit = hn::And(sample, hn::Gt(qa, hn::Zero(d_)));
        M stop = hn::FirstN(d_, 0);
        if (!hn::AllFalse(d_, lit)) {
            counters.lightSamples += hn::CountTrue(d_, lit);
            const V tau = Exp(hn::Mul(hn::Neg(hn::Mul(hn::Set(d_, s_.sigmaH), qa)), len));
            const V sunT = shadeLight_ ? BlendTaps(cells.t, taps) : SunLight(px, py, pz, lit);
            const V skyT = s_.light.skyOn ? Blend(vol_.sky, 1, taps) : hn::Set(d_, 1.0f);
            V sunGain = hn::Mul(sunT, sunPhase);
            if (s_.powder) sunGain = PerLane(lit, sunGain, [&](size_t, float gain, const float* lane) {
                return gain * PowderTerm(s_.powderC, lane[0]);
            }, sunT);
            V in0, in1, in2;
            if (HWY_UNLIKELY(rareLight_)) {
                RareInScattered(lit, sunGain, sunT, skyT, px, py, pz, in0, in1, in2);
            } else {
                const LightTerms& L = s_.light;
                in0 = hn::Add(hn::Mul(hn::Set(d_, L.sunRadiance[0]), sunGain), hn::Set(d_, L.ambient[0]));
                in1 = hn::Add(hn::Mul(hn::Set(d_, L.sunRadiance[1]), sunGain), hn::Set(d_, L.ambient[1]));
                in2 = hn::Add(hn::Mul(hn::Set(d_, L.sunRadiance[2]), sunGain), hn::Set(d_, L.ambient[2]));
                if (L.skyOn) {
                    const V skyGain = hn::Mul(skyT, skyPhase);
                    in0 = hn::Add(in0, hn::Mul(hn::Set(d_, L.skyRadiance[0]), skyGain));
                    in1 = hn::Add(in1, hn::Mul(hn::Set(d_, L.skyRadiance[1]), skyGain));
                    in2 = hn::Add(in2, hn::Mul(hn::Set(d_, L.skyRadiance[2]), skyGain));
                }
            }
            const V w = hn::Mul(T, hn::Sub(hn::Set(d_, 1.0f), tau));
            L0 = hn::IfThenElse(lit, hn::Add(L0, hn::Mul(w, in0)), L0);
            L1 = hn::IfThenElse(lit, hn::Add(L1, hn::Mul(w, in1)), L1);
            L2 = hn::IfThenElse(lit, hn::Add(L2, hn::Mul(w, in2)), L2);
            depthSum = hn::IfThenElse(lit, hn::Add(depthSum, hn::Mul(w, ts)), depthSum);
            T = hn::IfThenElse(lit, hn::Mul(T, tau), T);
            stop = hn::And(lit, hn::Or(hn::Lt(T, hn::Set(d_, s_.epsilon)), hn::Eq(T, hn::Zero(d_))));
        }
        // Every sampling lane moves on, also one that stops here (its ray ends, and the next pixel replaces tn
        // and n): so the next step's position does not wait for this step's light.
        n = hn::IfThenElse(hn::RebindMask(di, sample), hn::Add(n, hn::Set(di, 1)), n);
        tn = hn::IfThenElse(sample, tNext, tn);
        return hn::Or(ended, hn::Or(stop, hn::And(sample, hn::Not(hn::Lt(tn, tMax)))));
    }

    // The end of a walk through empty bricks, for the lanes in `landing`: on to the first sample at or past tExit
    // (MarchRay's skip, from the step that found the first empty brick: tn, n, tNext and delta are still its).
    void Land(M landing, V tNext, V delta) {
        const DI di;
        if (s_.adaptive) {
            // Per lane: a lane or two land in a step, and the recurrence's iterations are a few operations each.
            alignas(64) float t[kMax], end[kMax], xs[kMax], exit[kMax];
            hn::Store(tNext, d_, t), hn::Store(tMax, d_, end), hn::Store(xi, d_, xs), hn::Store(tExit, d_, exit);
            tn = PerLane(
                landing, tn,
                [&](size_t i, float, const float*) { return MarchAdaptiveLanding(s_, t[i], end[i], xs[i], exit[i]); },
                tn);
        } else {
            const V m = hn::Floor(hn::Sub(hn::Div(hn::Sub(tExit, tMin), delta), xi));
            const VI mi = hn::ConvertTo(di, Clamp(m, hn::Zero(d_), hn::Set(d_, 16777216.0f)));
            const VI n1 = hn::Add(n, hn::Set(di, 1));
            const VI nSkip = hn::IfThenElse(hn::Lt(n1, mi), mi, n1);
            n = hn::IfThenElse(hn::RebindMask(di, landing), nSkip, n);
            tn = hn::IfThenElse(landing, hn::Add(tMin, hn::Mul(hn::ConvertTo(d_, n), delta)), tn);
        }
    }

    // f(lane, value, extra's lane) for the lanes in `lanes`, value elsewhere.
    template <class F>
    V PerLane(M lanes, V value, F&& f, V extra) const {
        alignas(64) float v[kMax], e[kMax], m[kMax];
        hn::Store(value, d_, v), hn::Store(extra, d_, e), hn::Store(hn::VecFromMask(d_, lanes), d_, m);
        for (size_t i = 0; i < hn::Lanes(d_); ++i)
            if (m[i] != 0.0f) v[i] = f(i, v[i], &e[i]);
        return hn::Load(d_, v);
    }

    // InScattered per lane, with the point light's own light march (PointLightMarch) where it is on.
    void RareInScattered(M lit, V sunGain, V sunT, V skyT, V px, V py, V pz, V& in0, V& in1, V& in2) const {
        alignas(64) float g[kMax], st[kMax], sk[kMax], sp[kMax], x[kMax], y[kMax], z[kMax], m[kMax];
        alignas(64) float dxs[kMax], dys[kMax], dzs[kMax], c0[kMax], c1[kMax], c2[kMax];
        hn::Store(sunGain, d_, g), hn::Store(sunT, d_, st), hn::Store(skyT, d_, sk), hn::Store(skyPhase, d_, sp);
        hn::Store(px, d_, x), hn::Store(py, d_, y), hn::Store(pz, d_, z), hn::Store(hn::VecFromMask(d_, lit), d_, m);
        hn::Store(dx, d_, dxs), hn::Store(dy, d_, dys), hn::Store(dz, d_, dzs);
        auto plainQ = [this](const Vec3& p) { return scalarVolume_.Q(p); };
        for (size_t i = 0; i < hn::Lanes(d_); ++i) {
            c0[i] = c1[i] = c2[i] = 0.0f;
            if (m[i] == 0.0f) continue;
            const Vec3 p{x[i], y[i], z[i]};
            const float pointT = s_.light.pointOn ? PointLightMarch(s_, p, nl_, plainQ) : 1.0f;
            const Vec3 c = InScattered(s_.light, LightSample{g[i], st[i], pointT, p, Vec3{dxs[i], dys[i], dzs[i]},
                                                             sk[i] * sp[i]});
            c0[i] = c[0], c1[i] = c[1], c2[i] = c[2];
        }
        in0 = hn::Load(d_, c0), in1 = hn::Load(d_, c1), in2 = hn::Load(d_, c2);
    }

    D d_;
    const MarchSetup& s_;
    MarchLaneVolume vol_;
    bool bricks_, shadeLight_, rareLight_ = false;
    uint32_t nl_;
    const MarchPaddedVolume& scalarVolume_;

    // A lane's ray: origin, direction and its inverse, [tMin, tMax], jitter, the two phases; MarchRay's tn, n, T,
    // L and depthSum; and, while it walks through empty bricks, the last one's exit.
    V ox, oy, oz, dx, dy, dz, ix, iy, iz, tMin, tMax, xi, tn, T, L0, L1, L2, depthSum, sunPhase, skyPhase, tExit;
    VI n;
    M walking;
    alignas(64) float ox_[kMax], oy_[kMax], oz_[kMax], dx_[kMax], dy_[kMax], dz_[kMax], ix_[kMax], iy_[kMax],
        iz_[kMax];
    alignas(64) float tMin_[kMax], tMax_[kMax], xi_[kMax], tn_[kMax], T_[kMax], L0_[kMax], L1_[kMax], L2_[kMax],
        depthSum_[kMax];
    alignas(64) float sunPhase_[kMax], skyPhase_[kMax];
    alignas(64) float tExit_[kMax];
    alignas(64) int32_t n_[kMax], walking_[kMax], pixel_[kMax];
};

#endif  // HWY_TARGET != HWY_SCALAR

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // CB_IMPL_CPU_MARCH_LANES_CPU_INL_H
