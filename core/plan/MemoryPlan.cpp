#include "core/plan/MemoryPlan.h"

#include <algorithm>

#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"

namespace cb {

uint64_t HostStagingBytes(const Scene& scene) {
    uint64_t largest = 0;
    for (const PlannedBuffer& b : PlanBuffers(scene))
        largest = std::max(largest, CanonicalBufferBytes(b.format, b.extent));
    return largest;
}

uint64_t EstimateSceneBytes(const Scene& scene) {
    uint64_t bytes = HostStagingBytes(scene);
    for (const PlannedBuffer& b : PlanBuffers(scene)) bytes = SaturatingAdd(bytes, HostBufferBytes(b.format, b.extent));
    return bytes;
}

uint64_t PlannedBytes(const Scene& scene, const Backend& backend) {
    uint64_t bytes = backend.ScratchBytes(scene);
    for (const PlannedBuffer& b : PlanBuffers(scene))
        bytes = SaturatingAdd(bytes, backend.BufferBytes(b.format, b.extent));
    return bytes;
}

Status CheckPlannedBytesFit(const Scene& scene, const Backend& backend) {
    const std::optional<uint64_t> available = backend.AvailableBytes();
    if (!available) return {};
    const uint64_t needed = PlannedBytes(scene, backend);
    if (needed <= *available) return {};
    return MakeError(backend.Name() + ": the scene's buffers need " + FormatGiB(needed) + " GiB (" +
                     std::to_string(needed) + " bytes), more than the " + FormatGiB(*available) + " GiB (" +
                     std::to_string(*available) + " bytes) available to it");
}

Status CheckDeviceLimits(const Scene& scene, const Backend& backend) {
    const std::optional<LimitExceeded> exceeded = backend.ExceededLimit(scene);
    if (!exceeded) return {};
    return MakeError((scene.path.empty() ? scene.name : scene.path) + ": " + exceeded->field + ": " + exceeded->reason);
}

}  // namespace cb
