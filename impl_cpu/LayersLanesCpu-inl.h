// The CPU's layers with pixels in SIMD lanes: a row of Lanes(d) pixels walks its layers together, the n-th
// fragment of every lane at once (each lane its own layer: rays up and down walk the planes in opposite orders).
// Each lane replays LayerFragment operation for operation (core/math/Layers.h; the helpers of LaneMathCpu-inl.h):
// the crossing (the plane, the near and far planes, the annulus, the drift and the wrap or the box), the
// empty-taps bit of its point (FormEmptyTaps), and where that is not set the blend of the taps, beer's opacity, the
// falloff, the sun, ambient and sky light and the blend over the pixel. What the lanes do not replay runs
// LayerFragment itself for its lane: a point that is not finite, and in a call with wang's opacity, city glow, eye
// scattering or multiple-scattering octaves every fragment whose bit is not set; LOD0's billboards run per lane through
// LayersBillboardsOver. So each pixel blends LayersPixel's fragments in its order, bit for bit (tests/CpuIsaTest.cpp
// compares every target with the scalar one, which runs LayersPixel per pixel). Per-target code (Highway's -inl.h
// form): included by a file that compiles itself once per SIMD target (impl_cpu/CpuIsa.h), after hwy/highway.h, so that
// each target has its own copy; no #pragma once.
#if defined(CB_IMPL_CPU_LAYERS_LANES_CPU_INL_H) == defined(HWY_TARGET_TOGGLE)
#ifdef CB_IMPL_CPU_LAYERS_LANES_CPU_INL_H
#undef CB_IMPL_CPU_LAYERS_LANES_CPU_INL_H
#else
#define CB_IMPL_CPU_LAYERS_LANES_CPU_INL_H
#endif

#include <hwy/highway.h>

#include <algorithm>
#include <cstdint>

#include "core/math/Layers.h"
#include "impl_cpu/LaneMathCpu-inl.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {

#if HWY_TARGET != HWY_SCALAR  // the scalar target runs LayersPixel per pixel

namespace hn = hwy::HWY_NAMESPACE;

// The pixels (x0 + l, y), l < count <= Lanes(d), of one image row into out (RGB, the row's pixel x0 first);
// fragments and drawn add the row's counts. fetch is a LayersPaddedFetch (its emptyTaps bits are read in lanes).
template <class Fetch>
void LayersRowInLanes(const LayersSetup& s, const LayersWalks& walks, const CameraFrame& camera,
                      const LayersBillboards& billboards, const Fetch& fetch, uint32_t x0, uint32_t y, uint32_t count,
                      float* out, uint64_t& fragments, uint64_t& drawn) {
    using D = hn::ScalableTag<float>;
    using DI = hn::RebindToSigned<D>;
    using DU = hn::RebindToUnsigned<D>;
    const D d;
    const DI di;
    const DU du;
    constexpr size_t kMost = HWY_MAX_BYTES / sizeof(float);
    const size_t lanes = hn::Lanes(d);

    // Each lane's ray and walk, made as LayersPixel makes them, and what LayerFragment holds for the whole walk.
    LayersRay rays[kMost];
    SunPhases phases[kMost];  // each lane's (its value[0] in sunPhase, for the lanes)
    HWY_ALIGN float sunPhase[kMost], skyPhase[kMost], dx[kMost], dy[kMost], tNear[kMost], tFar[kMost], invDz[kMost],
        length[kMost];
    HWY_ALIGN float red[kMost], green[kMost], blue[kMost];  // the pixels' colours so far
    HWY_ALIGN int32_t first[kMost], step[kMost], walkCount[kMost];
    uint32_t longest = 0;
    for (size_t l = 0; l < lanes; ++l) {
        LayersWalk w;
        rays[l] = {};
        sunPhase[l] = skyPhase[l] = 0.0f;
        phases[l] = {};
        if (l < count) {
            rays[l] = MakeLayersRay(camera, s.voxelSize, x0 + uint32_t(l), y);
            phases[l] = LayersSunPhases(s, rays[l]);
            sunPhase[l] = phases[l].value[0];
            skyPhase[l] = SkyPhase(s.light, rays[l].dir);
            w = LayersWalkOfRay(walks, rays[l]);
        }
        red[l] = s.background[0], green[l] = s.background[1], blue[l] = s.background[2];
        dx[l] = rays[l].dir[0], dy[l] = rays[l].dir[1];
        tNear[l] = rays[l].tNear, tFar[l] = rays[l].tFar;
        invDz[l] = w.count > 0 ? 1.0f / rays[l].dir[2] : 0.0f;
        length[l] = std::min(s.spacing * std::fabs(invDz[l]), s.maxLength);
        first[l] = w.first, step[l] = w.step, walkCount[l] = int32_t(w.count);
        longest = std::max(longest, w.count);
    }

    const auto vdx = hn::Load(d, dx), vdy = hn::Load(d, dy), vNear = hn::Load(d, tNear), vFar = hn::Load(d, tFar);
    const auto vInvDz = hn::Load(d, invDz), vLength = hn::Load(d, length);
    const auto vSunPhase = hn::Load(d, sunPhase), vSkyPhase = hn::Load(d, skyPhase);
    const auto vFirst = hn::Load(di, first), vStep = hn::Load(di, step), vCount = hn::Load(di, walkCount);
    const auto zero = hn::Zero(d), half = hn::Set(d, 0.5f), one = hn::Set(d, 1.0f);
    const auto eyeX = hn::Set(d, s.eye[0]), eyeY = hn::Set(d, s.eye[1]), eyeZ = hn::Set(d, s.eye[2]);
    const auto driftX = hn::Set(d, s.drift[0]), driftY = hn::Set(d, s.drift[1]);
    const auto nx = hn::Set(d, s.size[0]), ny = hn::Set(d, s.size[1]), nz = hn::Set(d, s.size[2]);
    const auto invNx = hn::Set(d, s.invSize[0]), invNy = hn::Set(d, s.invSize[1]);
    const auto spacing = hn::Set(d, s.spacing), outer2 = hn::Set(d, s.outer2), inner2 = hn::Set(d, s.inner2);
    const auto infinity = hn::Set(d, hwy::HighestValue<float>());
    const uint32_t px = uint32_t(s.size[0]) + 2u, py = uint32_t(s.size[1]) + 2u;  // LayersTapsAt's strides
    const uint32_t pxy = px * py;
    const auto vpx = hn::Set(du, px), vpy = hn::Set(du, py);
    const int32_t* emptyWords = reinterpret_cast<const int32_t*>(fetch.emptyTaps);  // bit b: word b / 32, bit b % 32
    // The fields of a padded cell, (q, T) or (q, T, T_sky), read as floats.
    constexpr int32_t kFields = int32_t(sizeof(*fetch.volume) / sizeof(float));
    const float* cells = reinterpret_cast<const float*>(fetch.volume);
    const LightTerms& light = s.light;
    // The lanes gather cells by an int32 float index.
    const bool indexFits = uint64_t(pxy) * (uint64_t(s.size[2]) + 2u) * kFields < (uint64_t(1) << 31);
    const bool inLanes = !s.wang && !light.pointOn && !light.glowOn && !light.eyeOn && light.octaves == 1 && indexFits;

    HWY_ALIGN int32_t layerOf[kMost];
    uint8_t scalarBits[(kMost + 7) / 8];
    for (uint32_t n = 0; n < longest; ++n) {
        const auto vn = hn::Set(di, int32_t(n));
        const auto layer = hn::Add(vFirst, hn::Mul(vStep, vn));
        // LayerFragment: z_i, t, the range and the annulus; LayersSampleAt: the drift, then the wrap or the box.
        const auto z = hn::Mul(hn::Add(hn::ConvertTo(d, layer), half), spacing);
        const auto t = hn::Mul(hn::Sub(z, eyeZ), vInvDz);
        auto crossed = hn::And(hn::RebindMask(d, hn::Lt(vn, vCount)),
                               hn::And(hn::And(hn::Ge(t, vNear), hn::Le(t, vFar)), hn::Gt(t, zero)));
        const auto hx = hn::Mul(vdx, t), hy = hn::Mul(vdy, t);
        const auto r2 = hn::Add(hn::Mul(hx, hx), hn::Mul(hy, hy));
        crossed = hn::And(crossed, hn::And(hn::Le(r2, outer2), hn::Ge(r2, inner2)));
        auto x = hn::Sub(hn::Add(eyeX, hx), driftX), yy = hn::Sub(hn::Add(eyeY, hy), driftY);
        if (s.tiling) {
            x = hn::Sub(x, hn::Mul(nx, hn::Floor(hn::Mul(x, invNx))));
            yy = hn::Sub(yy, hn::Mul(ny, hn::Floor(hn::Mul(yy, invNy))));
        } else {
            crossed = hn::And(
                crossed, hn::And(hn::And(hn::Ge(x, zero), hn::Le(x, nx)), hn::And(hn::Ge(yy, zero), hn::Le(yy, ny))));
        }
        if (hn::AllFalse(d, crossed)) continue;
        fragments += hn::CountTrue(d, crossed);
        // LayersTapsAt where the point is finite (clamping a finite value, hardware and std agree), and its bit:
        // set means every tap reads q = 0, the fragment is not drawn.
        const auto known = hn::And(crossed, hn::And(hn::Le(hn::Abs(x), infinity), hn::Le(hn::Abs(yy), infinity)));
        const auto cx = hn::Add(hn::Min(hn::Max(x, zero), nx), half);
        const auto cy = hn::Add(hn::Min(hn::Max(yy, zero), ny), half);
        const auto cz = hn::Add(hn::Min(hn::Max(z, zero), nz), half);
        const auto i = LaneTruncate(cx), j = LaneTruncate(cy), k = LaneTruncate(cz);
        const auto base = hn::IfThenElseZero(
            hn::RebindMask(du, known),
            hn::Add(hn::BitCast(du, i), hn::Mul(vpx, hn::Add(hn::BitCast(du, j), hn::Mul(vpy, hn::BitCast(du, k))))));
        const auto word = hn::BitCast(du, hn::GatherIndex(di, emptyWords, hn::BitCast(di, hn::ShiftRight<5>(base))));
        const auto bit = hn::And(hn::Shr(word, hn::And(base, hn::Set(du, 31u))), hn::Set(du, 1u));
        const auto clear = hn::And(known, hn::RebindMask(d, hn::Ne(bit, hn::Zero(du))));
        const auto rest = hn::AndNot(clear, crossed);
        if (hn::AllFalse(d, rest)) continue;
        auto viaScalar = rest;
        if (inLanes) {
            viaScalar = hn::AndNot(known, rest);
            // LayersBlend's fields, then LayersSampleAt from q > 0 on.
            const auto wx = hn::Sub(cx, hn::ConvertTo(d, i)), wy = hn::Sub(cy, hn::ConvertTo(d, j));
            const auto wz = hn::Sub(cz, hn::ConvertTo(d, k));
            const auto at = hn::Mul(hn::BitCast(di, base), hn::Set(di, kFields));  // float index of tap 0's cell
            const auto blend = [&](int32_t field) {
                const auto tap = [&](uint32_t offset) {
                    return hn::GatherIndex(d, cells, hn::Add(at, hn::Set(di, int32_t(offset) * kFields + field)));
                };
                const auto c00 = LaneLerp(tap(0), tap(1), wx), c10 = LaneLerp(tap(px), tap(px + 1), wx);
                const auto c01 = LaneLerp(tap(pxy), tap(pxy + 1), wx);
                const auto c11 = LaneLerp(tap(pxy + px), tap(pxy + px + 1), wx);
                return LaneLerp(LaneLerp(c00, c10, wy), LaneLerp(c01, c11, wy), wz);
            };
            const auto q = blend(0);
            const auto drawnHere = hn::And(hn::And(rest, known), hn::Gt(q, zero));
            if (!hn::AllFalse(d, drawnHere)) {
                drawn += hn::CountTrue(d, drawnHere);
                auto alpha =
                    hn::Sub(one, LaneExpNonPositive(hn::Mul(hn::Neg(hn::Mul(hn::Set(d, s.sigmaH), q)), vLength)));
                if (s.fadeInv2 > 0.0f) {  // LayersFade; 1 otherwise, and alpha 1 = alpha
                    const auto w = LaneMin(LaneMax(hn::Mul(hn::Sub(outer2, r2), hn::Set(d, s.fadeInv2)), zero), one);
                    alpha =
                        hn::Mul(alpha, hn::Mul(hn::Mul(w, w), hn::Sub(hn::Set(d, 3.0f), hn::Mul(hn::Set(d, 2.0f), w))));
                }
                const auto lit = hn::Mul(blend(1), hn::Set(d, s.lightScale));
                const auto gain = hn::Mul(lit, vSunPhase);
                const auto skyGain = light.skyOn && kFields > 2 ? hn::Mul(blend(2), vSkyPhase) : zero;
                const auto keep = hn::Sub(one, alpha);
                float* colours[3] = {red, green, blue};
                for (int c = 0; c < 3; ++c) {  // InScattered, then LayersOver
                    auto in = hn::Add(hn::Mul(hn::Set(d, light.sunRadiance[c]), gain), hn::Set(d, light.ambient[c]));
                    if (light.skyOn) in = hn::Add(in, hn::Mul(hn::Set(d, light.skyRadiance[c]), skyGain));
                    const auto before = hn::Load(d, colours[c]);
                    const auto over = hn::Add(hn::Mul(alpha, in), hn::Mul(keep, before));
                    hn::Store(hn::IfThenElse(drawnHere, over, before), d, colours[c]);
                }
            }
        }
        if (hn::AllFalse(d, viaScalar)) continue;
        hn::Store(layer, di, layerOf);
        hn::StoreMaskBits(d, viaScalar, scalarBits);
        for (size_t l = 0; l < lanes; ++l) {
            if (!((scalarBits[l / 8] >> (l % 8)) & 1u)) continue;
            const LayerFragmentResult f = LayerFragment(s, rays[l], phases[l], uint32_t(layerOf[l]), fetch);
            if (!f.drawn) continue;
            ++drawn;
            const Vec3 over = LayersOver({red[l], green[l], blue[l]}, f.alpha, f.color);
            red[l] = over[0], green[l] = over[1], blue[l] = over[2];
        }
    }
    for (size_t l = 0; l < count; ++l) {
        LayersPixelResult pixel;
        pixel.color = {red[l], green[l], blue[l]};
        LayersBillboardsOver(s, billboards, rays[l], phases[l], fetch, pixel);
        fragments += pixel.fragments;  // the billboards' (the layers' were counted in lanes)
        drawn += pixel.drawn;
        float* o = out + 3 * l;
        o[0] = pixel.color[0], o[1] = pixel.color[1], o[2] = pixel.color[2];
    }
}

#endif  // HWY_TARGET != HWY_SCALAR

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // CB_IMPL_CPU_LAYERS_LANES_CPU_INL_H
