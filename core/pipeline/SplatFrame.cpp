#include "core/pipeline/SplatFrame.h"

namespace cb {

SplatFrame MakeSplatFrame(const SplatParams& p, const Extent3& e, const FlatSplatOrder& flat, uint32_t width,
                          uint32_t height) {
    const CameraFrame& cam = p.camera;
    const SplatOrder& order = *p.order;
    return {{e.nx, e.ny, e.nz, 0},
            {uint32_t(order.axes[0]), uint32_t(order.axes[1]), uint32_t(order.axes[2]), uint32_t(e.Count())},
            {flat.base[0], flat.base[1], flat.base[2], 0},
            {p.tile, p.band, CeilDiv(e.nx, p.tile), CeilDiv(e.ny, p.tile)},
            {width, height, 0, 0},
            {cam.eye[0], cam.eye[1], cam.eye[2], cam.nearPlane},
            {cam.forward[0], cam.forward[1], cam.forward[2], cam.focalPx},
            {cam.right[0], cam.right[1], cam.right[2], kMieCloudTable.indexPerRadian},
            {cam.upVector[0], cam.upVector[1], cam.upVector[2], float(kMieCloudTable.count)},
            {p.sun[0], p.sun[1], p.sun[2], p.phase.g},
            {p.sunRadiance[0], p.sunRadiance[1], p.sunRadiance[2], float(p.phase.kind)},
            {p.ambient[0], p.ambient[1], p.ambient[2], p.qMin},
            {p.background[0], p.background[1], p.background[2], p.opacity},
            {p.origin[0], p.origin[1], p.origin[2], p.voxelSize},
            {p.splatDiameter, p.alpha, 0, 0}};
}

}  // namespace cb
