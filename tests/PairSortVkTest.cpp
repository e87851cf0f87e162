// The device-wide scan and stable pair sort of impl_vk/PairSortVk.h (scan.comp,
// radix_sort.comp), against std::exclusive_scan and std::stable_sort: lengths
// around the 256-entry block, one and several digits, keys with many ties
// (where a sort that is not stable shows), the block widened past 256 (the
// path for more than 16.7 M pairs), and the plan's limits. render_splat sorts
// its (screen tile, splat) pairs so; the conformance tests see only the image.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <span>
#include <vector>

#include "core/math/Random.h"

#if CLOUDBENCH_HAVE_VK
#include "impl_vk/PairSortVk.h"

namespace cb::vk {
namespace {

class PairSortVk : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        auto context = VulkanContext::Create("", true);
        if (!context) {
            sSkipReason = "no Vulkan device: " + context.error().message;
            return;
        }
        sContext = std::move(*context);
    }
    static void TearDownTestSuite() { sContext.reset(); }
    void SetUp() override {
        if (!sContext) GTEST_SKIP() << sSkipReason;
    }
    void TearDown() override {
        if (sContext) {
            EXPECT_EQ(sContext->ValidationMessages(), 0u);
        }
    }

    // A device buffer holding `words` (at least 16 bytes), freed with the test's buffers.
    DeviceBuffer Buffer(const std::vector<uint32_t>& words) {
        auto b = sContext->CreateBuffer(std::max<VkDeviceSize>(16, words.size() * 4));
        EXPECT_TRUE(b.has_value());
        if (!words.empty()) {
            EXPECT_TRUE(sContext->Upload(*b, std::as_bytes(std::span(words))));
        }
        mBuffers.push_back(*b);
        return *b;
    }
    std::vector<uint32_t> Read(const DeviceBuffer& b, size_t n) {
        std::vector<uint32_t> words(n);
        if (n) {
            EXPECT_TRUE(sContext->Download(b, std::as_writable_bytes(std::span(words))));
        }
        return words;
    }
    void TearDownBuffers() {
        for (DeviceBuffer& b : mBuffers) sContext->DestroyBuffer(b);
        mBuffers.clear();
    }
    ~PairSortVk() override {
        if (sContext) TearDownBuffers();
    }
    Pipeline& Pipe(const char* name, uint32_t bindings) {
        auto pipe = sContext->GetPipeline(name, bindings);
        EXPECT_TRUE(pipe.has_value());
        return **pipe;
    }

    // Sorts pairs (keys[i], i) on the device with `plan`; expects std::stable_sort's order.
    void ExpectStableSort(const std::vector<uint32_t>& keys, const PairSortPlan& plan) {
        const uint32_t n = uint32_t(keys.size());
        std::vector<uint32_t> values(n);
        std::iota(values.begin(), values.end(), 0u);
        const DeviceBuffer k0 = Buffer(keys), v0 = Buffer(values), k1 = Buffer(std::vector<uint32_t>(n)),
                           v1 = Buffer(std::vector<uint32_t>(n));
        const DeviceBuffer counts = Buffer(std::vector<uint32_t>(plan.CountEntries()));
        const DeviceBuffer offsets = Buffer(std::vector<uint32_t>(plan.CountEntries() + 1));
        const DeviceBuffer sums = Buffer(std::vector<uint32_t>(ScanSumsEntries(plan.CountEntries())));
        const DeviceBuffer* keyBuffers[2] = {&k0, &k1};
        const DeviceBuffer* valueBuffers[2] = {&v0, &v1};
        auto ran = sContext->Run("sorting pairs", [&](VulkanContext::Recorder& r) {
            RecordPairSort(r, Pipe("radix_sort", 5), Pipe("scan", 3), plan, keyBuffers, valueBuffers, counts, offsets,
                           sums);
        });
        ASSERT_TRUE(ran) << ran.error().message;
        std::vector<uint32_t> expected = values;
        std::stable_sort(expected.begin(), expected.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
        const std::vector<uint32_t> sortedValues = Read(*valueBuffers[plan.Sorted()], n);
        const std::vector<uint32_t> sortedKeys = Read(*keyBuffers[plan.Sorted()], n);
        size_t wrong = 0;
        for (uint32_t i = 0; i < n; ++i)
            if (sortedValues[i] != expected[i] || sortedKeys[i] != keys[expected[i]]) ++wrong;
        EXPECT_EQ(wrong, 0u) << n << " pairs, block " << plan.block << ", " << plan.digits << " digits";
    }

    static inline std::unique_ptr<VulkanContext> sContext;
    static inline std::string sSkipReason;
    std::vector<DeviceBuffer> mBuffers;
};

std::vector<uint32_t> RandomKeys(uint32_t n, uint32_t largest, uint64_t seed) {
    Pcg32 rng(seed);
    std::vector<uint32_t> keys(n);
    for (uint32_t& k : keys) k = rng.Below(largest + 1);
    return keys;
}

TEST_F(PairSortVk, ScanEqualsExclusiveScan) {
    // Up to 1172 block sums: the middle pass scans them 256 at a time, in 5 rounds.
    for (uint32_t n : {0u, 1u, 255u, 256u, 257u, 1000u, 65536u, 65537u, 70000u, 300000u}) {
        Pcg32 rng(n + 1);
        std::vector<uint32_t> in(n);
        for (uint32_t& x : in) x = rng.Below(1000);
        const DeviceBuffer input = Buffer(in), output = Buffer(std::vector<uint32_t>(n + 1)),
                           sums = Buffer(std::vector<uint32_t>(ScanSumsEntries(n)));
        auto ran = sContext->Run("scanning", [&](VulkanContext::Recorder& r) {
            RecordScan(r, Pipe("scan", 3), input, output, sums, n);
        });
        ASSERT_TRUE(ran) << ran.error().message;
        std::vector<uint32_t> expected(n + 1, 0);
        std::exclusive_scan(in.begin(), in.end(), expected.begin(), 0u);
        if (n) expected[n] = expected[n - 1] + in[n - 1];
        EXPECT_EQ(Read(output, n + 1), expected) << n << " entries";
        TearDownBuffers();
    }
}

TEST_F(PairSortVk, StableSortByKey) {
    // (pairs, largest key): one digit, two, three (render_splat's 4K has 129 600 tiles), and
    // few distinct keys, so that most pairs tie; lengths around the 256-pair block.
    const std::pair<uint32_t, uint32_t> cases[] = {{0, 100},   {1, 100},     {255, 3},     {256, 255},
                                                   {257, 256}, {5000, 12287}, {70000, 7}, {70000, 129599}};
    for (const auto& [n, largest] : cases) {
        ExpectStableSort(RandomKeys(n, largest, n * 31 + largest), PlanPairSort(n, largest));
        TearDownBuffers();
    }
}

TEST_F(PairSortVk, AllKeysZeroNeedNoPass) {
    // One screen tile: no digit, and the pairs stay where they are, in order.
    const PairSortPlan plan = PlanPairSort(300, 0);
    EXPECT_EQ(plan.digits, 0u);
    ExpectStableSort(std::vector<uint32_t>(300, 0), plan);
}

TEST_F(PairSortVk, WiderBlocksSortTheSame) {
    // The plan widens blocks past 256 only beyond 16.7 M pairs; the same code, forced here.
    PairSortPlan plan = PlanPairSort(70000, 4095);
    plan.block = 1000;
    plan.blocks = 70;
    ExpectStableSort(RandomKeys(70000, 4095, 9), plan);
}

TEST(PairSortPlan, BlocksStayWithinTheScan) {
    for (uint32_t pairs : {0u, 1u, 256u, kScanMaxEntries, kScanMaxEntries + 1, 100000000u, 4000000000u}) {
        const PairSortPlan plan = PlanPairSort(pairs, 129599);
        EXPECT_GE(plan.block, kScanBlock);
        EXPECT_GE(uint64_t(plan.block) * plan.blocks, pairs);
        EXPECT_LE(plan.CountEntries(), kScanMaxEntries) << pairs;
        EXPECT_EQ(plan.digits, 3u);
    }
    EXPECT_EQ(PlanPairSort(1000, 255).digits, 1u);
    EXPECT_EQ(PlanPairSort(1000, 256).digits, 2u);
    EXPECT_EQ(PlanPairSort(1000, 65535).digits, 2u);
    EXPECT_EQ(PlanPairSort(1000, 65536).digits, 3u);
}

}  // namespace
}  // namespace cb::vk

#endif  // CLOUDBENCH_HAVE_VK
