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

}  // namespace cb
