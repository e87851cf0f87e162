// The ray marcher on the CPU (SPEC 10): per call, q_alpha and T are formed
// once into one padded volume of (q, T) pairs (a border voxel of q = 0, T = 1
// stands for "outside the grid", or with tiling holds the opposite edge's
// voxel in x and y, so the trilinear taps need no bounds checks; impl_cpu/PaddedVolumeCpu-inl.h), and with the sky
// light T_sky into a second one,
// the brick skip structure is built from it, and then the rays: on a SIMD target a packet of rays in lanes per
// 16 x 16 pixel tile (impl_cpu/MarchLanesCpu-inl.h), on the scalar target, a volume too large for 32-bit
// gathers or with multiple-scattering octaves, the shared kernel MarchRay (core/math/March.h) per pixel over 8 x 8
// pixel tiles; the same bits. A frame with temporal reprojection (core/math/Reprojection.h) traces one pixel of each
// block into a cell of its own, then fills the image from the previous frame it held on entry (ResolveReprojected).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/RenderMarchCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/blocked_range3d.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/math/March.h"
#include "core/math/Reprojection.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/MarchLanesCpu-inl.h"
#include "impl_cpu/PaddedVolumeCpu-inl.h"
#include "impl_cpu/RenderMarchCpuState.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {
namespace {

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

// The pixels a pass traces: cell (cx, cy) of a cols x rows grid traces pixel (X(cx), Y(cy)): every pixel in a full
// frame, else each k x k block's traced pixel (core/math/Reprojection.h).
struct MarchPixelGrid {
    uint32_t cols = 0, rows = 0, k = 1, offsetX = 0, offsetY = 0, width = 0, height = 0;
    explicit MarchPixelGrid(const MarchParams& p) : width(p.camera.width), height(p.camera.height) {
        const ReprojectionSetup& r = p.reprojection;
        if (!r.full) k = r.block, offsetX = r.offsetX, offsetY = r.offsetY;
        cols = ReprojectionBlocks(width, k), rows = ReprojectionBlocks(height, k);
    }
    uint32_t X(uint32_t cx) const { return TracedCoordinate(cx, k, offsetX, width); }
    uint32_t Y(uint32_t cy) const { return TracedCoordinate(cy, k, offsetY, height); }
    size_t Cells() const { return size_t(cols) * rows; }
};

// Writes traced pixel (x, y) from its march's L, T_view and depth sum: C = L + T_view background, the background the
// scene's colour or, with the ground G, the ground where the pixel's ray meets it (core/math/Ground.h). A full frame
// writes C into the image; a reprojected one writes C and the view depth into its block's cell of `traced` (4 floats a
// cell).
class MarchPixelWriter {
  public:
    MarchPixelWriter(const MarchParams& params, const MarchPixelGrid& cells, float* image, float* traced,
                     const float* G, const Extent3& grid)
        : params_(params),
          cells_(cells),
          image_(image),
          traced_(traced),
          G_(G),
          grid_(grid),
          groundLight_(MakeGroundLight(params)),
          eyeVoxel_(GroundEyeVoxel(params.camera, params.origin, params.setup.voxelSize)) {}
    void operator()(uint32_t x, uint32_t y, const Vec3& light, float transmittance, float depthSum) const {
        const Vec3 bg = G_ ? GroundBackground(params_.camera, eyeVoxel_, params_.setup.voxelSize, groundLight_, G_,
                                              grid_.nx, grid_.ny, x, y)
                           : params_.setup.background;
        if (cells_.k == 1) {
            float* out = image_ + 3 * (size_t(x) + size_t(params_.camera.width) * y);
            for (int c = 0; c < 3; ++c) out[c] = light[c] + transmittance * bg[c];
            return;
        }
        float* out = traced_ + 4 * (size_t(x / cells_.k) + size_t(cells_.cols) * (y / cells_.k));
        for (int c = 0; c < 3; ++c) out[c] = light[c] + transmittance * bg[c];
        out[3] = MarchViewDepth(depthSum, transmittance, params_.setup.voxelSize,
                                PixelRayDirection(params_.camera, x, y).cosForward, params_.camera.farPlane);
    }

  private:
    const MarchParams& params_;
    const MarchPixelGrid& cells_;
    float* image_;
    float* traced_;
    const float* G_;
    Extent3 grid_;
    GroundLight groundLight_;
    Vec3 eyeVoxel_;
};

// Pixel (x, y)'s ray and its jitter xi.
inline MarchRayGeometry PixelRay(const MarchParams& params, uint32_t x, uint32_t y, float& xi) {
    xi = params.jitter ? MarchJitter(params.seed, params.frame, x + params.camera.width * y) : 0.5f;
    return MakePixelRay(params.camera, params.origin, params.setup.voxelSize, params.setup.size, x, y,
                        params.setup.tiling);
}

// Adds part's per-ray counters (its rays' samples, skips and lanes) to total; the skip structure's are the call's.
void AddRayCounters(MarchStats& total, const MarchStats& part) {
    total.rays += part.rays;
    total.samples += part.samples;
    total.lightSamples += part.lightSamples;
    total.bricksSkipped += part.bricksSkipped;
    total.laneSteps += part.laneSteps;
    total.laneSlots += part.laneSlots;
}

// The grid's pixels through MarchRay, one ray at a time, TBB over 8 x 8 cell tiles.
template <class Light>
void MarchPixels(const MarchParams& params, const MarchPixelGrid& cells, const MarchPaddedVolume& volume,
                 const MarchBricks* bricks, const MarchPixelWriter& write, MarchStats& stats, Light&& makeLight) {
    tbb::combinable<MarchStats> perThread;
    // flatten: MarchRay and what it calls (core/math, compiled for the baseline
    // where they are not inlined) become this target's code.
    tbb::parallel_for(
        tbb::blocked_range2d<uint32_t>(0, cells.rows, 8, 0, cells.cols, 8), [&](const tbb::blocked_range2d<uint32_t>&
                                                                                    r) __attribute__((flatten)) {
            MarchStats& c = perThread.local();
            MarchCachedDensity density{&volume};
            auto light = makeLight(density);
            for (uint32_t cy = r.rows().begin(); cy < r.rows().end(); ++cy)
                for (uint32_t cx = r.cols().begin(); cx < r.cols().end(); ++cx) {
                    const uint32_t x = cells.X(cx), y = cells.Y(cy);
                    float xi;
                    const MarchRayGeometry ray = PixelRay(params, x, y, xi);
                    const MarchRayResult m = MarchRay(params.setup, ray, xi, bricks, density, light);
                    write(x, y, m.light, m.transmittance, m.depthSum);
                    c.rays += ray.Empty() ? 0 : 1;
                    c.samples += m.samples;
                    c.lightSamples += m.lightCalls;
                    c.bricksSkipped += m.bricksSkipped;
                }
        });
    perThread.combine_each([&](const MarchStats& c) { AddRayCounters(stats, c); });
}

#if HWY_TARGET != HWY_SCALAR
// The grid's pixels through MarchLanes (impl_cpu/MarchLanesCpu-inl.h), a packet of rays per 16 x 16 cell tile.
void MarchPixelsInLanes(const MarchParams& params, const MarchPixelGrid& cells, const MarchPaddedVolume& volume,
                        const MarchLaneVolume& lanes, const MarchPixelWriter& write, MarchStats& stats) {
    const uint32_t W = params.camera.width;
    const bool shadeLight = params.light == MarchLightSource::Shade;
    const Vec3 origin = GroundEyeVoxel(params.camera, params.origin, params.setup.voxelSize);  // MakePixelRay's
    tbb::combinable<MarchStats> perThread;
    tbb::parallel_for(
        tbb::blocked_range2d<uint32_t>(0, cells.rows, 16, 0, cells.cols, 16), [&](const tbb::blocked_range2d<uint32_t>&
                                                                                      r) __attribute__((flatten)) {
            const hn::ScalableTag<float> d;
            MarchLanes march(d, params.setup, lanes, shadeLight, params.lightSteps, volume);
            auto finish = [&](uint32_t pixel, const Vec3& light, float transmittance, float depthSum) {
                write(pixel % W, pixel / W, light, transmittance, depthSum);
            };
            MarchStats& c = perThread.local();
            // The range in tiles of at most 16 x 16 cells, each a batch of rays made in lanes, then marched.
            MarchPixelRays batch;
            uint32_t xs[kMarchTilePixels], ys[kMarchTilePixels];
            for (uint32_t y0 = r.rows().begin(); y0 < r.rows().end(); y0 += 16)
                for (uint32_t x0 = r.cols().begin(); x0 < r.cols().end(); x0 += 16) {
                    size_t count = 0;
                    for (uint32_t cy = y0; cy < std::min(y0 + 16, r.rows().end()); ++cy)
                        for (uint32_t cx = x0; cx < std::min(x0 + 16, r.cols().end()); ++cx)
                            xs[count] = cells.X(cx), ys[count] = cells.Y(cy), ++count;
                    MakePixelRaysInLanes(d, params.setup, params.camera, origin, xs, ys, count, params.jitter,
                                         params.seed, params.frame, batch);
                    march.Run(batch, origin, finish, c);
                }
        });
    perThread.combine_each([&](const MarchStats& c) { AddRayCounters(stats, c); });
}
#endif

// A reprojected frame's pixels (SPEC 19): a traced pixel its traced colour, every other the previous frame (`history`)
// reprojected by its block's traced depth and clamped to the traced colours of the 3 x 3 blocks around its own
// (ReprojectedColor). `bounds` takes 6 floats a block.
void ResolveReprojected(const MarchParams& params, const MarchPixelGrid& cells, const float* traced,
                        const float* history, float* bounds, float* image) {
    // Each block's least and greatest traced colour over itself and its neighbours.
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, cells.rows), [&](const tbb::blocked_range<uint32_t>& r) {
        for (uint32_t cy = r.begin(); cy < r.end(); ++cy)
            for (uint32_t cx = 0; cx < cells.cols; ++cx) {
                float* b = bounds + 6 * (cx + size_t(cells.cols) * cy);
                for (int c = 0; c < 3; ++c)
                    b[c] = std::numeric_limits<float>::infinity(), b[3 + c] = -std::numeric_limits<float>::infinity();
                for (uint32_t ny = cy > 0 ? cy - 1 : 0; ny <= std::min(cy + 1, cells.rows - 1); ++ny)
                    for (uint32_t nx = cx > 0 ? cx - 1 : 0; nx <= std::min(cx + 1, cells.cols - 1); ++nx) {
                        const float* t = traced + 4 * (nx + size_t(cells.cols) * ny);
                        for (int c = 0; c < 3; ++c) b[c] = std::min(b[c], t[c]), b[3 + c] = std::max(b[3 + c], t[c]);
                    }
            }
    });
    const uint32_t W = cells.width, H = cells.height;
    // The image-plane offsets of every column, made once.
    std::vector<float> us(W);
    for (uint32_t x = 0; x < W; ++x) us[x] = PixelPlaneU(params.camera, x);
    tbb::parallel_for(
        tbb::blocked_range<uint32_t>(0, H, 8), [&](const tbb::blocked_range<uint32_t>& r) __attribute__((flatten)) {
            for (uint32_t y = r.begin(); y < r.end(); ++y) {
                const uint32_t cy = y / cells.k;
                const float v = PixelPlaneV(params.camera, y);
                for (uint32_t x = 0; x < W; ++x) {
                    const uint32_t cx = x / cells.k;
                    const size_t cell = cx + size_t(cells.cols) * cy;
                    const float* t = traced + 4 * cell;
                    float* out = image + 3 * (size_t(x) + size_t(W) * y);
                    if (x == cells.X(cx) && y == cells.Y(cy)) {
                        out[0] = t[0], out[1] = t[1], out[2] = t[2];
                        continue;
                    }
                    const float* b = bounds + 6 * cell;
                    const Vec3 c = ReprojectedColor(params.reprojection, params.camera, history, us[x], v, t[3],
                                                    {t[0], t[1], t[2]}, {b[0], b[1], b[2]}, {b[3], b[4], b[5]});
                    out[0] = c[0], out[1] = c[1], out[2] = c[2];
                }
            }
        });
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
        const size_t brickCount = size_t(bx) * by * bz;
        if (params.skipping) {
            // Three bytes past the last brick: the lanes read a brick's byte with a 32-bit gather.
            state.bricks.assign(brickCount + 3, 0);
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
            local.bricks = brickCount;
            local.emptyBricks =
                uint64_t(std::count(state.bricks.begin(), state.bricks.begin() + brickCount, uint8_t(1)));
        }
        // 3. The rays.
        const MarchPaddedVolume volume{state.volume.data(), skyLight ? state.skyVolume.data() : nullptr, px, px * py,
                                       &params.setup};
        const MarchBricks* brickPtr = params.skipping ? &bricks : nullptr;
        const MarchSetup& s = params.setup;
        const uint32_t nl = params.lightSteps;
        const MarchPixelGrid cells(params);
        const bool reprojected = !params.reprojection.full;
        if (reprojected) state.traced.resize(4 * cells.Cells());
        const MarchPixelWriter write(params, cells, out, state.traced.data(), G, e);
        // A reprojected frame reads the previous frame from the image, which it then overwrites.
        auto resolve = [&] {
            if (!reprojected) return;
            const size_t pixels = size_t(params.camera.width) * params.camera.height;
            state.history.resize(3 * pixels);
            tbb::parallel_for(tbb::blocked_range<size_t>(0, 3 * pixels, size_t(1) << 16),
                              [&](const tbb::blocked_range<size_t>& r) {
                                  std::copy(out + r.begin(), out + r.end(), state.history.data() + r.begin());
                              });
            state.bounds.resize(6 * cells.Cells());
            ResolveReprojected(params, cells, state.traced.data(), state.history.data(), state.bounds.data(), out);
        };
#if HWY_TARGET != HWY_SCALAR
        // Multiple-scattering octaves run through MarchRay per pixel (their sum is not in lanes).
        if (MarchLanesFit(px * py * pz) && params.setup.light.octaves == 1) {
            MarchLaneVolume lanes;
            lanes.qt = &state.volume.data()->q;
            lanes.sky = skyLight ? state.skyVolume.data() : nullptr;
            lanes.px = int32_t(px), lanes.pxy = int32_t(px * py);
            if (params.skipping) {
                lanes.brickEmpty = state.bricks.data();
                lanes.brick = float(B), lanes.invBrick = 1.0f / float(B);
                lanes.brickCount[0] = float(bx), lanes.brickCount[1] = float(by), lanes.brickCount[2] = float(bz);
                lanes.brickStride[0] = int32_t(bx), lanes.brickStride[1] = int32_t(bx * by);
            }
            MarchPixelsInLanes(params, cells, volume, lanes, write, local);
            resolve();
            return;
        }
#endif
        auto plainQ = [&volume](const Vec3& p) { return volume.Q(p); };
        if (shadeLight) {
            MarchPixels(params, cells, volume, brickPtr, write, local, [&](MarchCachedDensity& density) {
                return [&density, &s, nl, plainQ](const Vec3& p) {
                    MarchLightSample l;
                    l.sun = density.LastT();
                    if (s.light.pointOn) l.point = PointLightMarch(s, p, nl, plainQ);
                    if (s.light.skyOn) l.sky = density.LastSkyT();
                    return l;
                };
            });
        } else {
            MarchPixels(params, cells, volume, brickPtr, write, local, [&](MarchCachedDensity& density) {
                return [&density, &s, nl, plainQ](const Vec3& p) {
                    MarchLightSample l;
                    l.sun = SunLightMarch(s, p, nl, plainQ);
                    if (s.light.pointOn) l.point = PointLightMarch(s, p, nl, plainQ);
                    if (s.light.skyOn) l.sky = density.LastSkyT();
                    return l;
                };
            });
        }
        resolve();
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
    const uint64_t volumes = SaturatingAdd(SaturatingMul(padded, cell), bricks + 3);
    const uint32_t k = scene.march.reprojectionBlock;
    if (k <= 1) return volumes;
    // Reprojecting: the previous frame (3 floats a pixel) and per block its traced colour and depth and its bounds.
    const uint64_t pixels = uint64_t(scene.render.width) * scene.render.height;
    const uint64_t blocks =
        uint64_t(ReprojectionBlocks(scene.render.width, k)) * ReprojectionBlocks(scene.render.height, k);
    return SaturatingAdd(
        volumes, SaturatingMul(SaturatingAdd(SaturatingMul(pixels, 3), SaturatingMul(blocks, 10)), sizeof(float)));
}

Status BackendCpu::RenderMarch(const MarchParams& params, const MarchInputs& in, Buffer& image, MarchStats* stats) {
    return HWY_DYNAMIC_DISPATCH(RenderMarch)(mArena, mStages.Get<RenderMarchCpuState>(), params, in, image, stats);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
