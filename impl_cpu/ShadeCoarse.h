// Shade at resolution f > 1 on the CPU (impl_cpu/ShadeCoarseCpu.cpp): the
// sweep runs on a coarse grid of plan.cells, formed from q and read back into T.
#pragma once
#include <tbb/task_arena.h>

#include "core/math/Grid.h"

namespace cb {
struct ShadePlan;
}

namespace cb::cpu {

// The coarse grid of q at resolution f: the mean of each f^3 block (partial
// blocks: of the voxels present). `cq` (plan.cells) must hold zeros.
void DownsampleShadeQ(const ShadePlan& plan, int f, const float* q, const Extent3& e, float* cq,
                      tbb::task_arena& arena);

// T at full resolution (extent e), trilinear from the coarse T `ct` (plan.cells):
// full voxel i sits at coarse coordinate (i + 0.5) / f - 0.5, clamped to the
// coarse grid's centres.
void UpsampleShadeT(const ShadePlan& plan, int f, const float* ct, const Extent3& e, float* T, tbb::task_arena& arena);

}  // namespace cb::cpu
