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
    ctx->mCpuDevice = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
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
        q.queryCount = 2 * kBatchStampPairs;
        CB_TRY(CheckVk(vkCreateQueryPool(ctx->mDevice, &q, nullptr, &ctx->mQueries), "creating the timestamp queries"));
    }
    CB_TRY(ctx->AddDescriptorPool());
    return ctx;
}

VulkanContext::~VulkanContext() {
    if (mDevice) {
        vkDeviceWaitIdle(mDevice);
        ++mHostWaits;
        for (auto& [name, p] : mPipelines) {
            vkDestroyPipeline(mDevice, p.pipeline, nullptr);
            vkDestroyPipelineLayout(mDevice, p.layout, nullptr);
            vkDestroyDescriptorSetLayout(mDevice, p.setLayout, nullptr);
        }
        mRecording = false;  // DestroyBuffer destroys at once from here on
        for (DeviceBuffer& b : mRetired) DestroyBuffer(b);
        if (mStagingMap) vkUnmapMemory(mDevice, mStaging.memory);
        DestroyBuffer(mStaging);
        for (ArenaChunk& chunk : mArena) {
            vkUnmapMemory(mDevice, chunk.buffer.memory);
            DestroyBuffer(chunk.buffer);
        }
        for (VkDescriptorPool pool : mDescriptors) vkDestroyDescriptorPool(mDevice, pool, nullptr);
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

}  // namespace cb::vk
