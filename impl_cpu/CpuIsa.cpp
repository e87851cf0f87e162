#include "impl_cpu/CpuIsa.h"

#include <hwy/highway.h>
#include <hwy/targets.h>

#include <bit>
#include <cstdint>

namespace cb::cpu {
namespace {

// The Highway targets of one CpuIsa, among those compiled (HWY_TARGETS, the
// same in every file of this library: impl_cpu/CMakeLists.txt).
int64_t HighwayTargets(CpuIsa isa) {
    switch (isa) {
        case CpuIsa::Auto:
            return 0;
        case CpuIsa::Scalar:
            return (HWY_SCALAR | HWY_EMU128) & HWY_TARGETS;
        case CpuIsa::Sse4:
            return HWY_SSE4 & HWY_TARGETS;
        case CpuIsa::Avx2:
            return HWY_AVX2 & HWY_TARGETS;
        case CpuIsa::Avx512:
            return (HWY_AVX3 | HWY_AVX3_DL) & HWY_TARGETS;
    }
    return 0;
}

CpuIsa IsaOfTarget(int64_t target) {
    for (const auto& [name, isa] : kCpuIsaNames)
        if (isa != CpuIsa::Auto && (HighwayTargets(isa) & target) != 0) return isa;
    return CpuIsa::Scalar;
}

// The compiled targets this CPU runs, read once before any is forced.
int64_t NaturalTargets() {
    static const int64_t natural = hwy::SupportedTargets() & HWY_TARGETS;
    return natural;
}

// The target dispatch picks: Highway's best, the lowest bit.
int64_t ChosenTarget() {
    const int64_t targets = hwy::SupportedTargets() & HWY_TARGETS;
    return targets & -targets;
}

}  // namespace

std::vector<CpuIsa> SupportedCpuIsas() {
    std::vector<CpuIsa> out;
    for (const auto& [name, isa] : kCpuIsaNames)
        if (isa != CpuIsa::Auto && (HighwayTargets(isa) & NaturalTargets()) != 0) out.push_back(isa);
    return out;
}

Status SelectCpuIsa(CpuIsa isa) {
    const int64_t natural = NaturalTargets();
    if (isa == CpuIsa::Auto) {
        hwy::SetSupportedTargetsForTest(0);
        return {};
    }
    // The target's lowest bit only: "avx512" is AVX3 even where AVX3_DL is compiled too.
    const int64_t wanted = HighwayTargets(isa) & natural;
    if (wanted == 0) {
        std::string have;
        for (CpuIsa s : SupportedCpuIsas()) have += (have.empty() ? "" : ", ") + std::string(CpuIsaName(s));
        return MakeError("--cpu-isa: this CPU cannot run " + std::string(CpuIsaName(isa)) + " (it runs " + have + ")");
    }
    hwy::SetSupportedTargetsForTest(int64_t(std::bit_floor(uint64_t(wanted))) | HighwayTargets(CpuIsa::Scalar));
    return {};
}

CpuIsa ActiveCpuIsa() { return IsaOfTarget(ChosenTarget()); }

std::string ActiveCpuIsaDescription() {
    const int64_t target = ChosenTarget();
    return std::string(CpuIsaName(IsaOfTarget(target))) + " (Highway " + hwy::TargetName(target) + ")";
}

}  // namespace cb::cpu
