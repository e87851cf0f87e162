// Stage `shade` (SPEC 6) on Vulkan: inverse shear-warp, 16 slices (8 at a
// 45-degree tie) per shade_block.comp dispatch (tiles of the slice plane that
// carry the dependency cone in shared memory), with a barrier between
// dispatches; at resolution 2 or 4 on a coarse grid (shade_down.comp,
// shade_up.comp). A share [m0, m1) of the sweep (SPEC 13) computes the slices
// m0 .. m1 - 1 in visiting order; at f > 1 the share with m = 0 also down-samples
// q and the share ending at nw up-samples into T. The coarse q and T
// (ShadeVkState's coarseQ and coarseT) carry the sweep from one share to the next.
// Stage `shade_sky` runs the same sweep toward the sky light into T_sky, with coarse
// grids of its own (ShadeSkyVkState), so that it may come between two shares of the
// sun's sweep, in a batch too: each call is one segment of the batch's command buffer,
// ordered after the one before by the segment's barrier.
// The reference path, one shade_slice.comp dispatch per slice, is what a CPU
// device (lavapipe) runs by default (BackendVk::ShadeSweep; the tests compare the
// two byte for byte).
#include <algorithm>

#include "core/pipeline/ShadePlan.h"
#include "impl_vk/BackendVk.h"
#include "impl_vk/PushBlocks.h"
#include "impl_vk/ShadeVkState.h"

namespace cb::vk {
namespace {

// shade_block.comp's kTile and kHalo: 32 x 32 tiles, and a region at most 16
// cells wider, which is 16 slices a dispatch where the tap offsets are -1 or 0
// (one cell of cone per slice) and 8 where one is +1 (a 45-degree tie: two).
// Its shared memory holds two slices of the widest region, (32 + 16)^2 floats
// each: 18 KiB of the 32 KiB that Vulkan guarantees (maxComputeSharedMemorySize).
// 16 slices cut 256 dispatches to 16; the regions hold on average up to 1.54
// times the tile's cells (1.23 where the plane ends within one axis's halo), work
// a larger tile would lower but with fewer groups to spread over a GPU (a 256 x 32
// plane is 8 groups already). On lavapipe, where a dispatch is cheap next to the
// cells, that extra work makes this path slower than the per-slice one
// (docs/performance.md); it is for GPUs, where each dispatch and barrier is a few
// microseconds of a dependent chain.
constexpr uint32_t kShadeBlockTile = 32;
constexpr int kShadeBlockHalo = 16;

// Slices a shade_block dispatch computes from the one before it: the cone grows
// by max(o + 1, 0) - min(o, 0) cells a slice along an axis whose tap offset is o.
uint32_t ShadeBlockSteps(int u0, int v0) {
    auto growth = [](int o) { return std::max(o + 1, 0) - std::min(o, 0); };
    return uint32_t(std::max(1, kShadeBlockHalo / std::max(growth(u0), growth(v0))));
}

}  // namespace

uint64_t ShadeVkState::ScratchBytes(const Scene& scene) const {
    const uint32_t f = uint32_t(std::max(scene.shade.resolution, 1));
    if (f == 1) return 0;
    const Extent3 e = scene.grid.size;
    return 2 * Extent3{CeilDiv(e.nx, f), CeilDiv(e.ny, f), CeilDiv(e.nz, f)}.Count() * 4;
}

Status BackendVk::Shade(const ShadeParams& params, const Buffer& q, Buffer& T) {
    return ShadeInto(mStages.Get<ShadeVkState>(), "shade", params, q, T);
}

Status BackendVk::ShadeSky(const ShadeParams& params, const Buffer& q, Buffer& T) {
    return ShadeInto(mStages.Get<ShadeSkyVkState>(), "shade_sky", params, q, T);
}

Status BackendVk::ShadeInto(ShadeVkState& state, const char* stage, const ShadeParams& params, const Buffer& q,
                            Buffer& T) {
    const int f = params.resolution;
    CB_TRY(CheckShadeResolution("vk", f));
    const Extent3 e = q.Extent();
    const ShadePlan plan = MakeShadePlan(params, e);
    const uint32_t* n = plan.cells;
    const uint32_t nw = plan.nw;
    const uint32_t m0 = params.slices.Begin(nw), m1 = params.slices.End(nw);
    if (m0 >= m1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    const VkDeviceSize coarseBytes = VkDeviceSize(n[0]) * n[1] * n[2] * 4;
    const DeviceBuffer* shadeQ = &Dev(q);
    const DeviceBuffer* shadeT = &Dev(T);
    if (f > 1) {
        auto cq = Scratch(state.coarseQ, coarseBytes);
        if (!cq) return std::unexpected(cq.error());
        auto ct = Scratch(state.coarseT, coarseBytes);
        if (!ct) return std::unexpected(ct.error());
        shadeQ = *cq;
        shadeT = *ct;
    }
    const bool perSlice =
        mShadeSweep == ShadeSweep::PerSlice || (mShadeSweep == ShadeSweep::Auto && mContext->CpuDevice());
    auto slice = mContext->GetPipeline(perSlice ? "shade_slice" : "shade_block", 2);
    if (!slice) return std::unexpected(slice.error());
    Pipeline* down = nullptr;
    Pipeline* up = nullptr;
    if (f > 1 && m0 == 0) {
        auto d = mContext->GetPipeline("shade_down", 2);
        if (!d) return std::unexpected(d.error());
        down = *d;
    }
    if (f > 1 && m1 == nw) {
        auto u = mContext->GetPipeline("shade_up", 2);
        if (!u) return std::unexpected(u.error());
        up = *u;
    }
    const ShearWarp& g = plan.geometry;
    const SliceAttenuation& a = plan.attenuation;
    const uint32_t stride[3] = {1, n[0], n[0] * n[1]};
    ShadeSlicePush push{n[g.u],
                        n[g.v],
                        stride[g.u],
                        stride[g.v],
                        0,
                        0,
                        g.u0,
                        g.v0,
                        g.fu,
                        g.fv,
                        0,
                        a.kind == AttenuationKind::Beer ? 1u : 0u,
                        a.opticalDepthPerQ,
                        a.thesisAr,
                        a.scatterGain,
                        uint32_t(params.storage)};
    ShadeBlockPush block{n[g.u],
                         n[g.v],
                         stride[g.u],
                         stride[g.v],
                         stride[g.w],
                         nw,
                         g.sunAbove ? 1u : 0u,
                         0,
                         0,
                         g.u0,
                         g.v0,
                         g.fu,
                         g.fv,
                         push.beer,
                         a.opticalDepthPerQ,
                         a.thesisAr,
                         a.scatterGain,
                         uint32_t(params.storage)};
    ShadeResamplePush resample{e.nx, e.ny, e.nz, n[0], n[1], n[2], uint32_t(f)};
    const DeviceBuffer* sliceBuffers[] = {shadeQ, shadeT};
    const DeviceBuffer* downBuffers[] = {&Dev(q), shadeQ};
    const DeviceBuffer* upBuffers[] = {shadeT, &Dev(T)};
    return Record(stage, [&](VulkanContext::Recorder& r) {
        if (down) {
            r.Dispatch(*down, downBuffers, &resample, sizeof resample, n[0] * n[1] * n[2]);
            r.Barrier();
        }
        if (!perSlice) {
            // A dispatch from slice 0 computes it and `steps` more.
            const uint32_t steps = ShadeBlockSteps(g.u0, g.v0);
            const uint32_t groupsU = (n[g.u] + kShadeBlockTile - 1) / kShadeBlockTile;
            const uint32_t groupsV = (n[g.v] + kShadeBlockTile - 1) / kShadeBlockTile;
            for (uint32_t m = m0; m < m1; m = block.end) {
                block.begin = m;
                block.end = std::min(m1, m + steps + (m == 0 ? 1u : 0u));
                r.DispatchGroups(**slice, sliceBuffers, &block, sizeof block, groupsU, groupsV, 1);
                r.Barrier();
            }
        }
        uint32_t previous = m0 > 0 ? plan.SliceW(m0 - 1) : 0;
        for (uint32_t m = perSlice ? m0 : m1; m < m1; ++m) {
            const uint32_t wIndex = plan.SliceW(m);
            push.first = m == 0 ? 1u : 0u;
            push.sliceBase = wIndex * stride[g.w];
            push.prevBase = previous * stride[g.w];
            r.Dispatch(**slice, sliceBuffers, &push, sizeof push, n[g.u] * n[g.v]);
            r.Barrier();
            previous = wIndex;
        }
        if (up) r.Dispatch(*up, upBuffers, &resample, sizeof resample, uint32_t(e.Count()));
    });
}

}  // namespace cb::vk
