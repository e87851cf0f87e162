#include "core/pipeline/MarchGpu.h"

#include <algorithm>

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
    for (int i = 0; i < 3; ++i) g.eye[i] = (c.eye[i] - params.origin[i]) / s.voxelSize;
    g.eye[3] = c.focalPx;
    g.forward = {c.forward[0], c.forward[1], c.forward[2], c.nearPlane};
    g.right = {c.right[0], c.right[1], c.right[2], c.farPlane};
    g.up = {c.upVector[0], c.upVector[1], c.upVector[2], s.voxelSize};
    g.size = {s.size[0], s.size[1], s.size[2], s.sigmaH};
    g.stepping = {s.step, s.kappa, s.adaptiveStart, s.epsilon};
    g.sun = {s.sun[0], s.sun[1], s.sun[2], s.phase.g};
    g.sunRadiance = {s.sunRadiance[0], s.sunRadiance[1], s.sunRadiance[2], s.powderC};
    g.ambient = {s.ambient[0], s.ambient[1], s.ambient[2], kMieCloudTable.indexPerRadian};
    g.background = {s.background[0], s.background[1], s.background[2], 0.0f};
    g.pointPosition = {s.point.position[0], s.point.position[1], s.point.position[2], s.point.minDistance2};
    g.pointRadiance = {s.point.radiance[0], s.point.radiance[1], s.point.radiance[2], 0.0f};
    g.image = {c.width, c.height, params.seed, params.frame};
    uint32_t flags = 0;
    if (s.adaptive) flags |= kMarchGpuAdaptive;
    if (params.jitter) flags |= kMarchGpuJitter;
    if (s.powder) flags |= kMarchGpuPowder;
    if (s.point.on) flags |= kMarchGpuPointLight;
    if (params.skipping) flags |= kMarchGpuSkipping;
    if (params.light == MarchLightSource::March) flags |= kMarchGpuLightMarch;
    if (params.ground.on) flags |= kMarchGpuGround;
    const uint32_t brick = std::max(params.brick, 1u);
    g.flags = {flags, uint32_t(s.phase.kind), params.lightSteps, brick};
    g.strides = {e.nx + 2, (e.nx + 2) * (e.ny + 2), kMieCloudTable.count, 0};
    const auto counts = MarchBrickCounts(e, brick);
    g.bricks = {counts[0], counts[1], counts[2], 0};
    return g;
}

}  // namespace cb
