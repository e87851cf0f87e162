// `cloudbench devices`: the backends of this build, the CPU's SIMD targets, the
// Vulkan devices and the OpenGL contexts, as the registry lists them.
#include <algorithm>
#include <cstdio>

#include "harness/platform/Command.h"
#include "registry/Registry.h"

namespace cb {
namespace {

constexpr const char* kHelp = R"(usage: cloudbench devices

Lists the backends of this build, the SIMD targets of the CPU backend's
kernels that --cpu-isa takes (those this CPU runs; auto picks the last), the
Vulkan devices with the index and name that --vk-device takes, and the OpenGL contexts that --gl-context takes, each
tried here: its GL_RENDERER and GL_VERSION, or why it cannot be created. Under
each device and context, its limits that bound a scene (for gl
GL_MAX_TEXTURE_SIZE, GL_MAX_ARRAY_TEXTURE_LAYERS and GL_MAX_VIEWPORT_DIMS, for
vk maxComputeWorkGroupCount[0] and maxStorageBufferRange), with what each
bounds: a scene past one is refused on that backend before any stage runs.
Exits 4 when the Vulkan backend is built but finds no device.
)";

// A device's limits, one a line under it: the API's name, the value and what it bounds.
void PrintLimits(const std::vector<DeviceLimit>& limits) {
    for (const DeviceLimit& limit : limits)
        std::printf("          %s %llu: %s\n", limit.name.c_str(), static_cast<unsigned long long>(limit.value),
                    limit.bounds.c_str());
}

// Returns false when Vulkan is built and has no device.
bool PrintVulkanDevices() {
    auto devices = ListVulkanDevices();
    if (!devices) {
        std::printf("vk: %s\n", devices.error().message.c_str());
        const std::vector<std::string> built = BuiltBackends();
        return std::ranges::find(built, "vk") == built.end();
    }
    std::printf("Vulkan devices (--vk-device INDEX or a part of the name):\n");
    for (const VulkanDeviceInfo& d : *devices) {
        std::printf("  %u  %s: %s, Vulkan %s, driver %s\n", d.index, d.name.c_str(), d.type.c_str(), d.api.c_str(),
                    d.driver.c_str());
        PrintLimits(d.limits);
    }
    return true;
}

void PrintCpuTargets() {
    std::printf("CPU SIMD targets (--cpu-isa NAME):");
    for (cpu::CpuIsa isa : cpu::SupportedCpuIsas()) std::printf(" %s", std::string(cpu::CpuIsaName(isa)).c_str());
    std::printf("\n  auto here: %s\n", cpu::ActiveCpuIsaDescription().c_str());
}

void PrintGLContexts() {
    auto contexts = ListGLContexts();
    if (!contexts) {
        std::printf("gl: %s\n", contexts.error().message.c_str());
        return;
    }
    std::printf("OpenGL contexts (--gl-context NAME):\n");
    for (const GLContextInfo& c : *contexts) {
        const std::string name(gl::ContextKindName(c.kind));
        if (c.available) {
            std::printf("  %-7s %s: OpenGL %s\n", name.c_str(), c.renderer.c_str(), c.version.c_str());
            PrintLimits(c.limits);
        } else
            std::printf("  %-7s unavailable: %s\n", name.c_str(), c.reason.c_str());
    }
}

int Devices(const CommonOptions&) {
    std::printf("backends in this build:");
    for (const std::string& name : BuiltBackends()) std::printf(" %s", name.c_str());
    std::printf("\n");
    PrintCpuTargets();
    const bool vulkanOk = PrintVulkanDevices();
    PrintGLContexts();
    return vulkanOk ? kExitOk : kExitNoBackend;
}

const CommandRegistration kRegistration({
    .name = "devices",
    .summary = "List the backends of this build, the CPU's SIMD targets, the Vulkan devices and the OpenGL contexts",
    .help = kHelp,
    .helpOrder = 3,
    .takesScene = false,
    .run = RunWith(Devices),
});

}  // namespace
}  // namespace cb
