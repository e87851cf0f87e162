#include "core/pipeline/SplatFrame.h"

namespace cb {

SplatFrame MakeSplatFrame(const SplatParams& p, const Extent3& e, const FlatSplatOrder& flat, uint32_t width,
                          uint32_t height) {
    const CameraFrame& cam = p.camera;
    const SplatOrder& order = *p.order;
    SplatFrame F{};
    const uint32_t grid[3] = {e.nx, e.ny, e.nz};
    for (int a = 0; a < 3; ++a) {
        F.grid[a] = grid[a];
        F.axes[a] = uint32_t(order.axes[a]);
        F.orderBase[a] = flat.base[a];
        F.eye[a] = cam.eye[a];
        F.forward[a] = cam.forward[a];
        F.right[a] = cam.right[a];
        F.up[a] = cam.upVector[a];
        F.sun[a] = p.sun[a];
        F.background[a] = p.background[a];
        F.origin[a] = p.origin[a];
    }
    F.voxelCount = uint32_t(e.Count());
    F.boxTile = p.tile;
    F.boxBand = p.band;
    F.boxTilesX = CeilDiv(e.nx, p.tile);
    F.boxTilesY = CeilDiv(e.ny, p.tile);
    F.width = width;
    F.height = height;
    F.nearPlane = cam.nearPlane;
    F.focalPx = cam.focalPx;
    F.qMin = p.qMin;
    F.opacity = p.opacity;
    F.voxelSize = p.voxelSize;
    F.splatDiameter = p.splatDiameter;
    F.alpha = p.alpha;
    F.light = MakeLightGpu(p.light);
    return F;
}

}  // namespace cb
