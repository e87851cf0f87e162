// Device-wide exclusive scans and stable sorts of (key, value) pairs by key,
// recorded into a command buffer (shaders/scan.comp, radix_sort.comp). Every
// invocation's loops are bounded by a block (256 entries, or more for very
// long inputs), never by the input: lavapipe ends an invocation's loops
// silently past 65535 iterations, and a GPU runs a long serial loop slowly.
// Deterministic: no atomics, so the same input gives the same bits.
#pragma once

#include <cstdint>

#include "impl_vk/VulkanContext.h"

namespace cb::vk {

// scan.comp's block: the entries one invocation sums in series.
constexpr uint32_t kScanBlock = 256;
// scan.comp's limit: at most 65535 blocks, so that its middle pass takes at most 256 rounds.
constexpr uint32_t kScanMaxEntries = kScanBlock * 65535u;

// The block sums a scan of n entries needs (its scratch buffer, in uints).
inline uint32_t ScanSumsEntries(uint32_t n) { return (n + kScanBlock - 1) / kScanBlock; }

// Records out[i] = in[0] + .. + in[i - 1] for i <= n (out[n]: the total), in
// three dispatches with barriers between; `sums` holds ScanSumsEntries(n)
// uints. n <= kScanMaxEntries. `scan` is the pipeline "scan" (3 bindings).
// The caller orders in's writes before it and out's reads after it (Barrier).
void RecordScan(VulkanContext::Recorder& r, Pipeline& scan, const DeviceBuffer& in, const DeviceBuffer& out,
                const DeviceBuffer& sums, uint32_t n);

// How RecordPairSort cuts its input: blocks of `block` pairs, one invocation
// each, and one pass per 8-bit digit of the largest key.
struct PairSortPlan {
    uint32_t pairs = 0, block = kScanBlock, blocks = 1, digits = 0;
    // Which of the two key and value buffers holds the sorted pairs.
    uint32_t Sorted() const { return digits % 2; }
    // Entries of the digit counts (and, plus one, of their scan).
    uint32_t CountEntries() const { return 256 * blocks; }
};
// Blocks of 256 pairs, or more where the counts' scan would pass kScanMaxEntries.
PairSortPlan PlanPairSort(uint32_t pairs, uint32_t largestKey);

// Records a stable sort of plan.pairs (keys[0][i], values[0][i]) by key, in
// plan.digits passes that alternate between the two buffers of each, so the
// result is in keys[plan.Sorted()], values[plan.Sorted()]. `counts` holds
// CountEntries() uints, `offsets` one more, `sums` ScanSumsEntries(CountEntries()).
// `sort` is the pipeline "radix_sort" (5 bindings), `scan` as for RecordScan.
// The caller orders the pairs' writes before it (Barrier) and its result before their reads.
void RecordPairSort(VulkanContext::Recorder& r, Pipeline& sort, Pipeline& scan, const PairSortPlan& plan,
                    const DeviceBuffer* const keys[2], const DeviceBuffer* const values[2], const DeviceBuffer& counts,
                    const DeviceBuffer& offsets, const DeviceBuffer& sums);

}  // namespace cb::vk
