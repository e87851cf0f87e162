#include "core/pipeline/LayersGpu.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cb {

LayersGpu MakeLayersGpu(const LayersParams& params) {
    const CameraFrame& c = params.camera;
    const LayersSetup& s = params.setup;
    LayersGpu g{};
    g.eye = {s.eye[0], s.eye[1], s.eye[2], c.focalPx};
    g.forward = {c.forward[0], c.forward[1], c.forward[2], c.nearPlane};
    g.right = {c.right[0], c.right[1], c.right[2], c.farPlane};
    g.up = {c.upVector[0], c.upVector[1], c.upVector[2], s.voxelSize};
    g.size = {s.size[0], s.size[1], s.size[2], s.sigmaH};
    g.invSize = {s.invSize[0], s.invSize[1], s.invSize[2], s.spacing};
    g.sun = {s.sun[0], s.sun[1], s.sun[2], s.phase.g};
    g.sunRadiance = {s.sunRadiance[0], s.sunRadiance[1], s.sunRadiance[2], s.outer2};
    g.ambient = {s.ambient[0], s.ambient[1], s.ambient[2], kMieCloudTable.indexPerRadian};
    g.background = {s.background[0], s.background[1], s.background[2], s.maxLength};
    g.image = {c.width, c.height, s.count,
               (s.tiling ? uint32_t(kLayersGpuTiling) : 0u) | (s.wang ? uint32_t(kLayersGpuWang) : 0u)};
    const uint32_t px = uint32_t(s.size[0]) + 2u, py = uint32_t(s.size[1]) + 2u;
    g.phase = {uint32_t(s.phase.kind), kMieCloudTable.count, px, px * py};
    g.drift = {s.drift[0], s.drift[1], s.coverage, s.density};
    g.light = {s.lightScale, s.fadeInv2, 0.0f, 0.0f};
    return g;
}

std::vector<uint32_t> LayersDrawOrder(const LayersSetup& s) {
    std::vector<uint32_t> order(s.count);
    std::iota(order.begin(), order.end(), 0u);
    auto distance = [&](uint32_t i) { return std::fabs(LayerHeight(s, i) - s.eye[2]); };
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return distance(a) > distance(b); });
    return order;
}

}  // namespace cb
