// `cloudbench devices`: the backends of this build and the Vulkan devices.
#include <cstdio>

#include "harness/Command.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/VulkanContext.h"
#endif

namespace cb {
namespace {

constexpr const char* kHelp = R"(usage: cloudbench devices

Lists the backends of this build and the Vulkan devices, with the index and
name that --vk-device takes.
)";

int Devices(const CommonOptions&) {
    std::printf("backends in this build:");
    for (const std::string& name : BuiltBackends()) std::printf(" %s", name.c_str());
    std::printf("\n");
#if CLOUDBENCH_HAVE_VK
    auto devices = vk::ListDevices();
    if (!devices) {
        std::printf("vk: %s\n", devices.error().message.c_str());
        return kExitNoBackend;
    }
    std::printf("Vulkan devices (--vk-device INDEX or a part of the name):\n");
    for (const vk::DeviceInfo& d : *devices)
        std::printf("  %u  %s (%s, Vulkan %u.%u)\n", d.index, d.name.c_str(), d.type.c_str(),
                    VK_API_VERSION_MAJOR(d.apiVersion), VK_API_VERSION_MINOR(d.apiVersion));
#else
    std::printf("vk: not built in this build\n");
#endif
    return kExitOk;
}

const CommandRegistration kRegistration({
    .name = "devices",
    .summary = "List the backends of this build and the Vulkan devices",
    .help = kHelp,
    .helpOrder = 3,
    .takesScene = false,
    .run = Devices,
});

}  // namespace
}  // namespace cb
