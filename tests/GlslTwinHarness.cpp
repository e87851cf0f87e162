// The harness of the GLSL twin tests: the comparison of outputs and the run of twin.comp.
#include "GlslTwinHarness.h"

#include <cstdlib>
#include <span>
#if CLOUDBENCH_HAVE_VK
#include "twin.spv.h"
#endif

namespace cb::test {
namespace {

// |a - b| in ulps (floats), or as integers.
uint64_t Distance(Kind kind, uint32_t a, uint32_t b) {
    if (kind == Kind::F) {
        if (std::isnan(Float(a)) && std::isnan(Float(b))) return 0;
        auto ordered = [](uint32_t u) { return (u >> 31) ? -int64_t(u & 0x7fffffffu) : int64_t(u); };
        return uint64_t(std::llabs(ordered(a) - ordered(b)));
    }
    if (kind == Kind::I) return uint64_t(std::llabs(int64_t(Int(a)) - int64_t(Int(b))));
    return a == b ? 0 : UINT64_MAX;
}

}  // namespace

// Compares the GLSL's outputs with the C++ twin's, element by element; the
// failure message shows the first few mismatches with their inputs.
void Compare(const char* name, const std::vector<Kind>& kinds, uint32_t ulps, const std::vector<Words>& inputs,
             const std::vector<Words>& glsl, const std::function<void(const Words&, Words&)>& cpp) {
    int reported = 0;
    size_t failures = 0;
    for (size_t n = 0; n < inputs.size(); ++n) {
        Words expected{};
        cpp(inputs[n], expected);
        for (size_t k = 0; k < kinds.size(); ++k) {
            const uint64_t allowed = kinds[k] == Kind::F ? ulps : std::min<uint32_t>(ulps, 1);
            if (Distance(kinds[k], glsl[n][k], expected[k]) <= allowed) continue;
            ++failures;
            if (reported++ < 5) {
                std::string in;
                for (int w = 0; w < 11; ++w) in += std::to_string(inputs[n][w]) + (w < 10 ? "," : "");
                ADD_FAILURE() << name << " input #" << n << " {" << in << "} output " << k << ": glsl 0x" << std::hex
                              << glsl[n][k] << " (" << Float(glsl[n][k]) << "), c++ 0x" << expected[k] << " ("
                              << Float(expected[k]) << ")" << std::dec;
            }
        }
    }
    EXPECT_EQ(failures, 0u) << name << ": " << failures << " mismatches in " << inputs.size() << " inputs";
}

#if CLOUDBENCH_HAVE_VK

std::vector<Words> GlslTwin::Run(TwinFn fn, const std::vector<Words>& inputs, const SplatFrame& frame,
                                 const MarchGpu& march, const LayersGpu& layers,
                                 std::span<const LayersBillboard> billboards) {
    vk::VulkanContext& ctx = *sContext;
    const VkDeviceSize bytes = inputs.size() * sizeof(Words);
    auto pipeline = ctx.GetPipeline("twin", 7, kSpirv_twin);
    auto in = ctx.CreateBuffer(bytes);
    auto out = ctx.CreateBuffer(bytes);
    auto frameBuffer = ctx.CreateBuffer(sizeof frame);
    auto marchBuffer = ctx.CreateBuffer(sizeof march);
    auto table = ctx.CreateBuffer(kMieCloudTable.count * 4);
    auto layersBuffer = ctx.CreateBuffer(sizeof layers);
    auto billboardBuffer = ctx.CreateBuffer(std::max<size_t>(billboards.size(), 1) * sizeof(LayersBillboard));
    std::vector<Words> result(inputs.size());
    if (!pipeline || !in || !out || !frameBuffer || !marchBuffer || !table || !layersBuffer || !billboardBuffer) {
        ADD_FAILURE() << "could not set up the twin pipeline";
        return result;
    }
    EXPECT_TRUE(ctx.Upload(*in, std::as_bytes(std::span(inputs))));
    EXPECT_TRUE(ctx.Upload(*frameBuffer, std::as_bytes(std::span(&frame, 1))));
    EXPECT_TRUE(ctx.Upload(*marchBuffer, std::as_bytes(std::span(&march, 1))));
    EXPECT_TRUE(ctx.Upload(*layersBuffer, std::as_bytes(std::span(&layers, 1))));
    if (!billboards.empty()) {
        EXPECT_TRUE(ctx.Upload(*billboardBuffer, std::as_bytes(billboards)));
    }
    EXPECT_TRUE(ctx.Upload(*table, std::as_bytes(std::span(kMieCloudTable.values, kMieCloudTable.count))));
    const struct { uint32_t fn, count; } push{uint32_t(fn), uint32_t(inputs.size())};
    const vk::DeviceBuffer* buffers[] = {&*in,    &*out,          &*frameBuffer,    &*marchBuffer,
                                         &*table, &*layersBuffer, &*billboardBuffer};
    auto ran = ctx.Run("twin", [&](vk::VulkanContext::Recorder& r) {
        r.Dispatch(**pipeline, buffers, &push, sizeof push, push.count);
    });
    EXPECT_TRUE(ran) << (ran ? "" : ran.error().message);
    EXPECT_TRUE(ctx.Download(*out, std::as_writable_bytes(std::span(result))));
    ctx.DestroyBuffer(*in);
    ctx.DestroyBuffer(*out);
    ctx.DestroyBuffer(*frameBuffer);
    ctx.DestroyBuffer(*marchBuffer);
    ctx.DestroyBuffer(*table);
    ctx.DestroyBuffer(*layersBuffer);
    ctx.DestroyBuffer(*billboardBuffer);
    return result;
}

#endif  // CLOUDBENCH_HAVE_VK

}  // namespace cb::test
