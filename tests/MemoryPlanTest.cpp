// The buffer plan and its pricing: the plan is what the simulation allocates,
// each backend prices a buffer in its own layout, and a backend whose memory
// the plan exceeds is refused before anything is allocated.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "SceneTestUtil.h"
#include "core/plan/MemoryPlan.h"
#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"
#include "impl_cpu/BackendCpu.h"
#include "registry/Registry.h"

namespace cb {
namespace {

using test::Parsed;

// The hand-worked scene: a 100 x 4 x 6 grid, V = 2400 voxels, the default
// stages (region, ca, smooth, density), tile 32 and band 4.
constexpr const char* kSmallScene = R"({"grid": {"size": [100, 4, 6]}})";

// The hand-worked scene with the lighting stages and two 10 x 7 cameras.
constexpr const char* kLitScene = R"({"grid": {"size": [100, 4, 6]},
    "stages": ["region", "ca", "smooth", "density", "shade", "shadow", "render_splat"],
    "render": {"width": 10, "height": 7, "cameras": [{"name": "a", "eye": [0, 0, 0], "target": [1, 0, 0]},
                                                     {"name": "b", "eye": [0, 0, 0], "target": [0, 1, 0]}]}})";

constexpr Extent3 kGrid{100, 4, 6};
constexpr Extent3 kColumns{100, 4, 1};
constexpr Extent3 kTiles{4, 1, 1};  // ceil(100/32) x ceil(4/32)
constexpr Extent3 kBands{4, 1, 2};  // ... x ceil(6/4)
constexpr Extent3 kImage{3, 10, 7};

// Test the plan of the small scene, buffer by buffer: the automaton's fields
// twice (this step's and the next), everything else once.
TEST(MemoryPlan, PlanBuffersOfTheSimulationStages) {
    using enum BufferRole;
    using enum BufferFormat;
    const std::vector<PlannedBuffer> expected = {
        {Resource::Region, Current, 0, U8, kGrid},
        {Resource::Hum, Current, 0, Bits, kGrid},
        {Resource::Hum, Next, 0, Bits, kGrid},
        {Resource::Act, Current, 0, Bits, kGrid},
        {Resource::Act, Next, 0, Bits, kGrid},
        {Resource::Cld, Current, 0, Bits, kGrid},
        {Resource::Cld, Next, 0, Bits, kGrid},
        {Resource::Q, Current, 0, F32, kGrid},
        {Resource::ColumnSum, Current, 0, F32, kColumns},
        {Resource::Tiles, Current, 0, U8, kTiles},
        {Resource::Bands, Current, 0, U8, kBands},
    };
    EXPECT_EQ(PlanBuffers(Parsed(kSmallScene)), expected);
}

// Test that the lighting stages add T, G, an image per camera, and the previous
// step's q and occupancy, which the splat renderer interpolates and skips by.
TEST(MemoryPlan, PlanBuffersOfTheLightingStages) {
    using enum BufferRole;
    using enum BufferFormat;
    const std::vector<PlannedBuffer> expected = {
        {Resource::Region, Current, 0, U8, kGrid},       {Resource::Hum, Current, 0, Bits, kGrid},
        {Resource::Hum, Next, 0, Bits, kGrid},           {Resource::Act, Current, 0, Bits, kGrid},
        {Resource::Act, Next, 0, Bits, kGrid},           {Resource::Cld, Current, 0, Bits, kGrid},
        {Resource::Cld, Next, 0, Bits, kGrid},           {Resource::Q, Current, 0, F32, kGrid},
        {Resource::Q, Previous, 0, F32, kGrid},          {Resource::ColumnSum, Current, 0, F32, kColumns},
        {Resource::Tiles, Current, 0, U8, kTiles},       {Resource::Tiles, Previous, 0, U8, kTiles},
        {Resource::Bands, Current, 0, U8, kBands},       {Resource::Bands, Previous, 0, U8, kBands},
        {Resource::T, Current, 0, F32, kGrid},           {Resource::Shadow, Current, 0, F32, kColumns},
        {Resource::SplatImage, Current, 0, F32, kImage}, {Resource::SplatImage, Current, 1, F32, kImage},
    };
    EXPECT_EQ(PlanBuffers(Parsed(kLitScene)), expected);
}

// Test the loader's estimate against the buffers counted and priced by hand in
// the host layout: bit fields as rows of 64-bit words, U8 with 64 bytes of
// padding, and the staging buffer as large as the largest canonical buffer.
TEST(MemoryPlan, EstimateSceneBytesByHand) {
    const uint64_t bitField = 2 * 4 * 6 * 8;  // ceil(100/64) = 2 words in each of 4 x 6 rows
    const uint64_t region = 2400 + 64, q = 2400 * 4, columnSum = 400 * 4;
    const uint64_t tiles = 4 + 64, bands = 8 + 64;
    const uint64_t staging = q;
    EXPECT_EQ(EstimateSceneBytes(Parsed(kSmallScene)),
              staging + region + 6 * bitField + q + columnSum + tiles + bands);  // 25708

    // Lighting: the previous q, tiles and bands; T; G; two images, the largest canonical buffer still q.
    const uint64_t image = 3 * 10 * 7 * 4;
    EXPECT_EQ(EstimateSceneBytes(Parsed(kLitScene)),
              staging + region + 6 * bitField + 2 * q + columnSum + 2 * tiles + 2 * bands + q + columnSum + 2 * image);

    // Only the region: no automaton, and the staging buffer is the region's own size.
    EXPECT_EQ(EstimateSceneBytes(Parsed(R"({"grid": {"size": [100, 4, 6]}, "stages": ["region"]})")), 2400 + region);

    // The largest valid scene: nx = 1 costs a whole 64-bit word per voxel in every bit field.
    const uint64_t v = 65535ull * 65535ull;
    const uint64_t huge = 4 * v + (v + 64) + 6 * 8 * v + 4 * v + 65535 * 4 + (65535 + 64) + (v + 64);
    Scene largest;  // the defaults, as the loader would read them, which refuses it on most machines
    largest.grid.size = Extent3{1, 65535, 65535};
    largest.stages = test::Stages({Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density});
    largest.density.tile = 1;
    largest.density.band = 1;
    EXPECT_EQ(EstimateSceneBytes(largest), huge);
}

// Test each backend's price of a hand-worked extent: bits of nx = 70 take
// 2 words of 64 bits per row on the CPU, 3 words of 32 bits on Vulkan and OpenGL.
TEST(MemoryPlan, BufferBytesPerBackend) {
    const Extent3 e{70, 3, 2};  // 6 rows, 420 voxels
    cpu::BackendCpu cpu(1);
    EXPECT_EQ(cpu.BufferBytes(BufferFormat::Bits, e), 6u * 2 * 8);
    EXPECT_EQ(cpu.BufferBytes(BufferFormat::U8, e), 420u + 64);
    EXPECT_EQ(cpu.BufferBytes(BufferFormat::F32, e), 420u * 4);
    EXPECT_EQ(HostBufferBytes(BufferFormat::Bits, e), 96u);

    for (const char* name : {"vk", "gl"}) {
        auto backend = CreateBackend(name);
        if (!backend) {
            std::printf("%s unavailable here: %s\n", name, backend.error().message.c_str());
            continue;
        }
        EXPECT_EQ((*backend)->BufferBytes(BufferFormat::Bits, e), 6u * 3 * 4) << name;
        EXPECT_EQ((*backend)->BufferBytes(BufferFormat::U8, e), 420u) << name;
        EXPECT_EQ((*backend)->BufferBytes(BufferFormat::F32, e), 420u * 4) << name;
        // Vulkan pads a storage buffer to whole 32-bit words; OpenGL's R8UI texture is 5 bytes.
        EXPECT_EQ((*backend)->BufferBytes(BufferFormat::U8, {5, 1, 1}), std::string(name) == "vk" ? 8u : 5u) << name;
    }
}

// Test the CPU's scratch by hand: with wind, three bit fields for advection;
// smoothing at radius 1 on 2 threads, two runs of a ring of three byte slices,
// a slice of x sums and two rows (nx + 2 + 8 bytes, nx uints).
TEST(MemoryPlan, CpuScratchBytesByHand) {
    Scene scene = Parsed(kSmallScene);
    cpu::BackendCpu cpu(2);
    const uint64_t slice = 100 * 4;
    const uint64_t smooth = 2 * (slice * (3 + 1) + (100 + 2 + 8) + 4 * 100);
    EXPECT_EQ(cpu.ScratchBytes(scene), smooth);
    scene.ca.windShift.assign(6, SliceShift{1, 0});
    EXPECT_EQ(cpu.ScratchBytes(scene), 3 * (2 * 4 * 6 * 8) + smooth);
    EXPECT_EQ(PlannedBytes(scene, cpu), EstimateSceneBytes(scene) - HostStagingBytes(scene) + cpu.ScratchBytes(scene));
}

// Records every buffer the simulation creates.
class CountingBackend : public cpu::BackendCpu {
  public:
    using cpu::BackendCpu::BackendCpu;
    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override {
        created.push_back({format, extent});
        return cpu::BackendCpu::CreateBuffer(format, extent);
    }
    std::vector<std::pair<BufferFormat, Extent3>> created;
};

// Test that the simulation allocates exactly the planned buffers, in order, for
// the scene the tests run (every stage of the splat pipeline) and for the
// simulation stages alone.
TEST(MemoryPlan, SimulationAllocatesThePlan) {
    for (const char* scene : {kSmallScene, kLitScene}) {
        const Scene parsed = Parsed(scene);
        CountingBackend backend(1);
        auto sim = Simulation::Create(parsed, backend);
        ASSERT_TRUE(sim.has_value()) << sim.error().message;
        std::vector<std::pair<BufferFormat, Extent3>> planned;
        for (const PlannedBuffer& b : PlanBuffers(parsed)) planned.push_back({b.format, b.extent});
        EXPECT_EQ(backend.created, planned);
    }
}

// A CPU backend with a few kilobytes of memory.
class TinyBackend : public cpu::BackendCpu {
  public:
    using cpu::BackendCpu::BackendCpu;
    std::optional<uint64_t> AvailableBytes() const override { return 4096; }
};

// Test that a backend whose memory the plan exceeds is refused before any
// buffer is made, the error naming the backend and the bytes needed and available.
TEST(MemoryPlan, SimulationRefusesWhatDoesNotFit) {
    const Scene scene = Parsed(kSmallScene);
    TinyBackend backend(1);
    auto sim = Simulation::Create(scene, backend);
    ASSERT_FALSE(sim.has_value());
    const std::string needed = std::to_string(PlannedBytes(scene, backend));
    EXPECT_EQ(sim.error().message, "cpu: the scene's buffers need 0.0 GiB (" + needed +
                                       " bytes), more than the 0.0 GiB (4096 bytes) available to it");
}

}  // namespace
}  // namespace cb
