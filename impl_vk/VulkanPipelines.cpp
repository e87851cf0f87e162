// VulkanContext's compute pipelines (impl_vk/VulkanContext.h): pipelines from
// the build's SPIR-V or a test's, the descriptor pools their sets come from,
// and the Recorder that binds and dispatches them.
#include <cassert>

#include "impl_vk/Shaders.h"
#include "impl_vk/VulkanContext.h"

namespace cb::vk {

Result<Pipeline*> VulkanContext::GetPipeline(const std::string& name, uint32_t bindings, PipelineRange range) {
    const bool ranged = range == PipelineRange::Share;
    const std::string key = ranged ? name + "/ranged" : name;
    if (auto it = mPipelines.find(key); it != mPipelines.end()) return &it->second;
    std::span<const uint32_t> spirv = FindShader(name);
    if (spirv.empty()) return MakeError("no compiled shader named '" + name + "'");
    return CreatePipeline(key, bindings, spirv, ranged);
}

Result<Pipeline*> VulkanContext::GetPipeline(const std::string& name, uint32_t bindings,
                                             std::span<const uint32_t> spirv) {
    if (auto it = mPipelines.find(name); it != mPipelines.end()) return &it->second;
    return CreatePipeline(name, bindings, spirv, false);
}

Result<Pipeline*> VulkanContext::CreatePipeline(const std::string& name, uint32_t bindings,
                                                std::span<const uint32_t> spirv, bool ranged) {
    Pipeline p;
    p.bindings = bindings;
    p.ranged = ranged;
    std::vector<VkDescriptorSetLayoutBinding> b(bindings);
    for (uint32_t n = 0; n < bindings; ++n)
        b[n] = {n, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    setInfo.bindingCount = bindings;
    setInfo.pBindings = b.data();
    const std::string what = "creating the " + name + " pipeline";
    CB_TRY(CheckVk(vkCreateDescriptorSetLayout(mDevice, &setInfo, nullptr, &p.setLayout), what.c_str()));
    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, 128};
    VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout.setLayoutCount = 1;
    layout.pSetLayouts = &p.setLayout;
    layout.pushConstantRangeCount = 1;
    layout.pPushConstantRanges = &push;
    CB_TRY(CheckVk(vkCreatePipelineLayout(mDevice, &layout, nullptr, &p.layout), what.c_str()));
    VkShaderModuleCreateInfo module{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    module.codeSize = spirv.size_bytes();
    module.pCode = spirv.data();
    VkShaderModule shader = VK_NULL_HANDLE;
    CB_TRY(CheckVk(vkCreateShaderModule(mDevice, &module, nullptr, &shader), what.c_str()));
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = shader;
    info.stage.pName = "main";
    info.layout = p.layout;
    const VkBool32 kRanged = VK_TRUE;
    const VkSpecializationMapEntry rangedEntry{0, 0, sizeof kRanged};
    const VkSpecializationInfo specialization{1, &rangedEntry, sizeof kRanged, &kRanged};
    if (ranged) {
        info.flags = VK_PIPELINE_CREATE_DISPATCH_BASE_BIT;
        info.stage.pSpecializationInfo = &specialization;
    }
    VkResult r = vkCreateComputePipelines(mDevice, VK_NULL_HANDLE, 1, &info, nullptr, &p.pipeline);
    vkDestroyShaderModule(mDevice, shader, nullptr);
    CB_TRY(CheckVk(r, what.c_str()));
    return &(mPipelines[name] = p);
}

Status VulkanContext::AddDescriptorPool() {
    // Enough sets for a few stage calls: shading records one dispatch per slice.
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 32768};
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.maxSets = 8192;
    dp.poolSizeCount = 1;
    dp.pPoolSizes = &size;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    CB_TRY(CheckVk(vkCreateDescriptorPool(mDevice, &dp, nullptr, &pool), "creating a descriptor pool"));
    mDescriptors.push_back(pool);
    return {};
}

Result<VkDescriptorSet> VulkanContext::AllocateSet(VkDescriptorSetLayout layout) {
    for (;;) {
        VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        alloc.descriptorPool = mDescriptors[mDescriptorPool];
        alloc.descriptorSetCount = 1;
        alloc.pSetLayouts = &layout;
        VkDescriptorSet set = VK_NULL_HANDLE;
        const VkResult r = vkAllocateDescriptorSets(mDevice, &alloc, &set);
        if (r == VK_SUCCESS) return set;
        if (r != VK_ERROR_OUT_OF_POOL_MEMORY && r != VK_ERROR_FRAGMENTED_POOL)
            return std::unexpected(CheckVk(r, "allocating a descriptor set").error());
        // This pool is full until the next wait: go on in the next one.
        if (++mDescriptorPool == mDescriptors.size()) CB_TRY(AddDescriptorPool());
    }
}

void VulkanContext::Recorder::Dispatch(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers,
                                       const void* push, uint32_t pushBytes, uint32_t invocations) {
    DispatchGroups(pipeline, buffers, push, pushBytes, (invocations + 63) / 64, 1, 1);
}

void VulkanContext::Recorder::DispatchRange(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers,
                                            const void* push, uint32_t pushBytes, uint32_t first, uint32_t end) {
    assert((pipeline.ranged || first < 64) && first < end);
    const uint32_t base = first / 64, groups = (end + 63) / 64 - base;
    if (base == 0) return DispatchGroups(pipeline, buffers, push, pushBytes, groups, 1, 1);
    if (!Bind(pipeline, buffers, push, pushBytes)) return;
    vkCmdDispatchBase(mCmd, base, 0, 0, groups, 1, 1);
    ++mContext.mDispatches;
}

void VulkanContext::Recorder::DispatchGroups(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers,
                                             const void* push, uint32_t pushBytes, uint32_t groupsX, uint32_t groupsY,
                                             uint32_t groupsZ) {
    if (!Bind(pipeline, buffers, push, pushBytes)) return;
    vkCmdDispatch(mCmd, groupsX, groupsY, groupsZ);
    ++mContext.mDispatches;
}

bool VulkanContext::Recorder::Bind(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers, const void* push,
                                   uint32_t pushBytes) {
    auto allocated = mContext.AllocateSet(pipeline.setLayout);
    if (!allocated) {
        // Reported by the segment's end (EndSegment); nothing is bound or dispatched.
        if (!mContext.mRecordError) mContext.mRecordError = allocated.error();
        return false;
    }
    const VkDescriptorSet set = *allocated;
    std::vector<VkDescriptorBufferInfo> infos(buffers.size());
    std::vector<VkWriteDescriptorSet> writes(buffers.size());
    for (size_t n = 0; n < buffers.size(); ++n) {
        infos[n] = {buffers[n]->buffer, 0, VK_WHOLE_SIZE};
        writes[n] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[n].dstSet = set;
        writes[n].dstBinding = uint32_t(n);
        writes[n].descriptorCount = 1;
        writes[n].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[n].pBufferInfo = &infos[n];
    }
    vkUpdateDescriptorSets(mContext.mDevice, uint32_t(writes.size()), writes.data(), 0, nullptr);
    vkCmdBindPipeline(mCmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline);
    vkCmdBindDescriptorSets(mCmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout, 0, 1, &set, 0, nullptr);
    if (pushBytes) vkCmdPushConstants(mCmd, pipeline.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes, push);
    return true;
}

void VulkanContext::Recorder::Barrier() {
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    vkCmdPipelineBarrier(mCmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

void VulkanContext::Recorder::Fill(const DeviceBuffer& buffer, uint32_t value) {
    vkCmdFillBuffer(mCmd, buffer.buffer, 0, VK_WHOLE_SIZE, value);
}

void VulkanContext::Recorder::Copy(const DeviceBuffer& from, VkDeviceSize fromOffset, const DeviceBuffer& to,
                                   VkDeviceSize toOffset, VkDeviceSize bytes) {
    mContext.RecordFullBarrier();  // the copy reads what shaders wrote
    const VkBufferCopy region{fromOffset, toOffset, bytes};
    vkCmdCopyBuffer(mCmd, from.buffer, to.buffer, 1, &region);
}

}  // namespace cb::vk
