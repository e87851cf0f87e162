// Stage `shade` (SPEC 6) on Vulkan: inverse shear-warp, one shade_slice.comp
// dispatch per slice; at resolution 2 or 4 on a coarse grid (shade_down.comp,
// shade_up.comp). A share [m0, m1) of the sweep (SPEC 13) dispatches the slices
// m0 .. m1 - 1 in visiting order; at f > 1 the share with m = 0 also down-samples
// q and the share ending at nw up-samples into T. The coarse q and T
// (VkScratch::ShadeCoarseQ/T) carry the sweep from one share to the next.
#include "core/ShadePlan.h"
#include "impl_vk/StageVk.h"

namespace cb::vk {

Status BackendVk::Shade(const ShadeParams& params, const Buffer& q, Buffer& T) {
    const int f = params.resolution;
    if (f != 1 && f != 2 && f != 4) return MakeError("vk: shade resolution must be 1, 2 or 4");
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
        auto cq = Scratch(VkScratch::ShadeCoarseQ, coarseBytes);
        if (!cq) return std::unexpected(cq.error());
        auto ct = Scratch(VkScratch::ShadeCoarseT, coarseBytes);
        if (!ct) return std::unexpected(ct.error());
        shadeQ = *cq;
        shadeT = *ct;
    }
    auto slice = mContext->GetPipeline("shade_slice", 2);
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
    struct {
        uint32_t nu, nv, strideU, strideV, sliceBase, prevBase;
        int32_t u0, v0;
        float fu, fv;
        uint32_t first, beer;
        float depthPerQ, thesisAr, scatterGain;
        uint32_t storage;
    } push{n[g.u],
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
    struct {
        uint32_t nx, ny, nz, cx, cy, cz, f;
    } resample{e.nx, e.ny, e.nz, n[0], n[1], n[2], uint32_t(f)};
    const DeviceBuffer* sliceBuffers[] = {shadeQ, shadeT};
    const DeviceBuffer* downBuffers[] = {&Dev(q), shadeQ};
    const DeviceBuffer* upBuffers[] = {shadeT, &Dev(T)};
    return Record("shade", [&](VulkanContext::Recorder& r) {
        if (down) {
            r.Dispatch(*down, downBuffers, &resample, sizeof resample, n[0] * n[1] * n[2]);
            r.Barrier();
        }
        uint32_t previous = m0 > 0 ? plan.SliceW(m0 - 1) : 0;
        for (uint32_t m = m0; m < m1; ++m) {
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
