#include "core/pipeline/ShadePlan.h"

#include "core/pipeline/Backend.h"

namespace cb {

ShadePlan MakeShadePlan(const ShadeParams& p, const Extent3& e) {
    ShadePlan plan;
    const uint32_t f = uint32_t(p.resolution);
    plan.resolution = p.resolution;
    plan.cells[0] = CeilDiv(e.nx, f);
    plan.cells[1] = CeilDiv(e.ny, f);
    plan.cells[2] = CeilDiv(e.nz, f);
    plan.geometry = MakeShearWarp(p.sun, p.filter);
    plan.attenuation =
        MakeSliceAttenuation(p.attenuation, p.sigma, p.voxelSize * float(p.resolution), plan.geometry.absSw, p.thesisAr,
                             p.scattering, p.albedo, p.solidAngle, p.phase);
    plan.nu = plan.cells[plan.geometry.u];
    plan.nv = plan.cells[plan.geometry.v];
    plan.nw = plan.cells[plan.geometry.w];
    return plan;
}

}  // namespace cb
