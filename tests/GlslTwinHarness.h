// The harness of the GLSL twin tests (GlslTwinTest.cpp): a case is one
// function of core/math, run by tests/twin/twin.comp on a Vulkan device and
// compared with its C++ twin; the cases are in GlslTwinCases.cpp.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "core/math/Random.h"
#include "core/math/Splat.h"
#include "core/pipeline/LayersGpu.h"
#include "core/pipeline/MarchGpu.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/VulkanContext.h"
#endif

namespace cb::test {

// One element: 16 input words, 16 output words; floats as their bits.
using Words = std::array<uint32_t, 16>;
inline constexpr uint32_t kRandomPerCase = 4096;

inline uint32_t Bits(float f) { return std::bit_cast<uint32_t>(f); }
inline float Float(uint32_t u) { return std::bit_cast<float>(u); }
inline float Uniform(Pcg32& rng, double lo, double hi) { return float(rng.Uniform(lo, hi)); }
inline int32_t Int(uint32_t u) { return int32_t(u); }

enum class Kind : uint8_t { U, I, F };  // how an output word compares

// The functions of twin.comp by name (kTwinLowBias32, ...): the list tests/twin/twin_fns.h, which twin.comp
// reads too for its switch labels.
enum TwinFn : uint32_t {
#define CB_TWIN_FN(name, number) kTwin##name = number,
#include "twin/twin_fns.h"
#undef CB_TWIN_FN
};

struct TwinCase {
    const char* name;
    TwinFn fn;  // the `fn` of twin.comp
    std::vector<Kind> outputs;
    std::function<void(Pcg32&, Words&)> random;
    std::vector<Words> edges;
    std::function<void(const Words&, Words&)> cpp;
    uint32_t otherDeviceUlps = 0;  // see the top of GlslTwinTest.cpp
    uint32_t expUlps = 0;          // on every device, lavapipe too: the case calls exp (GlslTwinTest.cpp)
};

inline Words W(std::initializer_list<uint32_t> words) {
    Words w{};
    std::copy(words.begin(), words.end(), w.begin());
    return w;
}
inline Words WF(std::initializer_list<float> floats) {
    Words w{};
    size_t n = 0;
    for (float f : floats) w[n++] = Bits(f);
    return w;
}

// twin.comp's synthetic padded volume (march.glsl's and layers.glsl's fetches): (q, T) of padded index i from a hash.
inline std::array<float, 2> TwinPaddedQT(uint32_t i) {
    return {float(LowBias32(i) >> 8) * (1.0f / 16777216.0f),
            float(LowBias32(i ^ 0x9E3779B9u) >> 8) * (1.0f / 16777216.0f)};
}

// twin.comp's synthetic T_sky (march.glsl's MarchFetchSkyT): a third hash of the padded index.
inline float TwinPaddedSkyT(uint32_t i) { return float(LowBias32(i ^ 0x2545F491u) >> 8) * (1.0f / 16777216.0f); }

// twin.comp's synthetic modulation map (layers.glsl's LayersMapValue): m of column index i from a hash.
inline float TwinLayersMap(uint32_t i) { return float(LowBias32(i ^ 0x51ED27u) >> 8) * (1.0f / 16777216.0f); }

// Floats next to x: x itself and one ulp either side.
inline std::vector<float> AndNeighbours(float x) {
    return {std::nextafter(x, -INFINITY), x, std::nextafter(x, INFINITY)};
}

// Every function of core/math but MakeSplat, PowderTerm and those that read a MarchGpu block
// (GlslTwinTest.cpp has them), with its random inputs, edges and C++ twin.
std::vector<TwinCase> Cases();
// The march.glsl part of Cases() (GlslTwinMarchCases.cpp).
void AddMarchCases(std::vector<TwinCase>& cases);
// The ground.glsl part of Cases() (GlslTwinMarchCases.cpp).
void AddGroundCases(std::vector<TwinCase>& cases);
// The shafts.glsl part of Cases() (GlslTwinMarchCases.cpp).
void AddShaftsCases(std::vector<TwinCase>& cases);

// Compares the GLSL's outputs with the C++ twin's, element by element; the
// failure message shows the first few mismatches with their inputs.
void Compare(const char* name, const std::vector<Kind>& kinds, uint32_t ulps, const std::vector<Words>& inputs,
             const std::vector<Words>& glsl, const std::function<void(const Words&, Words&)>& cpp);

#if CLOUDBENCH_HAVE_VK

// A Vulkan device for the twin tests (a skip without one), and twin.comp run on it.
class GlslTwin : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        auto context = vk::VulkanContext::Create("", false);
        if (!context) {
            sSkipReason = "no Vulkan device: " + context.error().message;
            return;
        }
        sContext = std::move(*context);
        auto devices = vk::ListDevices();
        if (devices)
            for (const vk::DeviceInfo& d : *devices)
                if (d.name == sContext->DeviceName()) sExact = d.type == "cpu";
    }
    static void TearDownTestSuite() { sContext.reset(); }
    void SetUp() override {
        if (!sContext) GTEST_SKIP() << sSkipReason;
    }

    // Runs twin.comp's function `fn` on `inputs` with `frame`, `march`, kMieCloudTable, `layers` and the
    // billboard list `billboards` bound.
    static std::vector<Words> Run(TwinFn fn, const std::vector<Words>& inputs, const SplatFrame& frame,
                                  const MarchGpu& march = MarchGpu{}, const LayersGpu& layers = LayersGpu{},
                                  std::span<const LayersBillboard> billboards = {});

    static inline std::unique_ptr<vk::VulkanContext> sContext;
    static inline std::string sSkipReason;
    static inline bool sExact = false;  // lavapipe: every case bit-exact
};

#endif  // CLOUDBENCH_HAVE_VK

}  // namespace cb::test
