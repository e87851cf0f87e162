// VulkanContext's submission (impl_vk/VulkanContext.h): the command buffer,
// segments bracketed by timestamp pairs, submitting and waiting (Flush), and
// batches (BeginBatch, MarkBatch, EndBatch).
#include "impl_vk/VulkanContext.h"

namespace cb::vk {

Status VulkanContext::EnsureRecording(const char* what) {
    if (mRecording) return {};
    CB_TRY(CheckVk(vkResetCommandBuffer(mCmd, 0), what));
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    CB_TRY(CheckVk(vkBeginCommandBuffer(mCmd, &begin), what));
    mRecording = true;
    return {};
}

Status VulkanContext::BeginSegment(const char* what) {
    if (mTimestamps && mRecording && mPairInterval.size() == kBatchStampPairs) CB_TRY(Flush(what));
    CB_TRY(EnsureRecording(what));
    if (mTimestamps) {
        const uint32_t first = uint32_t(2 * mPairInterval.size());
        vkCmdResetQueryPool(mCmd, mQueries, first, 2);
        // Bottom of pipe: written once every earlier command has completed, so the
        // pair spans this segment's work alone, also when it follows others in a batch.
        vkCmdWriteTimestamp(mCmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, mQueries, first);
        mPairInterval.push_back(mInterval);
    }
    return {};
}

Result<double> VulkanContext::EndSegment(const char* what) {
    if (mTimestamps)
        vkCmdWriteTimestamp(mCmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, mQueries,
                            uint32_t(2 * mPairInterval.size() - 1));
    if (mInBatch) {
        RecordFullBarrier();
    } else {
        CB_TRY(Flush(what));
    }
    if (mRecordError) {
        Error e = std::move(*mRecordError);
        mRecordError.reset();
        return std::unexpected(Error{std::string(what) + ": " + e.message});
    }
    return mInBatch ? 0.0 : mLastPairMs;
}

void VulkanContext::RecordFullBarrier() {
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                            VK_ACCESS_TRANSFER_WRITE_BIT;
    const VkPipelineStageFlags stages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    vkCmdPipelineBarrier(mCmd, stages, stages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

Status VulkanContext::Flush(const char* what) {
    if (!mRecording) return {};
    mRecording = false;
    // This submission's pairs; the next command buffer starts at pair 0 whatever happens below.
    const size_t pairs = mPairInterval.size();
    std::vector<uint32_t> intervals = std::move(mPairInterval);
    mPairInterval.clear();
    CB_TRY(CheckVk(vkEndCommandBuffer(mCmd), what));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &mCmd;
    CB_TRY(CheckVk(vkResetFences(mDevice, 1, &mFence), what));
    CB_TRY(CheckVk(vkQueueSubmit(mQueue, 1, &submit, mFence), what));
    ++mSubmissions;
    const VkResult waited = vkWaitForFences(mDevice, 1, &mFence, VK_TRUE, UINT64_MAX);
    ++mHostWaits;
    CB_TRY(CheckVk(waited, what));
    for (VkDescriptorPool pool : mDescriptors) vkResetDescriptorPool(mDevice, pool, 0);
    mDescriptorPool = 0;
    for (DeviceBuffer& b : mRetired) DestroyBuffer(b);
    mRetired.clear();
    // The arena's bytes stay until the next batch writes them: read the later reads first.
    for (LaterRead& read : std::exchange(mLaterReads, {}))
        read.done(std::span(static_cast<const std::byte*>(read.mapped), read.bytes));
    mArenaChunk = 0;
    mArenaOffset = 0;
    if (mTimestamps && pairs > 0) {
        // The fence has signalled, so every stamp is available: one read, no wait.
        std::vector<uint64_t> stamps(2 * pairs);
        CB_TRY(CheckVk(vkGetQueryPoolResults(mDevice, mQueries, 0, uint32_t(2 * pairs), stamps.size() * 8,
                                             stamps.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT),
                       what));
        for (size_t n = 0; n < pairs; ++n) {
            const double ms = double(stamps[2 * n + 1] - stamps[2 * n]) * mTimestampPeriodNs * 1e-6;
            if (intervals[n] < mIntervalMs.size()) mIntervalMs[intervals[n]] += ms;
            mLastPairMs = ms;
        }
    }
    return {};
}

Status VulkanContext::BeginBatch() {
    if (mInBatch) return MakeError("vk: batches do not nest");
    // Nothing is pending outside a batch: every call there has waited.
    mInBatch = true;
    mInterval = 0;
    mIntervalMs.assign(1, 0.0);
    return {};
}

void VulkanContext::MarkBatch() {
    if (!mInBatch) return;
    ++mInterval;
    mIntervalMs.push_back(0.0);
}

Result<std::vector<double>> VulkanContext::EndBatch() {
    if (!mInBatch) return MakeError("vk: EndBatch without BeginBatch");
    Status flushed = Flush("ending a batch");
    mInBatch = false;
    std::vector<double> ms = std::move(mIntervalMs);
    mIntervalMs.clear();
    mInterval = 0;
    if (!flushed) return std::unexpected(flushed.error());
    if (!mTimestamps) return std::vector<double>{};
    return ms;
}

}  // namespace cb::vk
