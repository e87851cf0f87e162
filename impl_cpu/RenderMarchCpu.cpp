// The ray marcher on the CPU (SPEC 10): per call, q_alpha and T are formed
// once into one padded volume of (q, T) pairs (a border voxel of q = 0, T = 1
// stands for "outside the grid", or with tiling holds the opposite edge's
// voxel in x and y, so the trilinear taps need no bounds checks; impl_cpu/PaddedVolumeCpu-inl.h), and with the sky
// light T_sky into a second one,
// the brick skip structure is built from it, and then every pixel runs the
// shared kernel MarchRay (core/math/March.h), TBB over 8 x 8 pixel tiles.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/RenderMarchCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/blocked_range3d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/math/March.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/PaddedVolumeCpu-inl.h"
#include "impl_cpu/RenderMarchCpuState.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {
namespace {

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

// The main march's density functor: keeps the taps of its last sample so that
// the shade light source reads T there without recomputing them.
struct MarchCachedDensity {
    const MarchPaddedVolume* volume;
    MarchPaddedVolume::Taps last{};
    float operator()(const Vec3& p) {
        last = volume->TapsAt(p);
        return volume->Blend<&MarchQT::q>(last);
    }
    float LastT() const { return volume->Blend<&MarchQT::t>(last); }
    float LastSkyT() const { return volume->SkyT(last); }
};

template <class Light>
void MarchPixels(const MarchParams& params, const MarchPaddedVolume& volume, const MarchBricks* bricks, float* image,
                 MarchStats& stats, const float* G, const Extent3& grid, Light&& makeLight) {
    // The ground (core/math/Ground.h): with G, each pixel's background where its ray meets the plane.
    const GroundLight groundLight = MakeGroundLight(params);
    const Vec3 eyeVoxel = GroundEyeVoxel(params.camera, params.origin, params.setup.voxelSize);
    const CameraFrame& cam = params.camera;
    const uint32_t W = cam.width, H = cam.height;
    std::atomic<uint64_t> rays{0}, samples{0}, lightSamples{0}, skipped{0};
    // flatten: MarchRay and what it calls (core/math, compiled for the baseline
    // where they are not inlined) become this target's code.
    tbb::parallel_for(
        tbb::blocked_range2d<uint32_t>(0, H, 8, 0, W, 8), [&](const tbb::blocked_range2d<uint32_t>& r) __attribute__((
                                                              flatten)) {
            uint64_t nRays = 0, nSamples = 0, nLight = 0, nSkipped = 0;
            MarchCachedDensity density{&volume};
            auto light = makeLight(density);
            for (uint32_t y = r.rows().begin(); y < r.rows().end(); ++y)
                for (uint32_t x = r.cols().begin(); x < r.cols().end(); ++x) {
                    const MarchRayGeometry ray = MakePixelRay(cam, params.origin, params.setup.voxelSize,
                                                              params.setup.size, x, y, params.setup.tiling);
                    const uint32_t pixel = x + W * y;
                    const float xi = params.jitter ? MarchJitter(params.seed, params.frame, pixel) : 0.5f;
                    const MarchRayResult m = MarchRay(params.setup, ray, xi, bricks, density, light);
                    float* out = image + 3 * size_t(pixel);
                    if (G) {
                        const Vec3 bg = GroundBackground(cam, eyeVoxel, params.setup.voxelSize, groundLight, G, grid.nx,
                                                         grid.ny, x, y);
                        for (int c = 0; c < 3; ++c) out[c] = m.light[c] + m.transmittance * bg[c];
                    } else {
                        out[0] = m.color[0];
                        out[1] = m.color[1];
                        out[2] = m.color[2];
                    }
                    nRays += ray.Empty() ? 0 : 1;
                    nSamples += m.samples;
                    nLight += m.lightCalls;
                    nSkipped += m.bricksSkipped;
                }
            rays += nRays;
            samples += nSamples;
            lightSamples += nLight;
            skipped += nSkipped;
        });
    stats.rays = rays;
    stats.samples = samples;
    stats.lightSamples = lightSamples;
    stats.bricksSkipped = skipped;
    (void)H;
}

}  // namespace

Status RenderMarch(tbb::task_arena& arena, RenderMarchCpuState& state, const MarchParams& params, const MarchInputs& in,
                   Buffer& image, MarchStats* stats) {
    if (!in.qPrev || !in.qCur) return MakeError("cpu: render_march needs q");
    const Extent3 e = in.qCur->Extent();
    if (in.qPrev->Extent() != e) return MakeError("cpu: render_march: q_prev and q_cur differ in size");
    const bool shadeLight = params.light == MarchLightSource::Shade;
    if (shadeLight && !in.T) return MakeError("cpu: render_march: light source \"shade\" needs T");
    if (shadeLight && in.T->Extent() != e) return MakeError("cpu: render_march: T and q differ in size");
    const bool skyLight = params.setup.light.skyOn;
    if (skyLight && (!in.TSky || in.TSky->Extent() != e))
        return MakeError("cpu: render_march: the sky light needs T_sky of q's size");
    if (image.Extent() != Extent3{3, params.camera.width, params.camera.height})
        return MakeError("cpu: render_march: the image is not (3, width, height)");

    const float* qPrev = static_cast<const BufferCpu*>(in.qPrev)->F32();
    const float* qCur = static_cast<const BufferCpu*>(in.qCur)->F32();
    const float* T = shadeLight ? static_cast<const BufferCpu*>(in.T)->F32() : nullptr;
    const float* skyT = skyLight ? static_cast<const BufferCpu*>(in.TSky)->F32() : nullptr;
    float* out = static_cast<BufferCpu&>(image).F32();
    CB_TRY(CheckGroundInput(params.ground, in.G, e, "cpu: render_march"));
    const float* G = params.ground.on ? static_cast<const BufferCpu*>(in.G)->F32() : nullptr;
    const float alpha = params.alpha;
    const size_t px = size_t(e.nx) + 2, py = size_t(e.ny) + 2, pz = size_t(e.nz) + 2;
    const bool wrap = params.setup.tiling;
    const uint32_t B = std::max(params.brick, 1u);
    const uint32_t bx = CeilDiv(e.nx, B), by = CeilDiv(e.ny, B), bz = CeilDiv(e.nz, B);
    MarchStats local;

    arena.execute([&] {
        // 1. q_alpha and T into the padded volume, T_sky into its own with the sky light; the border reads
        //    q = 0, T = 1, T_sky = 1, or with tiling the opposite edge's voxel in x and y.
        FormPaddedVolume(state.volume, e, wrap, MarchQT{0.0f, 1.0f}, [&](size_t v) {
            return MarchQT{Lerp(qPrev[v], qCur[v], alpha), T ? T[v] : 1.0f};
        });
        if (skyLight) FormPaddedVolume(state.skyVolume, e, wrap, 1.0f, [&](size_t v) { return skyT[v]; });
        // 2. Bricks: empty iff q_alpha = 0 over the brick grown by one voxel (padded indices b B .. (b+1) B + 1).
        MarchBricks bricks;
        if (params.skipping) {
            state.bricks.assign(size_t(bx) * by * bz, 0);
            tbb::parallel_for(tbb::blocked_range<uint32_t>(0, bz), [&](const tbb::blocked_range<uint32_t>& r) {
                for (uint32_t c = r.begin(); c < r.end(); ++c)
                    for (uint32_t b = 0; b < by; ++b)
                        for (uint32_t a = 0; a < bx; ++a) {
                            bool empty = true;
                            const size_t k1 = std::min<size_t>(size_t(c + 1) * B + 1, pz - 1);
                            const size_t j1 = std::min<size_t>(size_t(b + 1) * B + 1, py - 1);
                            const size_t i1 = std::min<size_t>(size_t(a + 1) * B + 1, px - 1);
                            for (size_t k = size_t(c) * B; k <= k1 && empty; ++k)
                                for (size_t j = size_t(b) * B; j <= j1 && empty; ++j)
                                    for (size_t i = size_t(a) * B; i <= i1; ++i)
                                        if (state.volume[i + px * (j + py * k)].q != 0.0f) {
                                            empty = false;
                                            break;
                                        }
                            state.bricks[a + size_t(bx) * (b + size_t(by) * c)] = empty ? 1 : 0;
                        }
            });
            bricks.empty = state.bricks.data();
            bricks.brick = B;
            bricks.count[0] = bx;
            bricks.count[1] = by;
            bricks.count[2] = bz;
            local.bricks = state.bricks.size();
            local.emptyBricks = uint64_t(std::count(state.bricks.begin(), state.bricks.end(), uint8_t(1)));
        }
        // 3. The rays.
        const MarchPaddedVolume volume{state.volume.data(), skyLight ? state.skyVolume.data() : nullptr, px, px * py,
                                       &params.setup};
        const MarchBricks* brickPtr = params.skipping ? &bricks : nullptr;
        const MarchSetup& s = params.setup;
        const uint32_t nl = params.lightSteps;
        auto plainQ = [&volume](const Vec3& p) { return volume.Q(p); };
        if (shadeLight) {
            MarchPixels(params, volume, brickPtr, out, local, G, e, [&](MarchCachedDensity& density) {
                return [&density, &s, nl, plainQ](const Vec3& p) {
                    MarchLightSample l;
                    l.sun = density.LastT();
                    if (s.light.pointOn) l.point = PointLightMarch(s, p, nl, plainQ);
                    if (s.light.skyOn) l.sky = density.LastSkyT();
                    return l;
                };
            });
        } else {
            MarchPixels(params, volume, brickPtr, out, local, G, e, [&](MarchCachedDensity& density) {
                return [&density, &s, nl, plainQ](const Vec3& p) {
                    MarchLightSample l;
                    l.sun = SunLightMarch(s, p, nl, plainQ);
                    if (s.light.pointOn) l.point = PointLightMarch(s, p, nl, plainQ);
                    if (s.light.skyOn) l.sky = density.LastSkyT();
                    return l;
                };
            });
        }
    });
    if (stats) *stats = local;
    return {};
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(RenderMarch);

uint64_t RenderMarchCpuState::ScratchBytes(const Scene& scene) const {
    const Extent3 e = scene.grid.size;
    const uint64_t padded = uint64_t(e.nx + 2ull) * (e.ny + 2ull) * (e.nz + 2ull);
    const uint32_t b = std::max(scene.march.brick, 1u);
    const uint64_t bricks = uint64_t(CeilDiv(e.nx, b)) * CeilDiv(e.ny, b) * CeilDiv(e.nz, b);
    const uint64_t cell = sizeof(MarchQT) + (scene.lighting.sky.on ? sizeof(float) : 0);
    return SaturatingAdd(SaturatingMul(padded, cell), bricks);
}

Status BackendCpu::RenderMarch(const MarchParams& params, const MarchInputs& in, Buffer& image, MarchStats* stats) {
    return HWY_DYNAMIC_DISPATCH(RenderMarch)(mArena, mStages.Get<RenderMarchCpuState>(), params, in, image, stats);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
