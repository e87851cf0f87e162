// Device-wide scans and stable pair sorts (PairSortVk.h).
#include "impl_vk/PairSortVk.h"

#include <algorithm>

#include "impl_vk/PushBlocks.h"

namespace cb::vk {

void RecordScan(VulkanContext::Recorder& r, Pipeline& scan, const DeviceBuffer& in, const DeviceBuffer& out,
                const DeviceBuffer& sums, uint32_t n) {
    ScanPush push{n, 0};
    const DeviceBuffer* buffers[] = {&in, &out, &sums};
    const uint32_t blocks = ScanSumsEntries(n);
    r.Dispatch(scan, buffers, &push, sizeof push, blocks);
    r.Barrier();
    push.mode = 1;
    r.Dispatch(scan, buffers, &push, sizeof push, 1);
    r.Barrier();
    push.mode = 2;
    r.Dispatch(scan, buffers, &push, sizeof push, blocks);
}

PairSortPlan PlanPairSort(uint32_t pairs, uint32_t largestKey) {
    PairSortPlan plan;
    plan.pairs = pairs;
    // 256 x blocks <= kScanMaxEntries, so blocks <= 65535.
    plan.block = std::max(kScanBlock, (pairs + 65534u) / 65535u);
    plan.blocks = std::max(1u, (pairs + plan.block - 1) / plan.block);
    for (uint32_t key = largestKey; key != 0; key >>= 8) ++plan.digits;
    return plan;
}

void RecordPairSort(VulkanContext::Recorder& r, Pipeline& sort, Pipeline& scan, const PairSortPlan& plan,
                    const DeviceBuffer* const keys[2], const DeviceBuffer* const values[2], const DeviceBuffer& counts,
                    const DeviceBuffer& offsets, const DeviceBuffer& sums) {
    RadixSortPush push{plan.pairs, 0, plan.block, plan.blocks, 0};
    for (uint32_t digit = 0; digit < plan.digits; ++digit) {
        const uint32_t from = digit % 2, to = 1 - from;
        const DeviceBuffer* countPass[] = {keys[from], values[from], &counts, keys[to], values[to]};
        const DeviceBuffer* scatterPass[] = {keys[from], values[from], &offsets, keys[to], values[to]};
        push.shift = 8 * digit;
        push.mode = 0;
        if (digit > 0) r.Barrier();
        r.Dispatch(sort, countPass, &push, sizeof push, plan.blocks);
        r.Barrier();
        RecordScan(r, scan, counts, offsets, sums, plan.CountEntries());
        r.Barrier();
        push.mode = 1;
        r.Dispatch(sort, scatterPass, &push, sizeof push, plan.blocks);
    }
}

}  // namespace cb::vk
