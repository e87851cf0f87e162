// Making and checking a backend in a backend-parametrised test.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "registry/Registry.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif

namespace cb::test {

// The backend named `name` with the Khronos validation layer on ("gl_rgba8":
// gl with the automaton in the thesis's RGBA8 layout); an Error says why it
// cannot start here (the caller skips).
inline Result<std::unique_ptr<Backend>> MakeTestBackend(const std::string& name) {
    BackendOptions options;
    options.vkValidation = true;  // the tests expect no message
    const bool rgba8 = name == "gl_rgba8";
    if (rgba8) options.glCaLayout = gl::CaLayout::Rgba8;
    return CreateBackend(rgba8 ? "gl" : name, options);
}

// Expects that a Vulkan backend's validation layer reported nothing; any other backend passes.
inline void ExpectNoValidationMessages([[maybe_unused]] const Backend* backend) {
#if CLOUDBENCH_HAVE_VK
    if (auto* vk = dynamic_cast<const vk::BackendVk*>(backend)) {
        EXPECT_EQ(vk->ValidationMessages(), 0u);
    }
#endif
}

// A test parametrised by a backend's name (MakeTestBackend): SetUp makes it,
// or skips with the reason; TearDown expects no validation message.
class BackendTest : public ::testing::TestWithParam<std::string> {
  protected:
    void SetUp() override {
        auto backend = MakeTestBackend(GetParam());
        if (!backend) GTEST_SKIP() << "unsupported here: " << backend.error().message;
        mBackend = std::move(*backend);
    }
    void TearDown() override { ExpectNoValidationMessages(mBackend.get()); }

    std::unique_ptr<Backend> mBackend;
};

}  // namespace cb::test
