// The constants of stage `render_march` on the GPU backends, as one block of
// named members that both std140 (GL uniform block) and std430 (Vulkan storage
// or uniform buffer) lay out the same way. core/math/march.glsl declares the
// twin struct `MarchGpu`; the member order and the flag bits below must match
// (tests/GpuBlockLayoutTest.cpp checks every member against glslang's layout).
//
// Everything the CPU computes once per call (the eye in voxel units, sigma h,
// the point light in voxel units) is computed here by the same code
// (core/math/March.h, MakeMarchParams in core/stages/render_march/ and its
// MakeLightTerms, core/pipeline/LightTerms.h), so the GPU starts from the CPU's floats.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "core/math/Light.h"
#include "core/pipeline/Backend.h"

namespace cb {

// MarchGpu.flags bits (the point light's switch is light.pointOn).
enum MarchGpuFlag : uint32_t {
    kMarchGpuAdaptive = 1u << 0,
    kMarchGpuJitter = 1u << 1,
    kMarchGpuPowder = 1u << 2,
    kMarchGpuSkipping = 1u << 4,
    kMarchGpuLightMarch = 1u << 5,  // the sun's light from a light march; else shade's T
    kMarchGpuGround = 1u << 6,      // the ground plane (core/math/Ground.h) is the background, per pixel
    kMarchGpuTiling = 1u << 7,      // the volume repeats in x and y (MarchSetup::tiling)
};

// Member for member march.glsl's MarchGpu (a scalar after a vec3 takes its fourth lane in std140 and std430).
struct alignas(16) MarchGpu {
    std::array<float, 3> eye;  // the eye in voxel units ((eye - origin) / h)
    float focalPx;
    std::array<float, 3> forward;
    float nearPlane;  // metres
    std::array<float, 3> right;
    float farPlane;  // metres
    std::array<float, 3> up;
    float voxelSize;            // h, metres
    std::array<float, 3> size;  // the box (nx, ny, nz)
    float sigmaH;
    float baseStep;  // Delta_0
    float kappa;
    float adaptiveStart;  // t_a
    float epsilon;
    std::array<float, 3> sun;  // unit, toward the sun
    float powderC;
    std::array<float, 3> background;  // rgb
    uint32_t flags;                   // MarchGpuFlag bits
    uint32_t width;
    uint32_t height;
    uint32_t seed;
    uint32_t frame;
    uint32_t lightSteps;             // n_l
    uint32_t brick;                  // the brick edge B
    uint32_t strideY;                // padded strides: px = nx + 2
    uint32_t strideZ;                // px * (ny + 2)
    std::array<uint32_t, 3> bricks;  // bricks along x, y, z (ceil(n / B))
    uint32_t unused;
    std::array<float, 3> invSize;  // 1 / size: the tiling's wrap
    uint32_t unused2;
    LightGpu light;  // the sun, the ambient light, the point light and the phase (core/math/Light.h)
};
static_assert(sizeof(MarchGpu) == 12 * 16 + sizeof(LightGpu), "MarchGpu is twelve 16-byte rows and its light");
static_assert(offsetof(MarchGpu, light) % 16 == 0, "a nested struct starts a 16-byte row");

// The block for one call on a grid of extent e. The Mie table's values are
// bound separately (kMieCloudTable, read by the index of march.glsl).
MarchGpu MakeMarchGpu(const MarchParams& params, const Extent3& e);

// Bricks along each axis for the skip structure: ceil(n / B), B >= 1.
std::array<uint32_t, 3> MarchBrickCounts(const Extent3& e, uint32_t brick);

// For a GPU backend whose render_march does not reproject yet: the scene's march.reprojection.block > 1 as the setting
// it cannot run (Backend::ExceededLimit), so that the backend is unavailable for the scene before any stage runs.
std::optional<LimitExceeded> MarchReprojectionNotBuilt(const Scene& scene, const std::string& backend);

}  // namespace cb
