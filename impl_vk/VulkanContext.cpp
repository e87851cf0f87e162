// VulkanContext (impl_vk/VulkanContext.h): the instance, the device and its
// compute queue, creation and teardown. Buffers and transfers are in
// VulkanMemory.cpp, pipelines and the Recorder in VulkanPipelines.cpp,
// recording, submission and batches in VulkanSubmission.cpp.
#include "impl_vk/VulkanContext.h"

#include <cstring>

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
        out.push_back({n, p.deviceName, DeviceTypeName(p.deviceType), p.apiVersion, driver, p.limits});
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
    ctx->mLimits = props.limits;
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

}  // namespace cb::vk
