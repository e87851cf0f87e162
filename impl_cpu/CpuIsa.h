// The instruction-set target of the CPU backend's SIMD kernels. Every kernel
// in impl_cpu that vectorises is compiled once per target with Google Highway
// (foreach_target.h) and called through HWY_DYNAMIC_DISPATCH, so one binary,
// built for baseline x86-64, runs the best target this CPU has; SelectCpuIsa
// forces one target for every kernel at once (docs/performance.md, "SIMD
// targets"). Every target gives the same bits (tests/CpuIsaTest.cpp).
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/Error.h"
#include "core/base/NamedValues.h"

namespace cb::cpu {

enum class CpuIsa {
    Auto,    // the best target this CPU has
    Scalar,  // Highway's SCALAR (EMU128 on compilers where it works): one lane, plain C++
    Sse4,    // SSE4.2 with CLMUL and AES
    Avx2,    // AVX2, BMI2, F16C and FMA
    Avx512,  // AVX-512 F, VL, DQ and BW
};

inline constexpr std::array<NamedValue<CpuIsa>, 5> kCpuIsaNames{{
    {"auto", CpuIsa::Auto},
    {"scalar", CpuIsa::Scalar},
    {"sse4", CpuIsa::Sse4},
    {"avx2", CpuIsa::Avx2},
    {"avx512", CpuIsa::Avx512},
}};
constexpr std::string_view CpuIsaName(CpuIsa isa) { return NameOf(kCpuIsaNames, isa); }

// The targets this CPU runs, Scalar first, the best last (never Auto).
std::vector<CpuIsa> SupportedCpuIsas();

// Makes every dispatched kernel run `isa` from now on (Auto: the best this
// CPU has), process-wide. An Error naming the targets this CPU has when it
// lacks `isa`. Not to be called while kernels run on other threads.
Status SelectCpuIsa(CpuIsa isa);

// The target the dispatched kernels run now (never Auto).
CpuIsa ActiveCpuIsa();

// "avx2 (Highway AVX2)": the active target as devices and provenance show it.
std::string ActiveCpuIsaDescription();

}  // namespace cb::cpu
