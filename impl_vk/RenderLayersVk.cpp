// Stage `render_layers` (SPEC 15) on Vulkan, one submit of two passes:
//   1. march_volume.comp: the padded (q_alpha, T) volume, its horizontal
//      border wrapped with tiling (render_march's pass 1 with `wrap`), and with
//      the sky light sky_volume.comp: T_sky's, wrapped alike (SkyVolumeVk.h);
//   2. render_layers.comp: one invocation per pixel, LayersPixel of
//      core/math/layers.glsl, the CPU's loop over the layers each ray crosses:
//      a compute pass touches only the layers on the ray's side of the eye,
//      where rasterising every layer would shade and discard the others; then
//      LOD0's billboards, a list made on the host per call, back to front, of
//      which each workgroup blends those that meet its 8 x 8 tile.
// The constants are core/pipeline/LayersGpu.h's block in a storage buffer.
#include <array>
#include <vector>

#include "core/pipeline/LayersGpu.h"
#include "impl_vk/BackendVk.h"
#include "impl_vk/PushBlocks.h"
#include "impl_vk/RenderLayersVkState.h"

namespace cb::vk {
namespace {

constexpr uint32_t kLayersStatWords = 4;  // fragments, drawn (low, high each)

}  // namespace

uint64_t RenderLayersVkState::ScratchBytes(const Scene& scene) const {
    uint64_t bytes = sizeof(LayersGpu) + MarchVolumeBytes(scene.grid.size, true) + kLayersStatWords * 4;
    if (scene.phase.kind == PhaseKind::Mie) bytes += uint64_t(kMieCloudTable.count) * 4;
    if (scene.layers.wang.enabled) bytes += uint64_t(scene.grid.size.nx) * scene.grid.size.ny * 4;
    bytes += uint64_t(LayersBillboardBound(scene.layers, scene.grid.voxelSize, scene.grid.size.nz)) *
             sizeof(LayersBillboard);
    if (scene.lighting.sky.on) bytes += SkyVolumeBytes(scene.grid.size);
    return bytes;
}

Status BackendVk::RenderLayers(const LayersParams& params, const LayersInputs& in, Buffer& image, LayersStats* stats) {
    RenderLayersVkState& state = mStages.Get<RenderLayersVkState>();
    if (!in.qPrev || !in.qCur || !in.T) return MakeError("vk: render_layers needs q and T");
    const Extent3 e = in.qCur->Extent();
    if (in.qPrev->Extent() != e || in.T->Extent() != e)
        return MakeError("vk: render_layers: q_prev, q_cur and T differ in size");
    const bool skyLight = params.setup.light.skyOn;
    if (skyLight) CB_TRY(CheckSkyInput(in.TSky, e, "render_layers"));
    const uint32_t W = params.camera.width, H = params.camera.height;
    if (image.Extent() != Extent3{3, W, H}) return MakeError("vk: render_layers: the image is not (3, width, height)");
    if (params.setup.wang && !params.setup.map) return MakeError("vk: render_layers: wang opacity needs its map");

    const std::vector<LayersBillboard> billboards = MakeLayersBillboards(params.setup, params.camera.forward);
    const LayersGpu frame = MakeLayersGpu(params, uint32_t(billboards.size()));
    const uint32_t px = e.nx + 2, py = e.ny + 2, pz = e.nz + 2;
    auto volumePipe = mContext->GetPipeline("march_volume", 4);
    if (!volumePipe) return std::unexpected(volumePipe.error());
    auto layersPipe = mContext->GetPipeline("render_layers", 8);
    if (!layersPipe) return std::unexpected(layersPipe.error());
    auto frameBuffer = Scratch(state.frame, sizeof frame);
    if (!frameBuffer) return std::unexpected(frameBuffer.error());
    auto volume = Scratch(state.volume, MarchVolumeBytes(e, true));
    if (!volume) return std::unexpected(volume.error());
    auto statsBuffer = Scratch(state.stats, kLayersStatWords * 4);
    if (!statsBuffer) return std::unexpected(statsBuffer.error());
    const DeviceBuffer* table = *frameBuffer;  // unread without phase Mie; a binding needs a buffer
    if (params.setup.light.phase.kind == PhaseKind::Mie) {
        auto t = MiePhaseTable(state.mieTable);
        if (!t) return std::unexpected(t.error());
        table = *t;
    }
    const DeviceBuffer* map = *frameBuffer;  // likewise without wang opacity
    if (params.setup.wang) {
        const std::span<const float> m(params.setup.map, size_t(e.nx) * e.ny);
        auto b = ScratchHolding(state.map, std::as_bytes(m), 0);
        if (!b) return std::unexpected(b.error());
        map = *b;
    }
    CB_TRY(mContext->Upload(**frameBuffer, std::as_bytes(std::span(&frame, 1))));
    const DeviceBuffer* billboardBuffer = *frameBuffer;  // unread without billboards (LOD0); a binding needs a buffer
    if (!billboards.empty()) {
        auto b = Scratch(state.billboards, billboards.size() * sizeof(LayersBillboard));
        if (!b) return std::unexpected(b.error());
        CB_TRY(mContext->Upload(**b, std::as_bytes(std::span(billboards))));
        billboardBuffer = *b;
    }
    // T_sky's padded volume with the sky light; without it, the frame stands in, unread.
    auto sky = PrepareSkyVolume(state.skyVolume, skyLight ? in.TSky : nullptr, params.setup.tiling, *frameBuffer);
    if (!sky) return std::unexpected(sky.error());

    const MarchVolumePush volumePush{e.nx, e.ny, e.nz, 1u, params.alpha, params.setup.tiling ? 1u : 0u};
    const DeviceBuffer* volumeBuffers[] = {&Dev(*in.qPrev), &Dev(*in.qCur), &Dev(*in.T), *volume};
    const DeviceBuffer* layerBuffers[] = {*frameBuffer, *volume, table,           &Dev(image),
                                          *statsBuffer, map,     billboardBuffer, sky->Volume()};
    CB_TRY(Record("render_layers", [&](VulkanContext::Recorder& r) {
        r.Fill(**statsBuffer, 0);
        r.DispatchGroups(**volumePipe, volumeBuffers, &volumePush, sizeof volumePush, CeilDiv(px, 64), py, pz);
        sky->Record(r);
        r.Barrier();
        r.DispatchGroups(**layersPipe, layerBuffers, nullptr, 0, CeilDiv(W, 8), CeilDiv(H, 8), 1);
    }));
    if (stats) {
        std::array<uint32_t, kLayersStatWords> words{};
        CB_TRY(mContext->Download(**statsBuffer, std::as_writable_bytes(std::span(words))));
        auto counter = [&](int n) { return uint64_t(words[2 * n]) | uint64_t(words[2 * n + 1]) << 32; };
        *stats = {counter(0), counter(1)};
    }
    return {};
}

}  // namespace cb::vk
