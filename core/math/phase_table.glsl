// GLSL twin of core/math/Shading.h's PhaseValue for every PhaseKind, the Mie
// table's lookup (SamplePhaseTable) included. Include after shading.glsl. The
// including shader DEFINES
//   float PhaseTableValue(uint i);  // kMieCloudTable.values[i]; read with phase Mie only
// (OpenGL's linker wants its body even where nothing calls it).
#ifndef CLOUDBENCH_PHASE_TABLE_GLSL
#define CLOUDBENCH_PHASE_TABLE_GLSL

const uint kPhaseMie = 3u;       // PhaseKind::Mie
const uint kPhaseDualLobe = 4u;  // PhaseKind::DualLobe

float PhaseTableValue(uint i);

// The table linearly interpolated in theta (SamplePhaseTable), read by hand:
// hardware filtering's few fractional weight bits would break conformance.
float SamplePhaseTable(float indexPerRadian, uint count, float cosTheta) {
    const float theta = ArcCos(clamp(cosTheta, -1.0, 1.0));
    precise float x = clamp(theta * indexPerRadian, 0.0, float(count - 1u));
    const uint i = min(uint(x), count - 2u);
    return Lerp(PhaseTableValue(i), PhaseTableValue(i + 1u), x - float(i));
}

// P^(cos theta) = 4 pi p(theta) for phase `kind` (PhaseValue); `lobes` (g_forward, g_backward, blend) are
// read with phase dual-lobe only, the table's index per radian and count with phase Mie only.
float PhaseOf(uint kind, float g, vec3 lobes, float indexPerRadian, uint count, float cosTheta) {
    if (kind == kPhaseMie) return SamplePhaseTable(indexPerRadian, count, cosTheta);
    if (kind == kPhaseDualLobe) return DualLobePhase(lobes.x, lobes.y, lobes.z, cosTheta);
    return PhaseValue(kind, g, cosTheta);
}

#endif
