#include "core/pipeline/LayersGpu.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cb {

LayersGpu MakeLayersGpu(const LayersParams& params, uint32_t billboardCount) {
    const CameraFrame& c = params.camera;
    const LayersSetup& s = params.setup;
    LayersGpu g{};
    SetCameraMembers(g, c, s.eye, s.voxelSize);
    g.size = s.size;
    g.sigmaH = s.sigmaH;
    g.invSize = s.invSize;
    g.spacing = s.spacing;
    g.sun = s.sun;
    g.outer2 = s.outer2;
    g.background = s.background;
    g.maxLength = s.maxLength;
    g.count = s.count;
    g.flags = (s.tiling ? uint32_t(kLayersGpuTiling) : 0u) | (s.wang ? uint32_t(kLayersGpuWang) : 0u);
    const uint32_t px = uint32_t(s.size[0]) + 2u, py = uint32_t(s.size[1]) + 2u;
    g.strideY = px;
    g.strideZ = px * py;
    g.lightScale = s.lightScale;
    g.fadeInv2 = s.fadeInv2;
    g.drift = s.drift;
    g.coverage = s.coverage;
    g.density = s.density;
    g.inner2 = s.inner2;
    g.halfWidth = s.halfWidth;
    g.halfHeight = s.halfHeight;
    g.billboardLength = s.billboardLength;
    g.billboardCount = billboardCount;
    g.light = MakeLightGpu(s.light);
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
