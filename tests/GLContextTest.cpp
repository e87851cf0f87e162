// The OpenGL context's error reporting: a shader that does not compile or a
// program that does not link comes back as an error naming the pass, with
// the driver's log. Skipped where no OpenGL 4.5 context can be made.
#include <gtest/gtest.h>

#if CLOUDBENCH_HAVE_GL
#include "impl_gl/GLContext.h"
#include "registry/Registry.h"

namespace cb::gl {
namespace {

class GLContextTest : public ::testing::Test {
  protected:
    void SetUp() override {
        auto context = GLContext::Create(ContextKind::OSMesa);
        if (!context) GTEST_SKIP() << "unsupported here: " << context.error().message;
        mContext = std::move(*context);
    }
    std::unique_ptr<GLContext> mContext;
};

TEST_F(GLContextTest, CompileErrorNamesThePassAndCarriesTheLog) {
    const std::string fragment = "#version 450 core\nout vec4 c;\nvoid main() { c = vec4(undeclared_thing); }\n";
    auto program = mContext->LinkProgram("broken_pass", nullptr, fragment);
    ASSERT_FALSE(program.has_value());
    const std::string& message = program.error().message;
    EXPECT_NE(message.find("compiling the broken_pass fragment shader failed"), std::string::npos) << message;
    EXPECT_NE(message.find("undeclared_thing"), std::string::npos) << "the log is missing: " << message;
}

TEST_F(GLContextTest, LinkErrorNamesThePassAndCarriesTheLog) {
    // The fragment shader reads an input no vertex shader writes.
    const std::string fragment = "#version 450 core\nflat in int never_written;\nout vec4 c;\n"
                                 "void main() { c = vec4(float(never_written)); }\n";
    auto program = mContext->LinkProgram("unlinkable_pass", nullptr, fragment);
    ASSERT_FALSE(program.has_value());
    const std::string& message = program.error().message;
    EXPECT_NE(message.find("linking the unlinkable_pass program failed"), std::string::npos) << message;
    EXPECT_NE(message.find("never_written"), std::string::npos) << "the log is missing: " << message;
}

TEST_F(GLContextTest, EveryEmbeddedPassLinks) {
    for (const char* pass : {"smooth_x", "smooth_y", "smooth_z", "density_sum", "density_cover", "occupancy", "shadow", "region", "ca_init", "ca",
                             "advect", "ca_pack_rgba8", "ca_rgba8", "advect_rgba8", "ca_unpack_rgba8", "shade_down",
                             "shade_slice", "shade_up", "splat"}) {
        auto program = mContext->Program(pass);
        EXPECT_TRUE(program.has_value()) << pass << ": " << program.error().message;
    }
    EXPECT_FALSE(mContext->Program("no_such_pass").has_value());
}

// Several gl backends in one process (tests, a library user): each call goes to
// its own context, whichever was made or destroyed last. Before GLContext made
// itself current, a backend used after another one was destroyed ran its calls
// with no context (its limits read 0 x 0, every buffer refused), and one used
// after another was created wrote into that one's objects of the same names.
std::vector<std::byte> GlPattern(size_t count, uint8_t seed) {
    std::vector<std::byte> bytes(count);
    for (size_t n = 0; n < count; ++n) bytes[n] = std::byte(uint8_t(seed + 7 * n));
    return bytes;
}

TEST(GLContextsInOneProcess, EachBackendKeepsItsOwnContext) {
    auto first = CreateBackend("gl");
    if (!first) GTEST_SKIP() << "unsupported here: " << first.error().message;
    const Extent3 extent{5, 4, 3};
    auto firstBuffer = (*first)->CreateBuffer(BufferFormat::U8, extent);
    ASSERT_TRUE(firstBuffer.has_value()) << firstBuffer.error().message;
    const std::vector<std::byte> firstBytes = GlPattern(extent.Count(), 1);
    ASSERT_TRUE((*first)->Upload(**firstBuffer, firstBytes));
    {
        // A second backend, used between the first's calls, then destroyed.
        auto second = CreateBackend("gl");
        ASSERT_TRUE(second.has_value()) << second.error().message;
        auto secondBuffer = (*second)->CreateBuffer(BufferFormat::U8, extent);
        ASSERT_TRUE(secondBuffer.has_value()) << secondBuffer.error().message;
        const std::vector<std::byte> secondBytes = GlPattern(extent.Count(), 100);
        ASSERT_TRUE((*second)->Upload(**secondBuffer, secondBytes));
        std::vector<std::byte> back(extent.Count());
        ASSERT_TRUE((*first)->Download(**firstBuffer, back));
        EXPECT_EQ(back, firstBytes) << "the first backend read the second one's texture";
        ASSERT_TRUE((*second)->Download(**secondBuffer, back));
        EXPECT_EQ(back, secondBytes);
    }
    // The second context is gone: the first must still work, old buffers and new.
    std::vector<std::byte> back(extent.Count());
    ASSERT_TRUE((*first)->Download(**firstBuffer, back));
    EXPECT_EQ(back, firstBytes);
    auto later = (*first)->CreateBuffer(BufferFormat::U8, extent);
    ASSERT_TRUE(later.has_value()) << later.error().message;
    const std::vector<std::byte> laterBytes = GlPattern(extent.Count(), 50);
    ASSERT_TRUE((*first)->Upload(**later, laterBytes));
    ASSERT_TRUE((*first)->Download(**later, back));
    EXPECT_EQ(back, laterBytes);
}

// Test that the texture limits `cloudbench devices` prints for each context (the registry's GLContextInfo, read
// from the context) are the ones gl's buffers meet: a buffer of exactly that many layers (an image's rows) or
// columns is made, one more is refused naming the limit. render.height's documented 16384 is more than llvmpipe's
// 2048 layers (docs/scenes.md).
TEST(GLLimits, DevicesLimitsAreWhatCreateBufferEnforces) {
    auto contexts = ListGLContexts();
    if (!contexts) GTEST_SKIP() << "unsupported here: " << contexts.error().message;
    size_t tried = 0;
    for (const GLContextInfo& info : *contexts) {
        if (!info.available) continue;
        SCOPED_TRACE(std::string(ContextKindName(info.kind)));
        BackendOptions options;
        options.glContext = info.kind;
        auto backend = CreateBackend("gl", options);
        ASSERT_TRUE(backend.has_value()) << backend.error().message;
        const uint32_t layers = uint32_t(info.maxArrayLayers), size = uint32_t(info.maxTextureSize);
        ASSERT_GT(layers, 0u);
        ASSERT_GT(size, 0u);
        EXPECT_TRUE((*backend)->CreateBuffer(BufferFormat::F32, {1, 1, layers}).has_value());
        auto tall = (*backend)->CreateBuffer(BufferFormat::F32, {1, 1, layers + 1});
        ASSERT_FALSE(tall.has_value());
        EXPECT_NE(tall.error().message.find("with " + std::to_string(layers) + " layers"), std::string::npos)
            << tall.error().message;
        EXPECT_TRUE((*backend)->CreateBuffer(BufferFormat::F32, {size, 1, 1}).has_value());
        auto wide = (*backend)->CreateBuffer(BufferFormat::F32, {size + 1, 1, 1});
        ASSERT_FALSE(wide.has_value());
        EXPECT_NE(wide.error().message.find("allows " + std::to_string(size) + " x " + std::to_string(size)),
                  std::string::npos)
            << wide.error().message;
        ++tried;
    }
    if (tried == 0) GTEST_SKIP() << "no OpenGL context here";
}

}  // namespace
}  // namespace cb::gl
#endif
