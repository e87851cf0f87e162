#include "core/pipeline/ShaftsPass.h"

namespace cb {

ShaftsFrame MakeSceneShaftsFrame(const Scene& sc, const CameraFrame& camera, uint32_t step) {
    const std::array<float, 3> origin{float(sc.grid.origin[0]), float(sc.grid.origin[1]), float(sc.grid.origin[2])};
    const Extent3& n = sc.grid.size;
    return MakeShaftsFrame(sc.lighting.shafts, camera, origin, float(sc.grid.voxelSize), n.nx, n.ny, n.nz,
                           sc.grid.tiling, sc.sun.DirectionAt(step), sc.sun.Radiance(), sc.shadow.form,
                           float(sc.shade.sigma), float(sc.shadow.kappa), float(sc.shadow.coverage),
                           float(sc.shadow.densityFactor));
}

Status CheckShaftsBuffers(const ShaftsFrame& frame, const Buffer& columnSum, const Buffer& image,
                          std::string_view backend) {
    if (columnSum.Extent() != Extent3{frame.gridX, frame.gridY, 1})
        return MakeError(std::string(backend) + ": shafts: D is not (nx, ny, 1) of the frame's grid");
    if (image.Extent() != Extent3{3, frame.width, frame.height})
        return MakeError(std::string(backend) + ": shafts: the image is not (3, width, height)");
    return {};
}

}  // namespace cb
