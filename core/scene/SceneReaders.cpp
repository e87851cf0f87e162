// Readers of the grid and the stage list.
#include "core/scene/SceneReaders.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string_view>
#include <utility>
#include <vector>

namespace cb::scene_io {
namespace {

constexpr Stage kDefaultStages[] = {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density};

constexpr std::string_view kGridKeys[] = {"size", "voxel_size", "origin", "tiling"};

}  // namespace

// Returns true when grid.size is present and valid.
bool ReadGrid(const Json& root, Validator& check, GridSettings& grid) {
    const Json* section = Validator::Find(root, "grid");
    if (!section) {
        check.Fail("grid.size", "required field is missing");
        return false;
    }
    section = check.Section(root, "", "grid", kGridKeys);
    if (!section) return false;

    bool sizeOk = false;
    if (const Json* size = Validator::Find(*section, "size")) {
        if (auto n = check.Integers<3>(*size, "grid.size", 1, kU32Max)) {
            grid.size = Extent3{uint32_t((*n)[0]), uint32_t((*n)[1]), uint32_t((*n)[2])};
            sizeOk = true;
        }
    } else {
        check.Fail("grid.size", "required field is missing");
    }
    if (const Json* v = Validator::Find(*section, "voxel_size")) {
        if (auto d = check.Number(*v, "grid.voxel_size", kSinglePositive)) grid.voxelSize = *d;
    }
    if (const Json* v = Validator::Find(*section, "origin")) {
        if (auto a = check.Numbers<3>(*v, "grid.origin", kFinite)) grid.origin = *a;
    }
    if (const Json* v = Validator::Find(*section, "tiling")) {
        if (auto b = check.Boolean(*v, "grid.tiling")) grid.tiling = *b;
    }
    return sizeOk;
}

bool ReadStages(const Json& root, Validator& check, StageSet& stages) {
    const Json* list = Validator::Find(root, "stages");
    if (!list) {
        for (Stage stage : kDefaultStages) stages.Add(stage);
        return true;
    }
    if (!list->is_array()) {
        check.Fail("stages", "expected an array of stage names, got " + Describe(*list));
        return false;
    }
    if (list->empty()) {
        check.Fail("stages", "must name at least one stage, got []");
        return false;
    }
    std::vector<std::string_view> known;
    for (Stage stage : kAllStages) known.push_back(StageName(stage));

    bool allOk = true;
    for (size_t i = 0; i < list->size(); ++i) {
        const std::string field = IndexField("stages", i);
        auto name = check.String((*list)[i], field);
        if (!name) {
            allOk = false;
            continue;
        }
        std::optional<Stage> stage = ParseStage(*name);
        if (!stage) {
            std::string all;
            for (std::string_view k : known) all += (all.empty() ? "" : ", ") + std::string(k);
            check.Fail(field, "unknown stage " + Quote(*name) + Suggestion(*name, known) + "; known: " + all);
            allOk = false;
        } else if (stages.Has(*stage)) {
            check.Fail(field, "duplicate stage " + Quote(*name));
            allOk = false;
        } else {
            stages.Add(*stage);
        }
    }
    return allOk;
}

}  // namespace cb::scene_io
