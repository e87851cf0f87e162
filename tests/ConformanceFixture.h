// The fixture of the stage-isolated conformance tests (ConformanceTest.cpp:
// the simulation stages; ConformanceRenderTest.cpp: shade, shadow, the splat
// renderer and the whole pipeline): a backend variant and a grid size per test,
// the CPU reference beside it, and the comparisons SPEC's rules need.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>
#include <tuple>

#include "core/math/Random.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/scene/Scene.h"
#include "harness/report/Report.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "registry/Registry.h"
#include "tests/TestUtil.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif

namespace cb::conformance {

struct SizeCase {
    const char* name;
    Extent3 size;
};
inline void PrintTo(const SizeCase& c, std::ostream* os) { *os << c.name; }

// A backend under test: its name and the options it is made with.
struct BackendVariant {
    std::string backend;
    BackendOptions options;
    // The name in test names: the backend, then any non-default automaton layout ("gl_rgba8").
    std::string Label() const {
        if (options.glCaLayout == gl::CaLayout::Packed) return backend;
        return backend + "_" + std::string(gl::CaLayoutName(options.glCaLayout));
    }
};
inline void PrintTo(const BackendVariant& v, std::ostream* os) { *os << v.Label(); }

using Param = std::tuple<BackendVariant, SizeCase>;

class Conformance : public ::testing::TestWithParam<Param> {
  protected:
    void SetUp() override {
        const BackendVariant& variant = std::get<0>(GetParam());
        BackendOptions options = variant.options;
        options.vkValidation = true;  // the tests run with the Khronos layer and expect no message
        mAutomatonOnly = options.glCaLayout != gl::CaLayout::Packed;
        auto backend = CreateBackend(variant.backend, options);
        if (!backend) GTEST_SKIP() << "unsupported here: " << backend.error().message;
        mBackend = std::move(*backend);
    }
    void TearDown() override {
#if CLOUDBENCH_HAVE_VK
        if (auto* vk = dynamic_cast<vk::BackendVk*>(mBackend.get())) {
            EXPECT_EQ(vk->ValidationMessages(), 0u);
        }
#endif
    }
    Extent3 Size() const { return std::get<1>(GetParam()).size; }
    // Why the test of `stage` is skipped on this backend; nullopt when it runs.
    // A variant with another automaton layout differs from its backend in the ca stage only.
    std::optional<std::string> SkipReason(Stage stage) const {
        if (!mBackend->Supports(stage))
            return "not implemented yet: " + mBackend->Name() + " has no " + std::string(StageName(stage)) + " stage";
        if (mAutomatonOnly && stage != Stage::Ca)
            return std::string("the RGBA8 automaton layout changes only the ca stage (tested as gl)");
        return std::nullopt;
    }

    // Location of voxel v as "(i, j, k)".
    static std::string Where(const Extent3& e, size_t v) {
        std::ostringstream s;
        s << "(" << v % e.nx << ", " << (v / e.nx) % e.ny << ", " << v / (size_t(e.nx) * e.ny) << ")";
        return s.str();
    }
    // Bit-exact comparison that reports the first differing voxel and how many differ.
    template <typename T>
    void ExpectExact(const std::vector<T>& reference, const std::vector<T>& got, const Extent3& e, const char* what) {
        ASSERT_EQ(reference.size(), got.size());
        size_t first = reference.size(), count = 0;
        for (size_t v = 0; v < reference.size(); ++v)
            if (std::memcmp(&reference[v], &got[v], sizeof(T)) != 0) {
                if (first == reference.size()) first = v;
                ++count;
            }
        EXPECT_EQ(count, 0u) << what << ": " << count << " of " << reference.size() << " differ; first at "
                             << Where(e, first) << ": cpu " << +reference[first] << ", " << mBackend->Name() << " "
                             << +got[first];
    }

    // Runs density with `params` on the CPU and on this backend from the same q and cld
    // (null: no automaton, the cover counts columns with D > 0) and expects D, tiles, bands
    // and the cover equal, bit for bit (SPEC 5). Returns the CPU's bands.
    std::vector<uint8_t> ExpectDensityMatches(const DensityParams& params, const Extent3& e,
                                              const std::vector<float>& q, const std::vector<uint8_t>* cld) {
        const Extent3 columns{e.nx, e.ny, 1}, tiles{CeilDiv(e.nx, params.tile), CeilDiv(e.ny, params.tile), 1},
            bands{tiles.nx, tiles.ny, CeilDiv(e.nz, params.band)};
        Backend* backends[2] = {&mCpu, mBackend.get()};
        std::unique_ptr<Buffer> in[2][2], out[2][3];
        DensityOutputs results[2];
        for (int n = 0; n < 2; ++n) {
            in[n][0] = test::MakeFilled(*backends[n], BufferFormat::F32, e, q);
            if (cld) in[n][1] = test::MakeFilled(*backends[n], BufferFormat::Bits, e, *cld);
            out[n][0] = test::MakeBuffer(*backends[n], BufferFormat::F32, columns);
            out[n][1] = test::MakeBuffer(*backends[n], BufferFormat::U8, tiles);
            out[n][2] = test::MakeBuffer(*backends[n], BufferFormat::U8, bands);
            results[n] = {out[n][0].get(), out[n][1].get(), out[n][2].get(), 0};
            Status s = backends[n]->Density(params, *in[n][0], in[n][1].get(), results[n]);
            EXPECT_TRUE(s.has_value()) << backends[n]->Name() << ": " << s.error().message;
            if (!s) return {};
        }
        const std::string how = cld ? "" : " without cld";
        ExpectExact(test::Read<float>(mCpu, *out[0][0]), test::Read<float>(*mBackend, *out[1][0]), columns,
                    ("D" + how).c_str());
        ExpectExact(test::Read<uint8_t>(mCpu, *out[0][1]), test::Read<uint8_t>(*mBackend, *out[1][1]), tiles,
                    ("tiles" + how).c_str());
        std::vector<uint8_t> refBands = test::Read<uint8_t>(mCpu, *out[0][2]);
        ExpectExact(refBands, test::Read<uint8_t>(*mBackend, *out[1][2]), bands, ("bands" + how).c_str());
        EXPECT_EQ(results[0].coveredColumns, results[1].coveredColumns) << "cover" << how;
        return refBands;
    }

    cpu::BackendCpu mCpu;
    std::unique_ptr<Backend> mBackend;
    bool mAutomatonOnly = false;
};

// Largest |a - b| and where it is.
template <typename T>
std::pair<double, size_t> WorstDifference(const std::vector<T>& a, const std::vector<T>& b) {
    double worst = 0;
    size_t at = 0;
    for (size_t v = 0; v < a.size(); ++v) {
        const double d = std::fabs(double(a[v]) - double(b[v]));
        if (!(d <= worst)) worst = d, at = v;  // NaN counts as worst
    }
    return {worst, at};
}

}  // namespace cb::conformance
