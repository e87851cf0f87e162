#include "core/pipeline/MarchGpu.h"

#include <algorithm>
#include <string>

#include "core/scene/Scene.h"

namespace cb {

std::array<uint32_t, 3> MarchBrickCounts(const Extent3& e, uint32_t brick) {
    const uint32_t b = std::max(brick, 1u);
    return {CeilDiv(e.nx, b), CeilDiv(e.ny, b), CeilDiv(e.nz, b)};
}

MarchGpu MakeMarchGpu(const MarchParams& params, const Extent3& e) {
    const CameraFrame& c = params.camera;
    const MarchSetup& s = params.setup;
    MarchGpu g{};
    // The eye as MakePixelRay forms it: (eye - origin) / h, per component.
    std::array<float, 3> eye;
    for (int i = 0; i < 3; ++i) eye[i] = (c.eye[i] - params.origin[i]) / s.voxelSize;
    SetCameraMembers(g, c, eye, s.voxelSize);
    g.size = s.size;
    g.sigmaH = s.sigmaH;
    g.baseStep = s.step;
    g.kappa = s.kappa;
    g.adaptiveStart = s.adaptiveStart;
    g.epsilon = s.epsilon;
    g.sun = s.sun;
    g.powderC = s.powderC;
    g.background = s.background;
    uint32_t flags = 0;
    if (s.adaptive) flags |= kMarchGpuAdaptive;
    if (params.jitter) flags |= kMarchGpuJitter;
    if (s.powder) flags |= kMarchGpuPowder;
    if (params.skipping) flags |= kMarchGpuSkipping;
    if (params.light == MarchLightSource::March) flags |= kMarchGpuLightMarch;
    if (params.ground.on) flags |= kMarchGpuGround;
    if (s.tiling) flags |= kMarchGpuTiling;
    g.flags = flags;
    g.seed = params.seed;
    g.frame = params.frame;
    const uint32_t brick = std::max(params.brick, 1u);
    g.lightSteps = params.lightSteps;
    g.brick = brick;
    g.strideY = e.nx + 2;
    g.strideZ = (e.nx + 2) * (e.ny + 2);
    const auto counts = MarchBrickCounts(e, brick);
    g.bricks = {counts[0], counts[1], counts[2]};
    g.invSize = s.invSize;
    g.light = MakeLightGpu(s.light);
    return g;
}

std::optional<LimitExceeded> MarchReprojectionNotBuilt(const Scene& scene, const std::string& backend) {
    if (!scene.stages.Has(Stage::RenderMarch) || scene.march.reprojectionBlock <= 1) return std::nullopt;
    return LimitExceeded{"march.reprojection.block",
                         backend + ": temporal reprojection (block " + std::to_string(scene.march.reprojectionBlock) +
                             ") is implemented on the cpu backend only so far; set it to 1 to trace every pixel"};
}

}  // namespace cb
