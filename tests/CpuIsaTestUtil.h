// Tests that run once per SIMD target of the CPU kernels (impl_cpu/CpuIsa.h):
// derive from OnEveryCpuIsa and instantiate with EveryCpuIsa(); a target this
// CPU lacks is skipped, and every test ends on the automatic choice again.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <ostream>
#include <string>

#include "impl_cpu/CpuIsa.h"

namespace cb::cpu {
// gtest's name for a target in messages ("avx2", not the enum's bytes).
inline void PrintTo(CpuIsa isa, std::ostream* os) { *os << CpuIsaName(isa); }
}  // namespace cb::cpu

namespace cb::test {

class OnEveryCpuIsa : public ::testing::TestWithParam<cpu::CpuIsa> {
  protected:
    void SetUp() override {
        const std::vector<cpu::CpuIsa> here = cpu::SupportedCpuIsas();
        if (std::ranges::find(here, GetParam()) == here.end())
            GTEST_SKIP() << "unsupported here: this CPU cannot run " << cpu::CpuIsaName(GetParam());
        const Status selected = cpu::SelectCpuIsa(GetParam());
        ASSERT_TRUE(selected.has_value()) << selected.error().message;
    }
    void TearDown() override { EXPECT_TRUE(cpu::SelectCpuIsa(cpu::CpuIsa::Auto).has_value()); }
};

inline auto EveryCpuIsa() {
    return ::testing::Values(cpu::CpuIsa::Scalar, cpu::CpuIsa::Sse4, cpu::CpuIsa::Avx2, cpu::CpuIsa::Avx512);
}

inline std::string CpuIsaTestName(const ::testing::TestParamInfo<cpu::CpuIsa>& info) {
    return std::string(cpu::CpuIsaName(info.param));
}

}  // namespace cb::test
