#include "core/pipeline/LightTerms.h"

namespace cb {

LightTerms MakeLightTerms(const Scene& sc, uint32_t step) {
    LightTerms L;
    L.sunRadiance = sc.sun.Radiance();
    L.ambient = sc.lighting.Ambient();
    L.phase = sc.phase;
    L.voxelSize = float(sc.grid.voxelSize);
    const LightningSettings& l = sc.lightning;
    L.pointOn = l.OnAt(step);
    for (int c = 0; c < 3; ++c) {
        L.pointPosition[c] = float((l.position[c] - sc.grid.origin[c]) / sc.grid.voxelSize);
        L.pointRadiance[c] = float(l.color[c] * l.intensity);
    }
    L.pointMinDistance2 = float(l.radius * l.radius);
    return L;
}

}  // namespace cb
