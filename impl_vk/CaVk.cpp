// Stage `ca` (SPEC 3) on Vulkan: the initial state (ca_init.comp) and a step
// (ca.comp, then advect.comp when any slice has wind).
#include <cassert>
#include <iterator>
#include <vector>

#include "impl_vk/BackendVk.h"
#include "impl_vk/CaVkState.h"
#include "impl_vk/PushBlocks.h"

namespace cb::vk {
uint64_t CaVkState::ScratchBytes(const Scene& scene) const {
    if (!scene.ca.HasWind()) return 0;
    const Extent3 e = scene.grid.size;
    return 3 * VulkanContext::StorageBufferBytes(VkDeviceSize(CeilDiv(e.nx, 32)) * e.ny * e.nz * 4);
}

Status BackendVk::CaInitialize(const CaInitParams& params, CaFields out) {
    const Extent3 e = out.hum->Extent();
    auto pipeline = mContext->GetPipeline("ca_init", 3);
    if (!pipeline) return std::unexpected(pipeline.error());
    const uint32_t words = (e.nx + 31) / 32;
    CaInitPush push{e.nx, e.ny, e.nz, words, params.seed, params.qHum0, params.qAct0};
    const DeviceBuffer* buffers[] = {&Dev(*out.hum), &Dev(*out.act), &Dev(*out.cld)};
    return Record("ca initial state", [&](VulkanContext::Recorder& r) {
        r.Dispatch(**pipeline, buffers, &push, sizeof push, words * e.ny * e.nz);
    });
}

Status BackendVk::CaStep(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) {
    const Extent3 e = in.hum->Extent();
    const uint32_t words = (e.nx + 31) / 32;
    // The share's slices [k0, k1): both dispatches cover those slices' words only.
    const uint32_t k0 = params.slices.Begin(e.nz), k1 = params.slices.End(e.nz);
    if (k0 >= k1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    const uint32_t first = words * e.ny * k0, end = words * e.ny * k1;  // the share's words
    auto rules =
        mContext->GetPipeline("ca", 7, params.slices.IsWhole(e.nz) ? PipelineRange::Whole : PipelineRange::Share);
    if (!rules) return std::unexpected(rules.error());
    bool wind = false;
    for (size_t k = 0; k < params.shiftX.size(); ++k) wind |= params.shiftX[k] != 0 || params.shiftY[k] != 0;

    CaStepPush push{e.nx,        e.ny,        e.nz,        words, params.seed, params.step,
                    params.qExt, params.qHum, params.qAct, first, end};
    const DeviceBuffer* targets[3] = {&Dev(*out.hum), &Dev(*out.act), &Dev(*out.cld)};
    Pipeline* advect = nullptr;
    DeviceBuffer* shifts = nullptr;
    if (wind) {
        // The rules write into scratch; advection moves the result into `out`.
        // Advection shifts within a slice, so a share needs only its own slices.
        for (size_t f = 0; f < 3; ++f) {
            auto s = Scratch(mStages.Get<CaVkState>().rules[f], VkDeviceSize(words) * e.ny * e.nz * 4);
            if (!s) return std::unexpected(s.error());
            targets[f] = *s;
        }
        std::vector<int32_t> packed;
        for (size_t k = 0; k < params.shiftX.size(); ++k) {
            packed.push_back(params.shiftX[k]);
            packed.push_back(params.shiftY[k]);
        }
        auto s = ScratchHolding(mStages.Get<CaVkState>().windShifts, std::as_bytes(std::span(packed)), 8);
        if (!s) return std::unexpected(s.error());
        shifts = *s;
        auto p = mContext->GetPipeline("advect", 7,
                                       params.slices.IsWhole(e.nz) ? PipelineRange::Whole : PipelineRange::Share);
        if (!p) return std::unexpected(p.error());
        advect = *p;
    }
    const DeviceBuffer* buffers[] = {&Dev(*in.hum), &Dev(*in.act), &Dev(*in.cld), &Dev(region),
                                     targets[0],    targets[1],    targets[2]};
    return Record("ca step", [&](VulkanContext::Recorder& r) {
        r.DispatchRange(**rules, buffers, &push, sizeof push, first, end);
        if (advect) {
            r.Barrier();
            AdvectPush advectPush{e.nx, e.ny, words, first, end};
            const DeviceBuffer* advectBuffers[] = {targets[0],     targets[1],     targets[2], &Dev(*out.hum),
                                                   &Dev(*out.act), &Dev(*out.cld), shifts};
            r.DispatchRange(*advect, advectBuffers, &advectPush, sizeof advectPush, first, end);
        }
    });
}

}  // namespace cb::vk
