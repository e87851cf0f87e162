#include "impl_vk/VulkanContext.h"

#include <algorithm>
#include <cassert>
#include <cstring>

#include "impl_vk/Shaders.h"

namespace cb::vk {
namespace {

const char* ResultName(VkResult r) {
    switch (r) {
        case VK_SUCCESS:
            return "VK_SUCCESS";
        case VK_NOT_READY:
            return "VK_NOT_READY";
        case VK_TIMEOUT:
            return "VK_TIMEOUT";
        case VK_ERROR_OUT_OF_HOST_MEMORY:
            return "VK_ERROR_OUT_OF_HOST_MEMORY";
        case VK_ERROR_OUT_OF_DEVICE_MEMORY:
            return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
        case VK_ERROR_INITIALIZATION_FAILED:
            return "VK_ERROR_INITIALIZATION_FAILED";
        case VK_ERROR_DEVICE_LOST:
            return "VK_ERROR_DEVICE_LOST";
        case VK_ERROR_LAYER_NOT_PRESENT:
            return "VK_ERROR_LAYER_NOT_PRESENT";
        case VK_ERROR_EXTENSION_NOT_PRESENT:
            return "VK_ERROR_EXTENSION_NOT_PRESENT";
        case VK_ERROR_FEATURE_NOT_PRESENT:
            return "VK_ERROR_FEATURE_NOT_PRESENT";
        case VK_ERROR_INCOMPATIBLE_DRIVER:
            return "VK_ERROR_INCOMPATIBLE_DRIVER";
        case VK_ERROR_OUT_OF_POOL_MEMORY:
            return "VK_ERROR_OUT_OF_POOL_MEMORY";
        default:
            return "VkResult error";
    }
}

const char* DeviceTypeName(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return "cpu";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return "integrated GPU";
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return "discrete GPU";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return "virtual GPU";
        default:
            return "other";
    }
}

Result<VkInstance> MakeInstance(bool validation, bool& debugUtils) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "cloudbench";
    app.apiVersion = VK_API_VERSION_1_2;
    std::vector<const char*> layers, extensions;
    debugUtils = false;
    if (validation) {
        uint32_t count = 0;
        vkEnumerateInstanceLayerProperties(&count, nullptr);
        std::vector<VkLayerProperties> available(count);
        vkEnumerateInstanceLayerProperties(&count, available.data());
        bool found = false;
        for (const VkLayerProperties& l : available)
            found |= std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0;
        if (!found)
            return MakeError("the Khronos validation layer is not installed (Debian package vulkan-validationlayers)");
        layers.push_back("VK_LAYER_KHRONOS_validation");
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        debugUtils = true;
    }
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    info.enabledLayerCount = uint32_t(layers.size());
    info.ppEnabledLayerNames = layers.data();
    info.enabledExtensionCount = uint32_t(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    VkInstance instance = VK_NULL_HANDLE;
    VkResult r = vkCreateInstance(&info, nullptr, &instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
        return MakeError("no Vulkan 1.2 driver found (install mesa-vulkan-drivers for lavapipe)");
    CB_TRY(CheckVk(r, "creating the Vulkan instance"));
    return instance;
}

}  // namespace

Status CheckVk(VkResult result, const char* what) {
    if (result == VK_SUCCESS) return {};
    return MakeError(std::string(what) + ": " + ResultName(result));
}

Result<std::vector<DeviceInfo>> ListDevices() {
    bool debugUtils = false;
    auto instance = MakeInstance(false, debugUtils);
    if (!instance) return std::unexpected(instance.error());
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(*instance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(*instance, &count, devices.data());
    std::vector<DeviceInfo> out;
    for (uint32_t n = 0; n < count; ++n) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[n], &p);
        // The driver properties are core from Vulkan 1.2 only.
        std::string driver = "?";
        if (p.apiVersion >= VK_API_VERSION_1_2) {
            VkPhysicalDeviceDriverProperties driverProperties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
            VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
            properties.pNext = &driverProperties;
            vkGetPhysicalDeviceProperties2(devices[n], &properties);
            driver = driverProperties.driverName;
            if (driverProperties.driverInfo[0] != '\0') driver += std::string(" ") + driverProperties.driverInfo;
        }
        out.push_back({n, p.deviceName, DeviceTypeName(p.deviceType), p.apiVersion, driver});
    }
    vkDestroyInstance(*instance, nullptr);
    if (out.empty()) return MakeError("no Vulkan device found (install mesa-vulkan-drivers for lavapipe)");
    return out;
}

VKAPI_ATTR VkBool32 VKAPI_CALL VulkanContext::OnValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                                  VkDebugUtilsMessageTypeFlagsEXT,
                                                                  const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                                  void* user) {
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        static_cast<VulkanContext*>(user)->mValidationMessages++;
        std::fprintf(stderr, "vk validation: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

Result<std::unique_ptr<VulkanContext>> VulkanContext::Create(const std::string& device, bool validation) {
    std::unique_ptr<VulkanContext> ctx(new VulkanContext());
    bool debugUtils = false;
    auto instance = MakeInstance(validation, debugUtils);
    if (!instance) return std::unexpected(instance.error());
    ctx->mInstance = *instance;
    if (debugUtils) {
        VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
        info.messageSeverity =
            VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        info.pfnUserCallback = &VulkanContext::OnValidationMessage;
        info.pUserData = ctx.get();
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(ctx->mInstance, "vkCreateDebugUtilsMessengerEXT"));
        if (create)
            CB_TRY(
                CheckVk(create(ctx->mInstance, &info, nullptr, &ctx->mMessenger), "creating the validation messenger"));
    }

    uint32_t count = 0;
    vkEnumeratePhysicalDevices(ctx->mInstance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(ctx->mInstance, &count, devices.data());
    if (devices.empty()) return MakeError("no Vulkan device found (install mesa-vulkan-drivers for lavapipe)");
    int chosen = -1;
    for (uint32_t n = 0; n < count && chosen < 0; ++n) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[n], &p);
        if (device.empty() || device == std::to_string(n) ||
            std::string(p.deviceName).find(device) != std::string::npos)
            chosen = int(n);
    }
    if (chosen < 0) return MakeError("no Vulkan device matches '" + device + "' (see cloudbench devices)");
    ctx->mPhysical = devices[size_t(chosen)];
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(ctx->mPhysical, &props);
    ctx->mDeviceName = props.deviceName;
    ctx->mTimestampPeriodNs = props.limits.timestampPeriod;
    if (props.apiVersion < VK_API_VERSION_1_2) return MakeError(ctx->mDeviceName + " supports Vulkan below 1.2");
    vkGetPhysicalDeviceMemoryProperties(ctx->mPhysical, &ctx->mMemory);

    VkPhysicalDeviceVulkan12Features have12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 have{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    have.pNext = &have12;
    vkGetPhysicalDeviceFeatures2(ctx->mPhysical, &have);
    if (!have12.storageBuffer8BitAccess)
        return MakeError(ctx->mDeviceName + " lacks storageBuffer8BitAccess, which the byte volumes need");

    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(ctx->mPhysical, &families, nullptr);
    std::vector<VkQueueFamilyProperties> familyProps(families);
    vkGetPhysicalDeviceQueueFamilyProperties(ctx->mPhysical, &families, familyProps.data());
    bool found = false;
    for (uint32_t f = 0; f < families && !found; ++f) {
        if (familyProps[f].queueFlags & VK_QUEUE_COMPUTE_BIT) {
            ctx->mQueueFamily = f;
            ctx->mTimestamps = familyProps[f].timestampValidBits > 0;
            found = true;
        }
    }
    if (!found) return MakeError(ctx->mDeviceName + " has no compute queue");

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue.queueFamilyIndex = ctx->mQueueFamily;
    queue.queueCount = 1;
    queue.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan12Features want12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    want12.storageBuffer8BitAccess = VK_TRUE;
    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    info.pNext = &want12;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue;
    CB_TRY(CheckVk(vkCreateDevice(ctx->mPhysical, &info, nullptr, &ctx->mDevice), "creating the Vulkan device"));
    vkGetDeviceQueue(ctx->mDevice, ctx->mQueueFamily, 0, &ctx->mQueue);

    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = ctx->mQueueFamily;
    CB_TRY(CheckVk(vkCreateCommandPool(ctx->mDevice, &pool, nullptr, &ctx->mPool), "creating the command pool"));
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = ctx->mPool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    CB_TRY(CheckVk(vkAllocateCommandBuffers(ctx->mDevice, &alloc, &ctx->mCmd), "allocating the command buffer"));
    VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    CB_TRY(CheckVk(vkCreateFence(ctx->mDevice, &fence, nullptr, &ctx->mFence), "creating the fence"));
    if (ctx->mTimestamps) {
        VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        q.queryType = VK_QUERY_TYPE_TIMESTAMP;
        q.queryCount = 2;
        CB_TRY(CheckVk(vkCreateQueryPool(ctx->mDevice, &q, nullptr, &ctx->mQueries), "creating the timestamp queries"));
    }
    // Enough sets for one stage call: shading records one dispatch per slice.
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 32768};
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    dp.maxSets = 8192;
    dp.poolSizeCount = 1;
    dp.pPoolSizes = &size;
    CB_TRY(CheckVk(vkCreateDescriptorPool(ctx->mDevice, &dp, nullptr, &ctx->mDescriptors),
                   "creating the descriptor pool"));
    return ctx;
}

VulkanContext::~VulkanContext() {
    if (mDevice) {
        vkDeviceWaitIdle(mDevice);
        for (auto& [name, p] : mPipelines) {
            vkDestroyPipeline(mDevice, p.pipeline, nullptr);
            vkDestroyPipelineLayout(mDevice, p.layout, nullptr);
            vkDestroyDescriptorSetLayout(mDevice, p.setLayout, nullptr);
        }
        if (mStagingMap) vkUnmapMemory(mDevice, mStaging.memory);
        DestroyBuffer(mStaging);
        if (mDescriptors) vkDestroyDescriptorPool(mDevice, mDescriptors, nullptr);
        if (mQueries) vkDestroyQueryPool(mDevice, mQueries, nullptr);
        if (mFence) vkDestroyFence(mDevice, mFence, nullptr);
        if (mPool) vkDestroyCommandPool(mDevice, mPool, nullptr);
        vkDestroyDevice(mDevice, nullptr);
    }
    if (mMessenger) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(mInstance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(mInstance, mMessenger, nullptr);
    }
    if (mInstance) vkDestroyInstance(mInstance, nullptr);
}

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

Status VulkanContext::CopyBuffer(VkBuffer from, VkBuffer to, VkDeviceSize size, const char* what) {
    CB_TRY(Begin());
    VkBufferCopy region{0, 0, size};
    vkCmdCopyBuffer(mCmd, from, to, 1, &region);
    Recorder none(*this, mCmd);
    auto done = Submit(what, none);
    if (!done) return std::unexpected(done.error());
    return {};
}

Status VulkanContext::Upload(const DeviceBuffer& buffer, std::span<const std::byte> data) {
    if (data.empty()) return {};
    CB_TRY(EnsureStaging(data.size()));
    std::memcpy(mStagingMap, data.data(), data.size());
    return CopyBuffer(mStaging.buffer, buffer.buffer, data.size(), "uploading a buffer");
}

Status VulkanContext::Download(const DeviceBuffer& buffer, std::span<std::byte> data) {
    if (data.empty()) return {};
    CB_TRY(EnsureStaging(data.size()));
    CB_TRY(CopyBuffer(buffer.buffer, mStaging.buffer, data.size(), "downloading a buffer"));
    std::memcpy(data.data(), mStagingMap, data.size());
    return {};
}

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

Status VulkanContext::Begin() {
    CB_TRY(CheckVk(vkResetCommandBuffer(mCmd, 0), "resetting the command buffer"));
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    CB_TRY(CheckVk(vkBeginCommandBuffer(mCmd, &begin), "beginning the command buffer"));
    if (mTimestamps) {
        vkCmdResetQueryPool(mCmd, mQueries, 0, 2);
        vkCmdWriteTimestamp(mCmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, mQueries, 0);
    }
    return {};
}

Result<double> VulkanContext::Submit(const char* what, Recorder& recorder) {
    if (mTimestamps) vkCmdWriteTimestamp(mCmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, mQueries, 1);
    CB_TRY(CheckVk(vkEndCommandBuffer(mCmd), what));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &mCmd;
    CB_TRY(CheckVk(vkResetFences(mDevice, 1, &mFence), what));
    CB_TRY(CheckVk(vkQueueSubmit(mQueue, 1, &submit, mFence), what));
    CB_TRY(CheckVk(vkWaitForFences(mDevice, 1, &mFence, VK_TRUE, UINT64_MAX), what));
    if (!recorder.mSets.empty())
        vkFreeDescriptorSets(mDevice, mDescriptors, uint32_t(recorder.mSets.size()), recorder.mSets.data());
    double ms = 0;
    if (mTimestamps) {
        uint64_t stamps[2] = {};
        CB_TRY(CheckVk(vkGetQueryPoolResults(mDevice, mQueries, 0, 2, sizeof stamps, stamps, sizeof(uint64_t),
                                             VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                       what));
        ms = double(stamps[1] - stamps[0]) * mTimestampPeriodNs * 1e-6;
    }
    return ms;
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
    Bind(pipeline, buffers, push, pushBytes);
    vkCmdDispatchBase(mCmd, base, 0, 0, groups, 1, 1);
}

void VulkanContext::Recorder::DispatchGroups(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers,
                                             const void* push, uint32_t pushBytes, uint32_t groupsX, uint32_t groupsY,
                                             uint32_t groupsZ) {
    Bind(pipeline, buffers, push, pushBytes);
    vkCmdDispatch(mCmd, groupsX, groupsY, groupsZ);
}

void VulkanContext::Recorder::Bind(Pipeline& pipeline, std::span<const DeviceBuffer* const> buffers, const void* push,
                                   uint32_t pushBytes) {
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.descriptorPool = mContext.mDescriptors;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &pipeline.setLayout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    vkAllocateDescriptorSets(mContext.mDevice, &alloc, &set);
    mSets.push_back(set);
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

}  // namespace cb::vk
