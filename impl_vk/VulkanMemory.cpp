// VulkanContext's memory (impl_vk/VulkanContext.h): storage buffers, the
// staging buffer, the host-visible arena a batch uploads through and reads
// back into, and Upload, Download and DownloadLater.
#include <algorithm>
#include <cstring>

#include "impl_vk/VulkanContext.h"

namespace cb::vk {

Result<DeviceBuffer> VulkanContext::CreateRawBuffer(VkDeviceSize size, VkBufferUsageFlags usage,
                                                    VkMemoryPropertyFlags properties) {
    DeviceBuffer b;
    b.size = size;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    CB_TRY(CheckVk(vkCreateBuffer(mDevice, &info, nullptr, &b.buffer), "creating a buffer"));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(mDevice, b.buffer, &req);
    uint32_t type = UINT32_MAX;
    for (uint32_t t = 0; t < mMemory.memoryTypeCount && type == UINT32_MAX; ++t)
        if ((req.memoryTypeBits & (1u << t)) && (mMemory.memoryTypes[t].propertyFlags & properties) == properties)
            type = t;
    if (type == UINT32_MAX) {
        vkDestroyBuffer(mDevice, b.buffer, nullptr);
        return MakeError("no suitable memory type for a buffer");
    }
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    VkResult r = vkAllocateMemory(mDevice, &alloc, nullptr, &b.memory);
    if (r != VK_SUCCESS) {
        vkDestroyBuffer(mDevice, b.buffer, nullptr);
        return std::unexpected(CheckVk(r, "allocating buffer memory").error());
    }
    CB_TRY(CheckVk(vkBindBufferMemory(mDevice, b.buffer, b.memory, 0), "binding buffer memory"));
    return b;
}

Result<DeviceBuffer> VulkanContext::CreateBuffer(VkDeviceSize size) {
    size = StorageBufferBytes(size);
    return CreateRawBuffer(
        size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
        VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
}

VkDeviceSize VulkanContext::LargestDeviceLocalHeap() const {
    VkDeviceSize largest = 0;
    for (uint32_t n = 0; n < mMemory.memoryHeapCount; ++n)
        if (mMemory.memoryHeaps[n].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            largest = std::max(largest, mMemory.memoryHeaps[n].size);
    return largest;
}

void VulkanContext::DestroyBuffer(DeviceBuffer& buffer) {
    if (mRecording && buffer.buffer) {
        mRetired.push_back(buffer);
        buffer = {};
        return;
    }
    if (buffer.buffer) vkDestroyBuffer(mDevice, buffer.buffer, nullptr);
    if (buffer.memory) vkFreeMemory(mDevice, buffer.memory, nullptr);
    buffer = {};
}

Status VulkanContext::EnsureStaging(VkDeviceSize size) {
    if (mStaging.size >= size) return {};
    if (mStagingMap) vkUnmapMemory(mDevice, mStaging.memory);
    mStagingMap = nullptr;
    DestroyBuffer(mStaging);
    auto staging = CreateRawBuffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                   VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    if (!staging) return std::unexpected(staging.error());
    mStaging = *staging;
    return CheckVk(vkMapMemory(mDevice, mStaging.memory, 0, VK_WHOLE_SIZE, 0, &mStagingMap),
                   "mapping the staging buffer");
}

Result<std::pair<const DeviceBuffer*, VkDeviceSize>> VulkanContext::ArenaSpace(VkDeviceSize size, void*& mapped) {
    constexpr VkDeviceSize kAlign = 16, kChunk = VkDeviceSize(4) << 20;
    while (mArenaChunk < mArena.size()) {
        ArenaChunk& chunk = mArena[mArenaChunk];
        const VkDeviceSize at = (mArenaOffset + kAlign - 1) & ~(kAlign - 1);
        if (at + size <= chunk.buffer.size) {
            mArenaOffset = at + size;
            mapped = static_cast<std::byte*>(chunk.mapped) + at;
            return std::pair<const DeviceBuffer*, VkDeviceSize>{&chunk.buffer, at};
        }
        ++mArenaChunk;
        mArenaOffset = 0;
    }
    // A further chunk; chunks stay for later batches (the arena keeps its high-water mark).
    auto created =
        CreateRawBuffer(std::max(size, kChunk), VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    if (!created) return std::unexpected(created.error());
    ArenaChunk chunk{*created, nullptr};
    if (Status mappedOk = CheckVk(vkMapMemory(mDevice, chunk.buffer.memory, 0, VK_WHOLE_SIZE, 0, &chunk.mapped),
                                  "mapping the upload arena");
        !mappedOk) {
        DestroyBuffer(chunk.buffer);
        return std::unexpected(mappedOk.error());
    }
    mArena.push_back(chunk);
    mArenaChunk = mArena.size() - 1;
    mArenaOffset = size;
    mapped = chunk.mapped;
    return std::pair<const DeviceBuffer*, VkDeviceSize>{&mArena.back().buffer, 0};
}

Status VulkanContext::Upload(const DeviceBuffer& buffer, std::span<const std::byte> data) {
    if (data.empty()) return {};
    if (!mInBatch) {
        CB_TRY(EnsureStaging(data.size()));
        std::memcpy(mStagingMap, data.data(), data.size());
        CB_TRY(BeginSegment("uploading a buffer"));
        const VkBufferCopy region{0, 0, data.size()};
        vkCmdCopyBuffer(mCmd, mStaging.buffer, buffer.buffer, 1, &region);
        auto done = EndSegment("uploading a buffer");
        if (!done) return std::unexpected(done.error());
        return {};
    }
    // In a batch: the bytes go to arena memory no recorded command reads yet;
    // the copy runs in order with the recorded commands.
    void* mapped = nullptr;
    auto space = ArenaSpace(data.size(), mapped);
    if (!space) return std::unexpected(space.error());
    std::memcpy(mapped, data.data(), data.size());
    CB_TRY(BeginSegment("uploading a buffer"));
    const VkBufferCopy region{space->second, 0, data.size()};
    vkCmdCopyBuffer(mCmd, space->first->buffer, buffer.buffer, 1, &region);
    auto done = EndSegment("uploading a buffer");
    if (!done) return std::unexpected(done.error());
    return {};
}

Status VulkanContext::Download(const DeviceBuffer& buffer, std::span<std::byte> data) {
    if (data.empty()) return {};
    // The staging buffer is read by no recorded command (batch uploads use the
    // arena, earlier downloads have completed), so it may grow here.
    CB_TRY(EnsureStaging(data.size()));
    CB_TRY(RecordCopyToHost(buffer, mStaging, 0, data.size(), "downloading a buffer"));
    if (mInBatch) CB_TRY(Flush("downloading a buffer"));
    std::memcpy(data.data(), mStagingMap, data.size());
    return {};
}

Status VulkanContext::RecordCopyToHost(const DeviceBuffer& from, const DeviceBuffer& to, VkDeviceSize offset,
                                       VkDeviceSize bytes, const char* what) {
    CB_TRY(BeginSegment(what));
    const VkBufferCopy region{0, offset, bytes};
    vkCmdCopyBuffer(mCmd, from.buffer, to.buffer, 1, &region);
    VkMemoryBarrier toHost{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(mCmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0, nullptr, 0,
                         nullptr);
    auto done = EndSegment(what);
    if (!done) return std::unexpected(done.error());
    return {};
}

Status VulkanContext::DownloadLater(const DeviceBuffer& buffer, VkDeviceSize bytes, ReadDone done) {
    if (!mInBatch) {
        std::vector<std::byte> data(bytes);
        CB_TRY(Download(buffer, data));
        done(data);
        return {};
    }
    void* mapped = nullptr;
    auto space = ArenaSpace(bytes, mapped);
    if (!space) return std::unexpected(space.error());
    CB_TRY(RecordCopyToHost(buffer, *space->first, space->second, bytes, "reading a result back later"));
    mLaterReads.push_back({mapped, bytes, std::move(done)});
    return {};
}

}  // namespace cb::vk
