#include "harness/accuracy/SweepFields.h"

#include <algorithm>
#include <initializer_list>
#include <set>
#include <string>

#include "core/pipeline/LightTerms.h"
#include "core/plan/StageGraph.h"
#include "harness/accuracy/Evaluator.h"

namespace cb {
bool RowDependsOn(Stage stage, std::string_view path) {
    if (StageOutputReads(stage, path)) return true;
    return Describe(stage).renderer && StageOutputReads(ReferenceRenderer(), path) && !ReferenceRenderIgnores(path);
}

std::vector<SceneOverride> SettingsRead(Stage stage, std::span<const SceneOverride> setting) {
    std::vector<SceneOverride> out;
    for (const SceneOverride& o : setting)
        if (RowDependsOn(stage, o.path)) out.push_back(o);
    return out;
}

std::vector<Stage> SweepStages(const std::vector<SweepAxis>& axes) {
    // The renderers' reference render costs most: images are measured only when a light term's section or a
    // renderer's image field varies.
    const bool images = std::ranges::any_of(axes, [](const SweepAxis& a) {
        return FieldsListed(kLightTermFields, a.path) || std::ranges::any_of(RendererStages(), [&](Stage stage) {
                   return FieldsListed(Describe(stage).renderer->imageFields, a.path);
               });
    });
    std::vector<Stage> candidates = {Stage::Shade, Stage::Shadow};
    if (images)
        candidates.insert(candidates.end(), RendererStages().begin(), RendererStages().end());
    std::vector<Stage> stages;
    for (Stage stage : candidates)
        if (std::ranges::any_of(axes, [&](const SweepAxis& a) { return RowDependsOn(stage, a.path); }))
            stages.push_back(stage);
    return stages;
}

std::vector<std::vector<Stage>> DistinctMeasurements(const std::vector<std::vector<SceneOverride>>& points,
                                                     std::span<const Stage> stages) {
    std::vector<std::vector<Stage>> out(points.size());
    for (Stage stage : stages) {
        std::set<std::vector<std::pair<std::string, std::string>>> seen;
        for (size_t k = 0; k < points.size(); ++k) {
            std::vector<std::pair<std::string, std::string>> key;
            for (const SceneOverride& o : SettingsRead(stage, points[k])) key.emplace_back(o.path, o.value);
            if (seen.insert(std::move(key)).second) out[k].push_back(stage);
        }
    }
    // Each point's stages in the order of `stages`.
    return out;
}

}  // namespace cb
