// Stage `render_splat` (SPEC 8) on Vulkan: count, write, bin and composite the
// splats in the shared order (splat_*.comp, scan.comp).
#include <algorithm>
#include <vector>

#include "core/Splat.h"
#include "impl_vk/StageVk.h"

namespace cb::vk {

Status BackendVk::RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& image, SplatStats* stats) {
    // The GLSL PhaseValue has no table yet: refuse rather than draw with another phase.
    if (p.phase.kind == PhaseKind::Mie)
        return MakeError("vk does not implement phase 'mie' in render_splat yet (issue 14)");
    if (!p.order || !in.qPrev || !in.qCur || !in.T)
        return MakeError("vk: render_splat needs q (both steps), T and an order");
    const Extent3 e = in.qCur->Extent();
    if (image.Extent().nx != 3) return MakeError("vk: render_splat image must have extent (3, width, height)");
    const uint32_t W = image.Extent().ny, H = image.Extent().nz;
    CB_TRY(CheckGroundInput(p.ground, in.G, e, "vk: render_splat"));

    // Which tile x band boxes can hold a splat: the frustum (host geometry,
    // shared with the CPU, core/Backend.h SplatBoxVisibility) and, when
    // skipping, the two steps' band occupancy, ORed on the device
    // (splat_boxes.comp), so nothing is read back for it.
    SplatParams frustumOnly = p;
    frustumOnly.skipping = false;
    const std::vector<uint8_t> boxes = SplatBoxVisibility(frustumOnly, e, {}, {});
    if (p.skipping) {
        if (!in.bandsPrev || !in.bandsCur)
            return MakeError("vk: render_splat with skipping needs both steps' occupancy");
        if (in.bandsPrev->CanonicalBytes() != boxes.size() || in.bandsCur->CanonicalBytes() != boxes.size())
            return MakeError("vk: render_splat's band occupancy does not match its tile and band");
    }
    // The shared order, outer axis first.
    const SplatOrder& order = *p.order;
    const FlatSplatOrder flat = FlattenSplatOrder(order);
    // kTileSize: splat_composite.comp runs a workgroup of 64 per 8 x 8 tile.
    constexpr uint32_t kVoxelsPerChunk = 1024, kSplatsPerChunk = 256, kTileSize = 8;
    const uint32_t voxels = uint32_t(e.Count());
    const uint32_t tilesX = CeilDiv(W, kTileSize), tilesY = CeilDiv(H, kTileSize), screenTiles = tilesX * tilesY;
    // The shared frame; this backend's lanes: voxels per chunk of ranks, screen tiles.
    SplatFrame frame = MakeSplatFrame(p, e, flat, W, H);
    frame.grid[3] = kVoxelsPerChunk;
    frame.image[2] = tilesX;
    frame.image[3] = tilesY;
    const uint32_t chunks = CeilDiv(voxels, kVoxelsPerChunk);
    // This stage's scratch buffers, one per VkScratch::Splat* slot (what each holds is said there).
    struct {
        DeviceBuffer *frame, *order, *boxes, *chunkSplats, *chunkVisited, *chunkOffsets;
        DeviceBuffer *splats, *binCounts, *tileTotals, *tileBases, *tileList, *scanSums;
    } scratch{};
    // At least 16 bytes: a binding needs a buffer even when nothing is in it.
    auto need = [&](DeviceBuffer*& buffer, VkScratch slot, VkDeviceSize bytes) -> Status {
        auto b = Scratch(slot, std::max<VkDeviceSize>(bytes, 16));
        if (!b) return std::unexpected(b.error());
        buffer = *b;
        return {};
    };
    CB_TRY(need(scratch.frame, VkScratch::SplatFrame, sizeof frame));
    CB_TRY(need(scratch.order, VkScratch::SplatOrder, flat.indices.size() * 4));
    CB_TRY(need(scratch.boxes, VkScratch::SplatBoxes, boxes.size()));
    CB_TRY(need(scratch.chunkSplats, VkScratch::SplatChunkSplats, VkDeviceSize(chunks) * 4));
    CB_TRY(need(scratch.chunkVisited, VkScratch::SplatChunkVisited, VkDeviceSize(chunks) * 4));
    CB_TRY(need(scratch.chunkOffsets, VkScratch::SplatChunkOffsets, VkDeviceSize(chunks + 1) * 4));
    // The scans' block sums (scan.comp): 256 entries a block, for the longer of the two scans.
    constexpr uint32_t kScanBlock = 256;
    CB_TRY(need(scratch.scanSums, VkScratch::SplatScanSums, VkDeviceSize(CeilDiv(std::max(chunks, screenTiles), kScanBlock)) * 4));
    CB_TRY(mContext->Upload(*scratch.frame, std::as_bytes(std::span(&frame, 1))));
    CB_TRY(mContext->Upload(*scratch.order, std::as_bytes(std::span(flat.indices))));
    CB_TRY(mContext->Upload(*scratch.boxes, std::as_bytes(std::span(boxes))));
    Pipeline* pipes[6] = {};
    const char* names[6] = {"splat_count", "scan", "splat_write", "splat_bin", "splat_composite", "splat_boxes"};
    const uint32_t bindings[6] = {8, 3, 8, 5, 6, 3};
    for (int n = 0; n < 6; ++n) {
        auto pipe = mContext->GetPipeline(names[n], bindings[n]);
        if (!pipe) return std::unexpected(pipe.error());
        pipes[n] = *pipe;
    }
    const DeviceBuffer* common[6] = {&Dev(*in.qPrev), &Dev(*in.qCur), &Dev(*in.T),
                                     scratch.order,   scratch.boxes,  scratch.frame};
    double deviceMs = 0;
    auto run = [&](const char* what, auto&& record) -> Status {
        CB_TRY(Record(what, record));
        deviceMs += mLastDeviceMs.value_or(0);
        return {};
    };
    // out = the exclusive prefix sum of n entries of in, and out[n] the total: three passes (scan.comp).
    auto scan = [&](VulkanContext::Recorder& r, const DeviceBuffer* in, const DeviceBuffer* out, uint32_t n) {
        struct {
            uint32_t n, mode;
        } push{n, 0};
        const DeviceBuffer* buffers[] = {in, out, scratch.scanSums};
        const uint32_t blocks = CeilDiv(n, kScanBlock);
        r.Dispatch(*pipes[1], buffers, &push, sizeof push, blocks);
        r.Barrier();
        push.mode = 1;
        r.Dispatch(*pipes[1], buffers, &push, sizeof push, 1);
        r.Barrier();
        push.mode = 2;
        r.Dispatch(*pipes[1], buffers, &push, sizeof push, blocks);
    };
    // 1. Splats per chunk of ranks, and their offsets.
    const uint32_t chunkPush = chunks;
    const DeviceBuffer* countBuffers[] = {common[0], common[1], common[2],           common[3],
                                          common[4], common[5], scratch.chunkSplats, scratch.chunkVisited};
    const uint32_t boxWords = CeilDiv(uint32_t(boxes.size()), 4);
    const DeviceBuffer* boxBuffers[] = {scratch.boxes, p.skipping ? &Dev(*in.bandsPrev) : scratch.boxes,
                                        p.skipping ? &Dev(*in.bandsCur) : scratch.boxes};
    CB_TRY(run("render_splat: counting splats", [&](VulkanContext::Recorder& r) {
        if (p.skipping) {
            r.Dispatch(*pipes[5], boxBuffers, &boxWords, sizeof boxWords, boxWords);
            r.Barrier();
        }
        r.Dispatch(*pipes[0], countBuffers, &chunkPush, sizeof chunkPush, chunks);
        r.Barrier();
        scan(r, scratch.chunkSplats, scratch.chunkOffsets, chunks);
    }));
    std::vector<uint32_t> chunkOffsets(chunks + 1);
    CB_TRY(mContext->Download(*scratch.chunkOffsets, std::as_writable_bytes(std::span(chunkOffsets))));
    const uint32_t splatCount = chunkOffsets[chunks];

    // 2. Write the splats in order; bin them by screen tile, keeping the order.
    const uint32_t splatChunks = std::max(1u, CeilDiv(splatCount, kSplatsPerChunk));
    CB_TRY(need(scratch.splats, VkScratch::Splats, VkDeviceSize(splatCount) * sizeof(Splat)));
    CB_TRY(need(scratch.binCounts, VkScratch::SplatBinCounts, VkDeviceSize(splatChunks) * screenTiles * 4));
    CB_TRY(need(scratch.tileTotals, VkScratch::SplatTileTotals, VkDeviceSize(screenTiles) * 4));
    CB_TRY(need(scratch.tileBases, VkScratch::SplatTileBases, VkDeviceSize(screenTiles + 1) * 4));
    struct {
        uint32_t mode, splatCount, chunkSize, chunks, tilesX, tilesY, tileSize;
    } bin{0, splatCount, kSplatsPerChunk, splatChunks, tilesX, tilesY, kTileSize};
    const DeviceBuffer* writeBuffers[] = {
        common[0], common[1], common[2], common[3], common[4], common[5], scratch.chunkOffsets, scratch.splats};
    // The list is sized in step 3; splat_bin's binding 4 needs a buffer in the first passes.
    CB_TRY(need(scratch.tileList, VkScratch::SplatTileList, 16));
    const DeviceBuffer* binBuffers[] = {scratch.splats, scratch.binCounts, scratch.tileTotals, scratch.tileBases,
                                        scratch.tileList};
    CB_TRY(run("render_splat: binning", [&](VulkanContext::Recorder& r) {
        r.Dispatch(*pipes[2], writeBuffers, &chunkPush, sizeof chunkPush, chunks);
        r.Barrier();
        r.Fill(*scratch.binCounts, 0);  // splat_bin's counts start at 0
        r.Barrier();
        bin.mode = 0;
        r.Dispatch(*pipes[3], binBuffers, &bin, sizeof bin, splatChunks);
        r.Barrier();
        bin.mode = 1;
        r.Dispatch(*pipes[3], binBuffers, &bin, sizeof bin, screenTiles);
        r.Barrier();
        scan(r, scratch.tileTotals, scratch.tileBases, screenTiles);
    }));
    std::vector<uint32_t> bases(screenTiles + 1);
    CB_TRY(mContext->Download(*scratch.tileBases, std::as_writable_bytes(std::span(bases))));

    // 3. Fill the tile lists; composite every pixel.
    CB_TRY(need(scratch.tileList, VkScratch::SplatTileList, VkDeviceSize(bases[screenTiles]) * 4));
    const DeviceBuffer* fillBuffers[] = {scratch.splats, scratch.binCounts, scratch.tileTotals, scratch.tileBases,
                                         scratch.tileList};
    struct {
        uint32_t width, height, tilesX, tileSize;
        float background[4];
        uint32_t ground;
    } composite{W, H, tilesX, kTileSize, {p.background[0], p.background[1], p.background[2], 0}, p.ground.on ? 1u : 0u};
    // The ground's block and G; without the ground, a buffer that exists (a binding needs one), unread.
    const DeviceBuffer* groundBlock = scratch.frame;
    const DeviceBuffer* groundG = scratch.frame;
    if (p.ground.on) {
        const GroundGpu block = MakeGroundGpu(p.camera, p.origin, p.voxelSize, MakeGroundLight(p), e.nx, e.ny);
        auto b = Scratch(VkScratch::GroundFrame, sizeof block);
        if (!b) return std::unexpected(b.error());
        CB_TRY(mContext->Upload(**b, std::as_bytes(std::span(&block, 1))));
        groundBlock = *b;
        groundG = &Dev(*in.G);
    }
    const DeviceBuffer* compositeBuffers[] = {scratch.splats, scratch.tileBases, scratch.tileList,
                                              &Dev(image),    groundBlock,       groundG};
    CB_TRY(run("render_splat: compositing", [&](VulkanContext::Recorder& r) {
        bin.mode = 2;
        r.Dispatch(*pipes[3], fillBuffers, &bin, sizeof bin, splatChunks);
        r.Barrier();
        r.DispatchGroups(*pipes[4], compositeBuffers, &composite, sizeof composite, tilesX, tilesY, 1);
    }));
    mLastDeviceMs = deviceMs;
    if (stats) {
        stats->splats = splatCount;
        stats->voxelsVisited = 0;  // not counted on this backend
        stats->fragments = 0;
    }
    return {};
}

}  // namespace cb::vk
