// The layered renderer on the CPU (SPEC 15): q_alpha and T are formed into a padded volume of (q, T) pairs, or
// (q, T, T_sky) triples with the sky light (core/math/Layers.h's taps: the border holds (0, 1) or (0, 1, 1), or with
// tiling the opposite edge's voxels; impl_cpu/PaddedVolumeCpu-inl.h), with a bit per cell where its taps read no
// cloud (LayersOccupancyCpu-inl.h), once for as long as the calls' inputs are unchanged (LayersInputs::stamp). Then
// the pixels, TBB over 8 x 16 pixel tiles: each runs LayersPixel, the layers its ray crosses back to front and then
// LOD0's billboards (a list made once per call, culled per tile), a row of SIMD lanes at a time
// (LayersLanesCpu-inl.h). A pixel's loop is the fastest form here: it touches only the layers on its side of the
// eye, where OpenGL rasterises every layer.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/RenderLayersCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <bit>
#include <vector>

#include "core/math/Layers.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/LayersLanesCpu-inl.h"
#include "impl_cpu/LayersOccupancyCpu-inl.h"
#include "impl_cpu/PaddedVolumeCpu-inl.h"
#include "impl_cpu/RenderLayersCpuState.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {

namespace {

// The pixels of one call, TBB over 8 x 16 pixel tiles, each reading the padded volume through fetch: a row of
// lanes at once (LayersRowInLanes), or on the scalar target a pixel at a time (LayersPixel).
template <class Fetch>
void LayersPixels(const LayersParams& params, Fetch&& fetch, float* out, std::atomic<uint64_t>& fragments,
                  std::atomic<uint64_t>& drawn) {
    const LayersSetup& s = params.setup;
    const uint32_t W = params.camera.width, H = params.camera.height;
    const LayersWalks walks = MakeLayersWalks(s);
    // LOD0's billboards, back to front (none without it).
    const std::vector<LayersBillboard> list = MakeLayersBillboards(s, params.camera.forward);
    // Each tile blends only the billboards whose rectangle (LayersBillboardRect) meets it, in the list's order:
    // a billboard outside has no fragment there, so the pixels are the same as with the whole list.
    std::vector<LayersPixelRect> rects(list.size());
    for (size_t n = 0; n < list.size(); ++n) rects[n] = LayersBillboardRect(s, params.camera, list[n]);
    // Tiles of 8 rows by 16 columns (a row of a tile: one or two packets of lanes). flatten: the layers' fragment
    // functions (core/math, compiled for the baseline where they are not inlined) become this target's code.
    constexpr uint32_t kTileRows = 8, kTileCols = 16;
    tbb::parallel_for(
        tbb::blocked_range2d<uint32_t>(0, H, kTileRows, 0, (W + kTileCols - 1) / kTileCols, 1),
        [&](const tbb::blocked_range2d<uint32_t>& r) __attribute__((flatten)) {
            uint64_t nFragments = 0, nDrawn = 0;
            const uint32_t xBegin = kTileCols * r.cols().begin(), xEnd = std::min(W, kTileCols * r.cols().end());
            std::vector<LayersBillboard> near;
            const double x0 = xBegin, x1 = xEnd;
            const double y0 = r.rows().begin(), y1 = r.rows().end();
            for (size_t n = 0; n < list.size(); ++n)
                if (rects[n].x1 >= x0 && rects[n].x0 <= x1 && rects[n].y1 >= y0 && rects[n].y0 <= y1)
                    near.push_back(list[n]);
            const LayersBillboards billboards{near.data(), uint32_t(near.size()), params.camera.right,
                                              params.camera.upVector};
            for (uint32_t y = r.rows().begin(); y < r.rows().end(); ++y) {
#if HWY_TARGET != HWY_SCALAR
                const uint32_t lanes = uint32_t(hwy::HWY_NAMESPACE::Lanes(hwy::HWY_NAMESPACE::ScalableTag<float>()));
                for (uint32_t x = xBegin; x < xEnd; x += lanes)
                    LayersRowInLanes(s, walks, params.camera, billboards, fetch, x, y, std::min(lanes, xEnd - x),
                                     out + 3 * (size_t(x) + size_t(W) * y), nFragments, nDrawn);
#else
                for (uint32_t x = xBegin; x < xEnd; ++x) {
                    const LayersRay ray = MakeLayersRay(params.camera, s.voxelSize, x, y);
                    const LayersPixelResult p = LayersPixel(s, walks, ray, fetch, billboards);
                    float* o = out + 3 * (size_t(x) + size_t(W) * y);
                    o[0] = p.color[0];
                    o[1] = p.color[1];
                    o[2] = p.color[2];
                    nFragments += p.fragments;
                    nDrawn += p.drawn;
                }
#endif
            }
            fragments += nFragments;
            drawn += nDrawn;
        });
}

}  // namespace

Status RenderLayers(tbb::task_arena& arena, RenderLayersCpuState& state, const LayersParams& params,
                    const LayersInputs& in, Buffer& image, LayersStats* stats) {
    if (!in.qPrev || !in.qCur || !in.T) return MakeError("cpu: render_layers needs q and T");
    const Extent3 e = in.qCur->Extent();
    if (in.qPrev->Extent() != e || in.T->Extent() != e)
        return MakeError("cpu: render_layers: q_prev, q_cur and T differ in size");
    const uint32_t W = params.camera.width, H = params.camera.height;
    if (image.Extent() != Extent3{3, W, H}) return MakeError("cpu: render_layers: the image is not (3, width, height)");
    if (params.setup.wang && !params.setup.map) return MakeError("cpu: render_layers: wang opacity needs its map");
    const float* qPrev = static_cast<const BufferCpu*>(in.qPrev)->F32();
    const float* qCur = static_cast<const BufferCpu*>(in.qCur)->F32();
    const float* T = static_cast<const BufferCpu*>(in.T)->F32();
    const bool skyLight = params.setup.light.skyOn;
    if (skyLight && (!in.TSky || in.TSky->Extent() != e))
        return MakeError("cpu: render_layers: the sky light needs T_sky of q's size");
    const float* skyT = skyLight ? static_cast<const BufferCpu*>(in.TSky)->F32() : nullptr;
    float* out = static_cast<BufferCpu&>(image).F32();
    const LayersSetup& s = params.setup;
    std::atomic<uint64_t> fragments{0}, drawn{0};

    // The volume and its bits are kept from the last call when its inputs are the same buffers with the same
    // stamp, alpha and tiling.
    const RenderLayersCpuState::Formed formed{
        in.stamp, in.qPrev, in.qCur, in.T, skyLight ? in.TSky : nullptr, std::bit_cast<uint32_t>(params.alpha),
        s.tiling};
    const bool keep = in.stamp != 0 && formed == state.formed;
    state.formed = {};  // until formed anew below
    arena.execute([&] {
        // 1. The padded volume (with the sky light its cells carry T_sky as a third field), 2. its empty taps,
        // 3. the pixels.
        const float alpha = params.alpha;
        auto readQ = [](const auto& cell) { return cell[0]; };
        if (skyLight) {
            using Cell = std::array<float, 3>;
            if (!keep) {
                FormPaddedVolume(state.volumeWithSky, e, s.tiling, Cell{0.0f, 1.0f, 1.0f}, [&](size_t v) {
                    return Cell{Lerp(qPrev[v], qCur[v], alpha), T[v], skyT[v]};
                });
                FormEmptyTaps(state.emptyTaps, state.volumeWithSky, e, readQ);
            }
            LayersPixels(params, LayersPaddedFetch<Cell>{state.volumeWithSky.data(), state.emptyTaps.data()}, out,
                         fragments, drawn);
        } else {
            using Cell = std::array<float, 2>;
            if (!keep) {
                FormPaddedVolume(state.volume, e, s.tiling, Cell{0.0f, 1.0f}, [&](size_t v) {
                    return Cell{Lerp(qPrev[v], qCur[v], alpha), T[v]};
                });
                FormEmptyTaps(state.emptyTaps, state.volume, e, readQ);
            }
            LayersPixels(params, LayersPaddedFetch<Cell>{state.volume.data(), state.emptyTaps.data()}, out, fragments,
                         drawn);
        }
    });
    state.formed = formed;
    if (stats) *stats = {fragments, drawn};
    return {};
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(RenderLayers);

uint64_t RenderLayersCpuState::ScratchBytes(const Scene& scene) const {
    const Extent3 e = scene.grid.size;
    const uint64_t fields = scene.lighting.sky.on ? 3 : 2;
    const uint64_t cells = uint64_t(e.nx + 2ull) * (e.ny + 2ull) * (e.nz + 2ull);
    return SaturatingAdd(SaturatingMul(cells, fields * sizeof(float)), (cells + 63) / 64 * 8);  // and the bits
}

Status BackendCpu::RenderLayers(const LayersParams& params, const LayersInputs& in, Buffer& image, LayersStats* stats) {
    return HWY_DYNAMIC_DISPATCH(RenderLayers)(mArena, mStages.Get<RenderLayersCpuState>(), params, in, image, stats);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
