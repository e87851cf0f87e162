// A backend's stage objects: one per stage the backend implements, each holding
// what its stage keeps between calls (scratch buffers and textures, tables made
// once, what a share of a sweep hands to the next) and saying what a scene makes
// it need (ScratchBytes). The façade keeps the context, runs its entries on
// these objects, and derives from the list what it supports and its scratch
// total, so a new stage on a backend is one object added to its list.
//
// A stage object is default-constructible and has
//   static constexpr Stage kStage;                        // the stage it serves
//   uint64_t ScratchBytes(const Scene& scene) const;      // what it allocates for `scene`
// ScratchBytes is asked only for the stages the scene runs.
#pragma once

#include <cstdint>
#include <tuple>
#include <type_traits>

#include "core/base/ProcessMemory.h"
#include "core/scene/Scene.h"
#include "core/scene/Stage.h"

namespace cb {

template <typename... Objects>
class StageObjects {
  public:
    // Whether one of the objects serves `stage`.
    static constexpr bool Implements(Stage stage) { return ((Objects::kStage == stage) || ...); }

    template <typename Object>
    Object& Get() {
        return std::get<Object>(mObjects);
    }
    template <typename Object>
    const Object& Get() const {
        return std::get<Object>(mObjects);
    }

    // The sum of the objects' ScratchBytes over the stages `scene` runs (saturating).
    uint64_t ScratchBytes(const Scene& scene) const {
        uint64_t bytes = 0;
        std::apply(
            [&](const auto&... object) {
                ((bytes = scene.stages.Has(object.kStage) ? SaturatingAdd(bytes, object.ScratchBytes(scene)) : bytes),
                 ...);
            },
            mObjects);
        return bytes;
    }

  private:
    static constexpr bool DistinctStages() {
        const Stage stages[] = {Objects::kStage...};
        for (size_t i = 0; i < sizeof...(Objects); ++i)
            for (size_t j = i + 1; j < sizeof...(Objects); ++j)
                if (stages[i] == stages[j]) return false;
        return true;
    }
    static_assert(sizeof...(Objects) > 0 && DistinctStages(), "one object per stage");

    std::tuple<Objects...> mObjects;
};

// The object of a stage that keeps nothing between calls on a backend.
template <Stage S>
struct NothingKept {
    static constexpr Stage kStage = S;
    uint64_t ScratchBytes(const Scene&) const { return 0; }
};

}  // namespace cb
