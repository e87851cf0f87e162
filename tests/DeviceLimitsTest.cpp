// Device limits (Backend::Limits, Backend::ExceededLimit): each GPU backend
// reports its device's own values, and a scene one past a limit is refused
// with the scene's file, the field, the backend and the limit named, while
// the same scene at the limit is not.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "core/plan/MemoryPlan.h"
#include "registry/Registry.h"
#include "core/scene/Scene.h"
#include "tests/SceneTestUtil.h"

#if CLOUDBENCH_HAVE_GL
#include "impl_gl/BackendGL.h"
#endif
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif

namespace cb {
namespace {

std::map<std::string, uint64_t> ByName(const std::vector<DeviceLimit>& limits) {
    std::map<std::string, uint64_t> out;
    for (const DeviceLimit& limit : limits) {
        EXPECT_FALSE(limit.bounds.empty()) << limit.name << " says nothing of what it bounds";
        out[limit.name] = limit.value;
    }
    return out;
}

// A scene of `stages` over `grid`, read from "limits.json", with the sun along +x (shade's principal axis x).
Scene LimitScene(Extent3 grid, std::initializer_list<Stage> stages) {
    Scene scene;
    scene.path = "limits.json";
    scene.grid.size = grid;
    scene.stages = test::Stages(stages);
    scene.sun.elevationDeg = 10;
    scene.sun.azimuthDeg = 0;
    scene.steps = 1;
    return scene;
}

// A backend whose only limit is nx <= 8, for CheckDeviceLimits.
class NarrowBackend final : public Backend {
  public:
    std::string Name() const override { return "narrow"; }
    std::string Device() const override { return "a test device"; }
    bool Supports(Stage) const override { return true; }
    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat, Extent3) override { return MakeError("unused"); }
    Status Upload(Buffer&, std::span<const std::byte>) override { return MakeError("unused"); }
    Status Download(const Buffer&, std::span<std::byte>) override { return MakeError("unused"); }
    std::vector<DeviceLimit> Limits() const override { return {{"MAX_NX", 8, "grid nx"}}; }
    std::optional<LimitExceeded> ExceededLimit(const Scene& scene) const override {
        if (scene.grid.size.nx <= 8) return std::nullopt;
        return LimitExceeded{"grid.size", "narrow: nx is more than MAX_NX 8"};
    }
};

// Test that CheckDeviceLimits refuses with `file: field: reason` and passes a scene within the limits, and a
// backend without device limits (the CPU).
TEST(DeviceLimits, CheckNamesTheFileTheFieldAndTheReason) {
    const NarrowBackend narrow;
    EXPECT_TRUE(CheckDeviceLimits(LimitScene({8, 2, 2}, {Stage::Noise}), narrow).has_value());
    const Status past = CheckDeviceLimits(LimitScene({9, 2, 2}, {Stage::Noise}), narrow);
    ASSERT_FALSE(past.has_value());
    EXPECT_EQ(past.error().message, "limits.json: grid.size: narrow: nx is more than MAX_NX 8");
    auto cpu = CreateBackend("cpu");
    ASSERT_TRUE(cpu.has_value()) << cpu.error().message;
    EXPECT_TRUE((*cpu)->Limits().empty());
    EXPECT_TRUE(CheckDeviceLimits(LimitScene({1u << 20, 2, 2}, {Stage::Noise, Stage::Shade}), **cpu).has_value());
}

#if CLOUDBENCH_HAVE_GL
// Test that gl's limits, as the backend and `cloudbench devices` (the registry) report them, are what
// glGetIntegerv gives on a context of the same kind.
TEST(DeviceLimits, GLReportsTheContextsQueries) {
    auto contexts = ListGLContexts();
    if (!contexts) GTEST_SKIP() << "unsupported here: " << contexts.error().message;
    size_t tried = 0;
    for (const GLContextInfo& info : *contexts) {
        if (!info.available) continue;
        SCOPED_TRACE(std::string(gl::ContextKindName(info.kind)));
        auto context = gl::GLContext::Create(info.kind);
        ASSERT_TRUE(context.has_value()) << context.error().message;
        GLint viewport[2] = {0, 0};
        (*context)->F().GetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport);
        const std::map<std::string, uint64_t> queried = {
            {"GL_MAX_TEXTURE_SIZE", uint64_t((*context)->Integer(GL_MAX_TEXTURE_SIZE))},
            {"GL_MAX_ARRAY_TEXTURE_LAYERS", uint64_t((*context)->Integer(GL_MAX_ARRAY_TEXTURE_LAYERS))},
            {"GL_MAX_VIEWPORT_DIMS[0]", uint64_t(viewport[0])},
            {"GL_MAX_VIEWPORT_DIMS[1]", uint64_t(viewport[1])},
        };
        for (const auto& [name, value] : queried) EXPECT_GT(value, 0u) << name;
        BackendOptions options;
        options.glContext = info.kind;
        auto backend = CreateBackend("gl", options);
        ASSERT_TRUE(backend.has_value()) << backend.error().message;
        EXPECT_EQ(ByName((*backend)->Limits()), queried);
        EXPECT_EQ(ByName(info.limits), queried);
        ++tried;
    }
    if (tried == 0) GTEST_SKIP() << "no OpenGL context here";
}

// Test that gl refuses a grid one cell longer along the sun's principal axis than the array layers shade's volume
// may have (the one past its slice count), naming the file, the field, the backend and the limit, and takes it at
// the limit; resolution 2 halves the slices.
TEST(DeviceLimits, GLRefusesShadeSlicesPastTheArrayLayers) {
    const gl::GLLimits limits{.textureSize = 4096, .arrayLayers = 64, .viewportWidth = 4096, .viewportHeight = 4096};
    EXPECT_FALSE(gl::FindExceededGLLimit(limits, LimitScene({64, 2, 2}, {Stage::Noise, Stage::Shade})));
    Scene past = LimitScene({65, 2, 2}, {Stage::Noise, Stage::Shade});
    auto exceeded = gl::FindExceededGLLimit(limits, past);
    ASSERT_TRUE(exceeded);
    EXPECT_EQ(exceeded->field, "grid.size");
    EXPECT_TRUE(exceeded->reason.starts_with("gl: nx 65 is more than this device's GL_MAX_ARRAY_TEXTURE_LAYERS 64 ("))
        << exceeded->reason;
    EXPECT_NE(exceeded->reason.find("principal axis, x here"), std::string::npos) << exceeded->reason;
    // Without shade the long x axis is a texture's width, well within the limits.
    EXPECT_FALSE(gl::FindExceededGLLimit(limits, LimitScene({65, 2, 2}, {Stage::Noise})));
    past.shade.resolution = 2;
    EXPECT_FALSE(gl::FindExceededGLLimit(limits, past));
    // The sun along y: the slices are along y, x is free.
    past.shade.resolution = 1;
    past.sun.azimuthDeg = 90;
    EXPECT_FALSE(gl::FindExceededGLLimit(limits, past));
}

// Test that gl bounds an image's width by the texture size and the viewport (render_splat's reaching 130 pixels
// past each side) and its height by the array layers.
TEST(DeviceLimits, GLRefusesImagesPastTheTextureAndViewport) {
    const gl::GLLimits limits{.textureSize = 1024, .arrayLayers = 64, .viewportWidth = 1024, .viewportHeight = 1024};
    Scene scene = LimitScene({8, 8, 8}, {Stage::Noise, Stage::RenderMarch});
    scene.render.width = 1024, scene.render.height = 64;
    EXPECT_FALSE(gl::FindExceededGLLimit(limits, scene));
    scene.render.height = 65;
    auto tall = gl::FindExceededGLLimit(limits, scene);
    ASSERT_TRUE(tall);
    EXPECT_EQ(tall->field, "render.height");
    EXPECT_TRUE(tall->reason.starts_with("gl: height 65 is more than this device's GL_MAX_ARRAY_TEXTURE_LAYERS 64"))
        << tall->reason;
    scene.render.height = 64;
    scene.stages = test::Stages({Stage::Noise, Stage::Density, Stage::Shade, Stage::RenderSplat});
    auto wide = gl::FindExceededGLLimit(limits, scene);
    ASSERT_TRUE(wide);
    EXPECT_EQ(wide->field, "render.width");
    EXPECT_TRUE(wide->reason.starts_with("gl: width + 260 1284 is more than this device's GL_MAX_VIEWPORT_DIMS[0] 1024"))
        << wide->reason;
    scene.render.width = 1024 - 260;
    EXPECT_FALSE(gl::FindExceededGLLimit(limits, scene));
}
#endif

#if CLOUDBENCH_HAVE_VK
// Test that vk's limits, as the backend and `cloudbench devices` report them, are the first device's
// VkPhysicalDeviceLimits, read here through a context of its own.
TEST(DeviceLimits, VkReportsTheDevicesProperties) {
    auto context = vk::VulkanContext::Create("", false);
    if (!context) GTEST_SKIP() << "unsupported here: " << context.error().message;
    auto backend = CreateBackend("vk");
    ASSERT_TRUE(backend.has_value()) << backend.error().message;
    auto devices = ListVulkanDevices();
    ASSERT_TRUE(devices.has_value()) << devices.error().message;
    const VkPhysicalDeviceLimits& limits = (*context)->DeviceLimits();
    const std::map<std::string, uint64_t> queried = {
        {"maxComputeWorkGroupCount[0]", limits.maxComputeWorkGroupCount[0]},
        {"maxStorageBufferRange", limits.maxStorageBufferRange},
    };
    EXPECT_EQ(ByName((*backend)->Limits()), queried);
    EXPECT_EQ(ByName(devices->front().limits), queried);
}

// Test that vk refuses a grid one voxel past 64 invocations per workgroup times maxComputeWorkGroupCount[0], and
// an image past maxStorageBufferRange, each naming the file, the field, the backend and the limit.
TEST(DeviceLimits, VkRefusesDispatchesAndBuffersPastTheLimits) {
    VkPhysicalDeviceLimits limits{};
    limits.maxComputeWorkGroupCount[0] = 16;
    limits.maxStorageBufferRange = 1 << 20;
    EXPECT_FALSE(vk::FindExceededVkLimit(limits, LimitScene({16, 8, 8}, {Stage::Noise, Stage::Shade})));
    auto groups = vk::FindExceededVkLimit(limits, LimitScene({1025, 1, 1}, {Stage::Noise, Stage::Shade}));
    ASSERT_TRUE(groups);
    EXPECT_EQ(groups->field, "grid.size");
    EXPECT_TRUE(groups->reason.starts_with("vk: nx * ny * nz 1025 needs 17 workgroups, more than this device's "
                                           "maxComputeWorkGroupCount[0] 16"))
        << groups->reason;
    Scene image = LimitScene({8, 8, 8}, {Stage::Noise, Stage::RenderMarch});
    image.render.width = 1024, image.render.height = 85;  // 12 * 1024 * 85 = 1044480 bytes, within 1 MiB
    EXPECT_FALSE(vk::FindExceededVkLimit(limits, image));
    image.render.height = 86;
    auto big = vk::FindExceededVkLimit(limits, image);
    ASSERT_TRUE(big);
    EXPECT_EQ(big->field, "render.width");
    EXPECT_NE(big->reason.find("more than this device's maxStorageBufferRange 1048576"), std::string::npos)
        << big->reason;
}
#endif

}  // namespace
}  // namespace cb
