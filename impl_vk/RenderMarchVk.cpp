// Stage `render_march` (SPEC 10) on Vulkan, one submit of three passes:
//   1. march_volume.comp: the padded volume (impl_cpu/RenderMarchCpu.cpp step 1),
//      (q_alpha, T) pairs with the light source "shade", q alone with "march";
//      the border reads (0, 1), or with tiling the opposite edge's voxels; with
//      the sky light, sky_volume.comp: T_sky's padded volume (SkyVolumeVk.h);
//   2. march_bricks.comp (skipping only): one word per brick, 1 iff q_alpha = 0
//      over the brick grown by one voxel (step 2), and the count of empty ones;
//   3. render_march.comp (light "shade") or render_march_q.comp ("march"), both
//      shaders/render_march.glsl: one invocation per pixel in 8 x 8 workgroups,
//      MarchPixel of core/math/march.glsl, and the MarchStats counters.
// The constants are core/pipeline/MarchGpu.h's block in a storage buffer (more
// than the 128 bytes of push constants every device guarantees). The Mie table
// (kMieCloudTable) is uploaded once, on the first call whose phase is Mie.
#include <algorithm>
#include <array>

#include "core/pipeline/MarchGpu.h"
#include "impl_vk/BackendVk.h"
#include "impl_vk/PushBlocks.h"
#include "impl_vk/RenderMarchVkState.h"

namespace cb::vk {
namespace {

// MarchStats words: rays, samples, light samples, bricks skipped (low, high
// each), then empty bricks (low, high); see render_march.comp and march_bricks.comp.
constexpr uint32_t kMarchStatWords = 10;

}  // namespace

uint64_t MarchVolumeBytes(const Extent3& e, bool withT) {
    return uint64_t(e.nx + 2ull) * (e.ny + 2ull) * (e.nz + 2ull) * (withT ? 8u : 4u);
}

uint64_t RenderMarchVkState::ScratchBytes(const Scene& scene) const {
    const Extent3 e = scene.grid.size;
    uint64_t bytes =
        sizeof(MarchGpu) + MarchVolumeBytes(e, scene.march.light == MarchLightSource::Shade) + kMarchStatWords * 4;
    if (scene.march.skipping) {
        const auto b = MarchBrickCounts(e, scene.march.brick);
        bytes += uint64_t(b[0]) * b[1] * b[2] * 4;
    }
    if (scene.phase.kind == PhaseKind::Mie) bytes += uint64_t(kMieCloudTable.count) * 4;
    if (scene.lighting.sky.on) bytes += SkyVolumeBytes(e);
    return bytes;
}

Status BackendVk::RenderMarch(const MarchParams& params, const MarchInputs& in, Buffer& image, MarchStats* stats) {
    RenderMarchVkState& state = mStages.Get<RenderMarchVkState>();
    if (!in.qPrev || !in.qCur) return MakeError("vk: render_march needs q");
    if (!params.reprojection.full)
        return MakeError(
            "vk: render_march: temporal reprojection (march.reprojection.block > 1) is implemented on "
            "the cpu backend only so far");
    const Extent3 e = in.qCur->Extent();
    if (in.qPrev->Extent() != e) return MakeError("vk: render_march: q_prev and q_cur differ in size");
    const bool shadeLight = params.light == MarchLightSource::Shade;
    if (shadeLight && !in.T) return MakeError("vk: render_march: light source \"shade\" needs T");
    if (shadeLight && in.T->Extent() != e) return MakeError("vk: render_march: T and q differ in size");
    const bool skyLight = params.setup.light.skyOn;
    if (skyLight) CB_TRY(CheckSkyInput(in.TSky, e, "render_march"));
    const uint32_t W = params.camera.width, H = params.camera.height;
    if (image.Extent() != Extent3{3, W, H}) return MakeError("vk: render_march: the image is not (3, width, height)");

    CB_TRY(CheckGroundInput(params.ground, in.G, e, "vk: render_march"));
    const MarchGpu frame = MakeMarchGpu(params, e);
    const uint32_t px = e.nx + 2, py = e.ny + 2, pz = e.nz + 2;
    const uint32_t B = frame.brick;
    const uint32_t brickCount = frame.bricks[0] * frame.bricks[1] * frame.bricks[2];
    const bool mie = params.setup.light.phase.kind == PhaseKind::Mie;

    Pipeline* pipes[3] = {};
    const char* names[3] = {"march_volume", "march_bricks", shadeLight ? "render_march" : "render_march_q"};
    const uint32_t bindings[3] = {4, 3, 9};
    for (int n = 0; n < 3; ++n) {
        auto pipe = mContext->GetPipeline(names[n], bindings[n]);
        if (!pipe) return std::unexpected(pipe.error());
        pipes[n] = *pipe;
    }
    auto frameBuffer = Scratch(state.frame, sizeof frame);
    if (!frameBuffer) return std::unexpected(frameBuffer.error());
    auto volume = Scratch(state.volume, MarchVolumeBytes(e, shadeLight));
    if (!volume) return std::unexpected(volume.error());
    auto statsBuffer = Scratch(state.stats, kMarchStatWords * 4);
    if (!statsBuffer) return std::unexpected(statsBuffer.error());
    // Unread bindings get a buffer that exists (the frame): a binding needs one.
    const DeviceBuffer* bricks = *frameBuffer;
    if (params.skipping) {
        auto b = Scratch(state.bricks, VkDeviceSize(brickCount) * 4);
        if (!b) return std::unexpected(b.error());
        bricks = *b;
    }
    const DeviceBuffer* table = *frameBuffer;
    if (mie) {
        auto t = MiePhaseTable(state.mieTable);
        if (!t) return std::unexpected(t.error());
        table = *t;
    }
    CB_TRY(mContext->Upload(**frameBuffer, std::as_bytes(std::span(&frame, 1))));
    // The ground's block and G (flag kMarchGpuGround); without the ground, the frame stands in, unread.
    const DeviceBuffer* groundBlock = *frameBuffer;
    const DeviceBuffer* groundG = *frameBuffer;
    if (params.ground.on) {
        const GroundGpu block =
            MakeGroundGpu(params.camera, params.origin, params.setup.voxelSize, MakeGroundLight(params), e.nx, e.ny);
        auto b = Scratch(state.ground, sizeof block);
        if (!b) return std::unexpected(b.error());
        CB_TRY(mContext->Upload(**b, std::as_bytes(std::span(&block, 1))));
        groundBlock = *b;
        groundG = &Dev(*in.G);
    }
    // T_sky's padded volume with the sky light; without it, the frame stands in, unread.
    auto sky = PrepareSkyVolume(state.skyVolume, skyLight ? in.TSky : nullptr, params.setup.tiling, *frameBuffer);
    if (!sky) return std::unexpected(sky.error());

    const MarchVolumePush volumePush{
        e.nx, e.ny, e.nz, shadeLight ? 1u : 0u, params.alpha, params.setup.tiling ? 1u : 0u};
    const MarchBricksPush brickPush{
        px, py, pz, B, frame.bricks[0], frame.bricks[1], frame.bricks[2], shadeLight ? 2u : 1u};
    const DeviceBuffer* volumeBuffers[] = {&Dev(*in.qPrev), &Dev(*in.qCur), shadeLight ? &Dev(*in.T) : &Dev(*in.qCur),
                                           *volume};
    const DeviceBuffer* brickBuffers[] = {*volume, bricks, *statsBuffer};
    const DeviceBuffer* marchBuffers[] = {*frameBuffer, *volume,     bricks,  table,        &Dev(image),
                                          *statsBuffer, groundBlock, groundG, sky->Volume()};
    CB_TRY(Record("render_march", [&](VulkanContext::Recorder& r) {
        r.Fill(**statsBuffer, 0);
        r.DispatchGroups(*pipes[0], volumeBuffers, &volumePush, sizeof volumePush, CeilDiv(px, 64), py, pz);
        sky->Record(r);
        r.Barrier();
        if (params.skipping) {
            r.DispatchGroups(*pipes[1], brickBuffers, &brickPush, sizeof brickPush, CeilDiv(frame.bricks[0], 64),
                             frame.bricks[1], frame.bricks[2]);
            r.Barrier();
        }
        r.DispatchGroups(*pipes[2], marchBuffers, nullptr, 0, CeilDiv(W, 8), CeilDiv(H, 8), 1);
    }));
    if (stats) {
        std::array<uint32_t, kMarchStatWords> words{};
        CB_TRY(mContext->Download(**statsBuffer, std::as_writable_bytes(std::span(words))));
        auto counter = [&](int n) { return uint64_t(words[2 * n]) | uint64_t(words[2 * n + 1]) << 32; };
        *stats = {};
        stats->rays = counter(0);
        stats->samples = counter(1);
        stats->lightSamples = counter(2);
        stats->bricksSkipped = counter(3);
        if (params.skipping) {
            stats->bricks = brickCount;
            stats->emptyBricks = counter(4);
        }
    }
    return {};
}

}  // namespace cb::vk
