// Shafts of light (SPEC 18) on the CPU: ShaftsPixel (core/math/Shafts.h) for every pixel, rows in parallel, added to
// the renderer's image.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/math/Shafts.h"
#include "core/pipeline/ShaftsPass.h"
#include "impl_cpu/BackendCpu.h"

namespace cb::cpu {

Status BackendCpu::AddShafts(const ShaftsFrame& frame, const Buffer& columnSum, Buffer& image) {
    CB_TRY(CheckShaftsBuffers(frame, columnSum, image, "cpu"));
    const float* D = static_cast<const BufferCpu&>(columnSum).F32();
    float* out = static_cast<BufferCpu&>(image).F32();
    auto fetch = [&](uint32_t i, uint32_t j) { return D[i + size_t(frame.gridX) * j]; };
    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, frame.height, 4),
                          [&](const tbb::blocked_range<uint32_t>& rows) {
                              for (uint32_t y = rows.begin(); y != rows.end(); ++y)
                                  for (uint32_t x = 0; x < frame.width; ++x) {
                                      const Vec3 light = ShaftsPixel(frame, x, y, fetch);
                                      float* pixel = out + 3 * (x + size_t(frame.width) * y);
                                      for (int c = 0; c < 3; ++c) pixel[c] += light[c];
                                  }
                          });
    });
    return {};
}

}  // namespace cb::cpu
