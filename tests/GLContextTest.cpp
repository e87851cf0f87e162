// The OpenGL context's error reporting: a shader that does not compile or a
// program that does not link comes back as an error naming the pass, with
// the driver's log. Skipped where no OpenGL 4.5 context can be made.
#include <gtest/gtest.h>

#if CLOUDBENCH_HAVE_GL
#include "impl_gl/GLContext.h"

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

}  // namespace
}  // namespace cb::gl
#endif
