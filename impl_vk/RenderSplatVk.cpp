// Stage `render_splat` (SPEC 8) on Vulkan: count, write, bin and composite the
// splats in the shared order (splat_*.comp, scan.comp, radix_sort.comp): bins
// are (screen tile, splat) pairs sorted stably by tile, so memory and every
// invocation's loop grow with the pairs, never with splats x tiles.
#include <algorithm>
#include <string>
#include <vector>

#include "core/math/Splat.h"
#include "core/pipeline/SplatFrame.h"
#include "impl_vk/BackendVk.h"
#include "impl_vk/PairSortVk.h"
#include "impl_vk/PushBlocks.h"
#include "impl_vk/RenderSplatVkState.h"

namespace cb::vk {
namespace {

// splat_ranks.glsl's RankParts entry: a position of one axis order.
struct RankPart {
    uint32_t coordinate, voxelShare, boxShare, pad;
};

// Per position of the outer, middle and inner axis orders (at flat.base): the
// coordinate, its share of the voxel index x + nx (y + ny z) and of the box index
// x / tile + tilesAcross (y / tile + tilesDown z / band) (SplatFrame.boxes).
std::vector<RankPart> MakeRankParts(const SplatFrame& F, const FlatSplatOrder& flat) {
    const uint32_t voxelStride[3] = {1, F.grid[0], F.grid[0] * F.grid[1]};
    const uint32_t boxSize[3] = {F.boxTile, F.boxTile, F.boxBand};
    const uint32_t boxStride[3] = {1, F.boxTilesX, F.boxTilesX * F.boxTilesY};
    std::vector<RankPart> parts(flat.indices.size());
    for (uint32_t level = 0; level < 3; ++level) {
        const uint32_t axis = F.axes[level];
        const uint32_t end = level < 2 ? flat.base[level + 1] : uint32_t(flat.indices.size());
        for (uint32_t n = flat.base[level]; n < end; ++n) {
            const uint32_t x = flat.indices[n];
            parts[n] = {x, x * voxelStride[axis], x / boxSize[axis] * boxStride[axis], 0};
        }
    }
    return parts;
}

}  // namespace

Status BackendVk::RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& image, SplatStats* stats) {
    RenderSplatVkState& state = mStages.Get<RenderSplatVkState>();
    if (!p.order || !in.qPrev || !in.qCur || !in.T)
        return MakeError("vk: render_splat needs q (both steps), T and an order");
    const Extent3 e = in.qCur->Extent();
    const bool skyLight = p.light.skyOn;
    if (skyLight) CB_TRY(CheckSkyInput(in.TSky, e, "render_splat"));
    if (image.Extent().nx != 3) return MakeError("vk: render_splat image must have extent (3, width, height)");
    const uint32_t W = image.Extent().ny, H = image.Extent().nz;
    CB_TRY(CheckGroundInput(p.ground, in.G, e, "vk: render_splat"));

    // Which tile x band boxes can hold a splat: the frustum (host geometry,
    // shared with the CPU, core/pipeline/Backend.h SplatBoxVisibility) and, when
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
    const FlatSplatOrder flat = FlattenSplatOrder(*p.order);
    // kTileSize: splat_composite.comp runs a workgroup of 64 per 8 x 8 tile.
    constexpr uint32_t kTileSize = 8;
    const uint32_t voxels = uint32_t(e.Count());
    // Ranks per invocation of the count and write passes (SetSplatChunkRanks), a
    // multiple of 32 (a word of candidate bits); one invocation per chunk, in at
    // most 65535 workgroups of 64.
    uint32_t ranksPerChunk = mSplatChunkRanks ? mSplatChunkRanks : mContext->CpuDevice() ? 1024 : 32;
    if (ranksPerChunk % 32 != 0) return MakeError("vk: render_splat's chunks must be a multiple of 32 ranks");
    while (CeilDiv(CeilDiv(voxels, ranksPerChunk), 64u) > 65535u) ranksPerChunk *= 2;
    const uint32_t tilesX = CeilDiv(W, kTileSize), tilesY = CeilDiv(H, kTileSize), screenTiles = tilesX * tilesY;
    // The shared frame; this backend's lanes: ranks per chunk, screen tiles.
    SplatFrame frame = MakeSplatFrame(p, e, flat, W, H);
    frame.ranksPerChunk = ranksPerChunk;
    frame.tilesX = tilesX;
    frame.tilesY = tilesY;
    const uint32_t chunks = CeilDiv(voxels, ranksPerChunk);
    const std::vector<RankPart> rankParts = MakeRankParts(frame, flat);
    // This stage's scratch buffers, one per slot of RenderSplatVkState (what each holds is said there).
    struct {
        DeviceBuffer *frame, *rankParts, *boxes, *candidates, *chunkSplats, *chunkPairs, *chunkOffsets, *chunkPairOffsets;
        DeviceBuffer* totals;
        DeviceBuffer *splats, *splatTiles, *pairOffsets, *keys[2], *values[2], *sortCounts, *sortOffsets, *tileBases;
        DeviceBuffer* scanSums;
    } scratch{};
    // At least 16 bytes: a binding needs a buffer even when nothing is in it.
    auto need = [&](DeviceBuffer*& buffer, BufferSlot& slot, VkDeviceSize bytes) -> Status {
        auto b = Scratch(slot, std::max<VkDeviceSize>(bytes, 16));
        if (!b) return std::unexpected(b.error());
        buffer = *b;
        return {};
    };
    CB_TRY(need(scratch.frame, state.frame, sizeof frame));
    CB_TRY(need(scratch.rankParts, state.rankParts, rankParts.size() * sizeof(RankPart)));
    CB_TRY(need(scratch.boxes, state.boxes, boxes.size()));
    CB_TRY(need(scratch.candidates, state.candidates, VkDeviceSize(chunks) * ranksPerChunk / 8));
    CB_TRY(need(scratch.chunkSplats, state.chunkSplats, VkDeviceSize(chunks) * 4));
    CB_TRY(need(scratch.chunkPairs, state.chunkPairs, VkDeviceSize(chunks) * 4));
    CB_TRY(need(scratch.chunkOffsets, state.chunkOffsets, VkDeviceSize(chunks + 1) * 4));
    CB_TRY(need(scratch.chunkPairOffsets, state.chunkPairOffsets, VkDeviceSize(chunks + 1) * 4));
    // What the host reads back: the splats, the pairs, then splat_count.comp's 64 slots of
    // (visited, fragments low, high), which it adds into.
    constexpr uint32_t kStatSlots = 64;
    CB_TRY(need(scratch.totals, state.totals, (2 + kStatSlots * 3) * 4));
    // The scans' block sums; sized again for the later, longer scans.
    CB_TRY(need(scratch.scanSums, state.scanSums, VkDeviceSize(ScanSumsEntries(chunks)) * 4));
    CB_TRY(mContext->Upload(*scratch.frame, std::as_bytes(std::span(&frame, 1))));
    CB_TRY(mContext->Upload(*scratch.rankParts, std::as_bytes(std::span(rankParts))));
    CB_TRY(mContext->Upload(*scratch.boxes, std::as_bytes(std::span(boxes))));
    enum { kCount, kScan, kWrite, kPairs, kSort, kRanges, kComposite, kBoxes, kPipes };
    Pipeline* pipes[kPipes] = {};
    const char* names[kPipes] = {"splat_count",  "scan",           "splat_write",    "splat_pairs",
                                 "radix_sort",   "splat_ranges",   "splat_composite", "splat_boxes"};
    const uint32_t bindings[kPipes] = {12, 3, 12, 4, 5, 2, 6, 3};
    for (int n = 0; n < kPipes; ++n) {
        auto pipe = mContext->GetPipeline(names[n], bindings[n]);
        if (!pipe) return std::unexpected(pipe.error());
        pipes[n] = *pipe;
    }
    const DeviceBuffer* common[6] = {&Dev(*in.qPrev), &Dev(*in.qCur), &Dev(*in.T),
                                     scratch.rankParts, scratch.boxes, scratch.frame};
    // splat_ranks.glsl's phase table: kMieCloudTable with phase Mie; else the frame stands in, unread.
    const DeviceBuffer* phaseTable = scratch.frame;
    if (p.light.phase.kind == PhaseKind::Mie) {
        auto t = MiePhaseTable(state.mieTable);
        if (!t) return std::unexpected(t.error());
        phaseTable = *t;
    }
    // splat_ranks.glsl's T_sky with the sky light; else T stands in, unread.
    const DeviceBuffer* skyT = skyLight ? &Dev(*in.TSky) : &Dev(*in.T);
    double deviceMs = 0;
    auto run = [&](const char* what, auto&& record) -> Status {
        CB_TRY(Record(what, record));
        deviceMs += mLastDeviceMs.value_or(0);
        return {};
    };
    auto scan = [&](VulkanContext::Recorder& r, const DeviceBuffer* in, const DeviceBuffer* out, uint32_t n) {
        RecordScan(r, *pipes[kScan], *in, *out, *scratch.scanSums, n);
    };
    // 1. Splats and (screen tile, splat) pairs per chunk of ranks, their offsets,
    //    and both totals, which size everything after: the one host wait.
    SplatChunksPush chunkPush{chunks, kTileSize};
    const DeviceBuffer* countBuffers[] = {common[0],          common[1],      common[2],           common[3],
                                          common[4],          common[5],      scratch.chunkSplats, scratch.chunkPairs,
                                          scratch.candidates, scratch.totals, phaseTable,          skyT};
    const SplatBoxesPush boxPush{CeilDiv(uint32_t(boxes.size()), 4)};
    const DeviceBuffer* boxBuffers[] = {scratch.boxes, p.skipping ? &Dev(*in.bandsPrev) : scratch.boxes,
                                        p.skipping ? &Dev(*in.bandsCur) : scratch.boxes};
    CB_TRY(run("render_splat: counting splats", [&](VulkanContext::Recorder& r) {
        if (p.skipping) {
            r.Dispatch(*pipes[kBoxes], boxBuffers, &boxPush, sizeof boxPush, boxPush.words);
            r.Barrier();
        }
        r.Fill(*scratch.totals, 0);
        r.Barrier();
        r.Dispatch(*pipes[kCount], countBuffers, &chunkPush, sizeof chunkPush, chunks);
        r.Barrier();
        scan(r, scratch.chunkSplats, scratch.chunkOffsets, chunks);
        r.Barrier();
        scan(r, scratch.chunkPairs, scratch.chunkPairOffsets, chunks);
        r.Copy(*scratch.chunkOffsets, VkDeviceSize(chunks) * 4, *scratch.totals, 0, 4);
        r.Copy(*scratch.chunkPairOffsets, VkDeviceSize(chunks) * 4, *scratch.totals, 4, 4);
    }));
    uint32_t totals[2 + kStatSlots * 3] = {};
    CB_TRY(mContext->Download(*scratch.totals, std::as_writable_bytes(std::span(totals))));
    const uint32_t splatCount = totals[0], pairCount = totals[1];
    uint64_t visited = 0, fragments = 0;
    for (uint32_t slot = 0; slot < kStatSlots; ++slot) {
        const uint32_t* stat = totals + 2 + 3 * slot;
        visited += stat[0];
        fragments += uint64_t(stat[2]) << 32 | stat[1];
    }

    // 2. Write the splats in order, their pairs in order, and sort the pairs by
    //    screen tile, stably (radix_sort.comp: 8-bit digits, as many as the
    //    largest tile index has), so that each tile's splats keep the order.
    const PairSortPlan sortPlan = PlanPairSort(pairCount, screenTiles - 1);
    if (splatCount > kScanMaxEntries)
        return MakeError("vk: render_splat makes " + std::to_string(splatCount) + " splats, over the " +
                         std::to_string(kScanMaxEntries) + " its scan of their tiles can take");
    CB_TRY(need(scratch.splats, state.splats, VkDeviceSize(splatCount) * sizeof(Splat)));
    CB_TRY(need(scratch.splatTiles, state.splatTiles, VkDeviceSize(splatCount) * 4));
    CB_TRY(need(scratch.pairOffsets, state.pairOffsets, VkDeviceSize(splatCount + 1) * 4));
    CB_TRY(need(scratch.keys[0], state.keys[0], VkDeviceSize(pairCount) * 4));
    CB_TRY(need(scratch.values[0], state.values[0], VkDeviceSize(pairCount) * 4));
    const VkDeviceSize swapBytes = sortPlan.digits ? VkDeviceSize(pairCount) * 4 : 0;
    CB_TRY(need(scratch.keys[1], state.keys[1], swapBytes));
    CB_TRY(need(scratch.values[1], state.values[1], swapBytes));
    CB_TRY(need(scratch.sortCounts, state.sortCounts, VkDeviceSize(sortPlan.CountEntries()) * 4));
    CB_TRY(need(scratch.sortOffsets, state.sortOffsets, (VkDeviceSize(sortPlan.CountEntries()) + 1) * 4));
    CB_TRY(need(scratch.tileBases, state.tileBases, VkDeviceSize(screenTiles + 1) * 4));
    const uint32_t longestScan = std::max({chunks, splatCount, sortPlan.CountEntries()});
    CB_TRY(need(scratch.scanSums, state.scanSums, VkDeviceSize(ScanSumsEntries(longestScan)) * 4));
    const DeviceBuffer* writeBuffers[] = {
        common[0],      common[1],          common[2],          common[3],  common[4], common[5], scratch.chunkOffsets,
        scratch.splats, scratch.splatTiles, scratch.candidates, phaseTable, skyT};
    SplatPairsPush pairPush{splatCount, tilesX, kTileSize};
    const DeviceBuffer* pairBuffers[] = {scratch.splats, scratch.pairOffsets, scratch.keys[0], scratch.values[0]};
    // One invocation per splat, in rows of kRowGroups workgroups (splat_tiles.glsl LinearInvocation).
    constexpr uint32_t kRowGroups = 32768;
    const uint32_t splatGroups = std::max(1u, CeilDiv(splatCount, 64u));
    SplatRangesPush rangePush{pairCount, screenTiles};
    SplatCompositePush composite{W, H, tilesX, kTileSize, p.background, p.ground.on ? 1u : 0u};
    // The ground's block and G; without the ground, a buffer that exists (a binding needs one), unread.
    const DeviceBuffer* groundBlock = scratch.frame;
    const DeviceBuffer* groundG = scratch.frame;
    if (p.ground.on) {
        const GroundGpu block = MakeGroundGpu(p.camera, p.origin, p.voxelSize, MakeGroundLight(p), e.nx, e.ny);
        auto b = Scratch(state.ground, sizeof block);
        if (!b) return std::unexpected(b.error());
        CB_TRY(mContext->Upload(**b, std::as_bytes(std::span(&block, 1))));
        groundBlock = *b;
        groundG = &Dev(*in.G);
    }
    const uint32_t sorted = sortPlan.Sorted();
    const DeviceBuffer* rangeBuffers[] = {scratch.keys[sorted], scratch.tileBases};
    const DeviceBuffer* compositeBuffers[] = {scratch.splats, scratch.tileBases, scratch.values[sorted],
                                              &Dev(image),    groundBlock,       groundG};
    CB_TRY(run("render_splat: binning and compositing", [&](VulkanContext::Recorder& r) {
        r.Dispatch(*pipes[kWrite], writeBuffers, &chunkPush, sizeof chunkPush, chunks);
        r.Barrier();
        scan(r, scratch.splatTiles, scratch.pairOffsets, splatCount);
        r.Barrier();
        r.DispatchGroups(*pipes[kPairs], pairBuffers, &pairPush, sizeof pairPush, std::min(splatGroups, kRowGroups),
                         CeilDiv(splatGroups, kRowGroups), 1);
        r.Barrier();
        RecordPairSort(r, *pipes[kSort], *pipes[kScan], sortPlan, scratch.keys, scratch.values, *scratch.sortCounts,
                       *scratch.sortOffsets, *scratch.scanSums);
        r.Barrier();
        // 3. Each tile's first pair, by binary search; composite every pixel.
        r.Dispatch(*pipes[kRanges], rangeBuffers, &rangePush, sizeof rangePush, screenTiles + 1);
        r.Barrier();
        r.DispatchGroups(*pipes[kComposite], compositeBuffers, &composite, sizeof composite, tilesX, tilesY, 1);
    }));
    mLastDeviceMs = deviceMs;
    if (stats) {
        stats->splats = splatCount;
        stats->voxelsVisited = visited;
        stats->fragments = fragments;
    }
    return {};
}

}  // namespace cb::vk
