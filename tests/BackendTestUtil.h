// Making and checking a backend in a backend-parametrised test.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "registry/Registry.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif

namespace cb::test {

// The backends a backend-parametrised suite runs on: every backend this build
// has. The one list of the tests; a suite names it instead of spelling backends.
inline std::vector<std::string> TestBackends() { return BuiltBackends(); }

// TestBackends() but the CPU, for the suites that test a GPU backend against the CPU's.
inline std::vector<std::string> GpuTestBackends() {
    std::vector<std::string> names = TestBackends();
    std::erase(names, std::string("cpu"));
    return names;
}

// TestBackends(), and gl once more as "gl_rgba8" (the automaton in the
// thesis's RGBA8 layout), for the suites that run the automaton.
inline std::vector<std::string> TestBackendsAndCaLayouts() {
    std::vector<std::string> names = TestBackends();
    if (std::find(names.begin(), names.end(), "gl") != names.end()) names.push_back("gl_rgba8");
    return names;
}

// What a test backend named `name` is made of: the registry's name and the
// options, with the Khronos validation layer on (the tests expect no message).
struct TestBackendSetup {
    std::string backend;
    BackendOptions options;
};
inline TestBackendSetup SetupOf(const std::string& name) {
    TestBackendSetup setup{name, {}};
    setup.options.vkValidation = true;
    if (name == "gl_rgba8") {
        setup.backend = "gl";
        setup.options.glCaLayout = gl::CaLayout::Rgba8;
    }
    return setup;
}

// The backend named `name` (SetupOf); an Error says why it cannot start here (the caller skips).
inline Result<std::unique_ptr<Backend>> MakeTestBackend(const std::string& name) {
    const TestBackendSetup setup = SetupOf(name);
    return CreateBackend(setup.backend, setup.options);
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
