// The references one process computes and keeps for `accuracy` and `sweep`:
// the lighting stages' inputs (the CPU simulation) per distinct setting, the
// exact Embree references of T and G for them, and the reference renders (the
// ray march with the parameters of the renderer whose descriptor has
// referenceParams; docs/accuracy.md), each computed once and cached.
#pragma once

#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"
#include "harness/accuracy/Accuracy.h"
#include "harness/run/Session.h"
#include "reference/MarchReference.h"

namespace cb {

class ImageReferences;

// printf of one value, for labels and cache keys.
std::string Fmt(const char* format, double value);

// The reference render of the scene's first camera at the inputs' step, with
// q_prev = q_cur = the inputs' q (as every renderer measured here is fed).
struct ImageReference {
    std::string phase;  // the phase function's name (the scene's, or "mie" for phase rows)
    float stepVoxels = 0.125f;
    uint32_t width = 0, height = 0;
    ref::MarchReferenceResult result;
};
Result<ImageReference> ComputeImageReference(const Scene& scene, const LightingInputs& in, float stepVoxels,
                                             int threads);

struct ReferenceRecord {
    std::string key;  // what the reference was computed for, for a reader
    ref::TraceStats tStats, gStats;
    double buildSeconds = 0;
    size_t primitives = 0;
};

class Evaluator {
  public:
    Evaluator(const Session& session, const MeasurementOptions& measurement, ref::RayStart start)
        : mSession(session), mMeasurement(measurement), mStart(start) {}

    // q and D for a scene loaded with `overrides` (cached by the overrides that can change them).
    Result<const LightingInputs*> Inputs(const Scene& scene, const std::vector<SceneOverride>& overrides);
    // The reference for the last Inputs() and the scene's sun, sigma and h.
    Result<const ReferenceResult*> Reference(const Scene& scene, const LightingInputs& in, ref::RayStart start);
    Result<const ReferenceResult*> Reference(const Scene& scene, const LightingInputs& in) {
        return Reference(scene, in, mStart);
    }

    // The session's scene with `extra` overrides, its inputs and its reference.
    struct Point {
        Scene scene;
        const LightingInputs* in = nullptr;
        const ReferenceResult* reference = nullptr;
    };
    Result<Point> Load(std::span<const SceneOverride> extra);

    const std::vector<ReferenceRecord>& Records() const { return mRecords; }
    const CommonOptions& Options() const { return mSession.Options(); }
    // --repeat and --reference-step of the command that measures.
    const MeasurementOptions& Measurement() const { return mMeasurement; }
    const Session& GetSession() const { return mSession; }
    // The reference renders of this process (harness/accuracy/ImageAccuracy.h), made on first use.
    ImageReferences& Images();

  private:
    // Bounds memory (a thesis-sized reference is about 11 MB): past kKept
    // entries, all but the last one returned are dropped, so the pointer the
    // caller still holds from the previous call stays valid.
    static constexpr size_t kKept = 8;
    template <typename Map>
    static void KeepOnlyLast(Map& map, const std::string& last) {
        if (map.size() < kKept) return;
        for (auto it = map.begin(); it != map.end();) it = it->first == last ? std::next(it) : map.erase(it);
    }

    const Session& mSession;
    const MeasurementOptions& mMeasurement;
    ref::RayStart mStart;
    std::string mLastReference;
    std::map<std::string, LightingInputs> mInputs;
    std::map<std::string, ReferenceResult> mReferences;
    std::vector<ReferenceRecord> mRecords;
    std::string mLastKey;
    std::shared_ptr<ImageReferences> mImages;
};

// The reference renders of one process, cached by the overrides that change
// the physical model (not a renderer's method: step, light source, n_l,
// epsilon, jitter, skipping, shade/shadow/density settings); a setting that
// varies phase.function gets the reference with the Mie phase.
class ImageReferences {
  public:
    ImageReferences(Evaluator& eval, const Session& session);
    struct Loaded {
        Scene scene;  // the session's scene with the setting
        const LightingInputs* in = nullptr;
        const ImageReference* reference = nullptr;  // valid until the next Load
    };
    Result<Loaded> Load(const std::vector<SceneOverride>& setting);
    // One JSON object per reference rendered (docs/results.md, image_references).
    const nlohmann::json& Records() const { return mRecords; }

  private:
    Evaluator& mEval;
    const Session& mSession;
    std::map<std::string, ImageReference> mCache;
    nlohmann::json mRecords = nlohmann::json::array();
};

// Whether a field changes how a renderer computes the image but not the physical model the reference
// render computes (the reference fixes its own step, light, epsilon, jitter and skipping, and reads no
// shade (but shade.sigma), shadow, density or layers setting): the reference is cached across it.
bool ReferenceRenderIgnores(std::string_view path);
// Whether a change of `path` leaves q and D as they are (no stage writing them reads it, StageOutputReads):
// the lighting inputs are then simulated once for every value.
bool LightingOnly(std::string_view path);
// The renderer whose parameters the exact reference render takes (RendererDescriptor::referenceParams).
Stage ReferenceRenderer();

// Whether a setting changes the physical model (the phase function): its
// rows are measured against the reference with the Mie phase.
bool VariesPhase(const std::vector<SceneOverride>& setting);

}  // namespace cb
