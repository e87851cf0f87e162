#include "harness/accuracy/Evaluator.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "core/scene/SceneNames.h"

namespace cb {
using nlohmann::json;

bool LightingOnly(std::string_view path) {
    for (Stage stage : kAllStages) {
        const std::vector<Resource>& writes = Describe(stage).writes;
        const bool volume = std::ranges::any_of(writes, [](Resource r) { return r == Resource::Q || r == Resource::ColumnSum; });
        if (volume && StageOutputReads(stage, path)) return false;
    }
    return true;
}

bool ReferenceRenderIgnores(std::string_view p) {
    // A renderer's own settings the reference does not read: the field itself, or one inside it.
    auto within = [&](std::string_view field) { return p == field || (p.starts_with(field) && p[field.size()] == '.'); };
    for (Stage stage : kAllStages)
        if (const RendererDescriptor* r = Describe(stage).renderer)
            if (std::ranges::any_of(r->referenceIgnores, within)) return true;
    if (p == "repeats" || p == "warmup_steps") return true;
    if (p == "shade.sigma") return false;
    for (const char* prefix : {"shade.", "shadow.", "density."})
        if (p.starts_with(prefix)) return true;
    return false;
}

Stage ReferenceRenderer() {
    for (Stage stage : kAllStages)
        if (const RendererDescriptor* r = Describe(stage).renderer; r && r->referenceParams) return stage;
    throw std::logic_error("no renderer gives the reference render's parameters");
}

std::string Fmt(const char* format, double value) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, format, value);
    return buffer;
}

Result<ImageReference> ComputeImageReference(const Scene& scene, const LightingInputs& in, float stepVoxels,
                                             int threads) {
    if (scene.render.cameras.empty()) return MakeError(scene.path + ": render: the reference render needs a camera");
    const MarchParams p = Describe(ReferenceRenderer()).renderer->referenceParams(scene, scene.render.cameras[0], in.step);
    ref::MarchReferenceOptions options;
    options.stepVoxels = stepVoxels;
    options.threads = threads;
    auto r = ref::RenderMarchReference(p, in.grid, in.q, in.q, options);
    if (!r) return std::unexpected(r.error());
    ImageReference out;
    out.phase = std::string(PhaseKindName(scene.phase.kind));
    out.stepVoxels = stepVoxels;
    out.width = p.camera.width;
    out.height = p.camera.height;
    out.result = std::move(*r);
    return out;
}

Result<const LightingInputs*> Evaluator::Inputs(const Scene& scene, const std::vector<SceneOverride>& overrides) {
    std::string key;
    for (const SceneOverride& o : overrides)
        if (!LightingOnly(o.path)) key += o.path + "=" + o.value + ";";
    auto it = mInputs.find(key);
    if (it == mInputs.end()) {
        if (!mSession.Options().quiet)
            std::fprintf(stderr, "simulating %u steps of %s%s%s\n", scene.steps, scene.name.c_str(),
                         key.empty() ? "" : " with ", key.c_str());
        auto in = SimulateLightingInputs(scene, mSession.Options().cpuThreads);
        if (!in) return std::unexpected(in.error());
        KeepOnlyLast(mInputs, mLastKey);
        it = mInputs.emplace(key, std::move(*in)).first;
    }
    mLastKey = key;
    return &it->second;
}

Result<const ReferenceResult*> Evaluator::Reference(const Scene& scene, const LightingInputs& in, ref::RayStart start) {
    const Vec3 s = scene.sun.Direction();
    const std::string key = mLastKey + "|sun " + Fmt("%.9g", s[0]) + " " + Fmt("%.9g", s[1]) + " " + Fmt("%.9g", s[2]) +
                            " sigma " + Fmt("%.17g", scene.shade.sigma) + " h " + Fmt("%.17g", scene.grid.voxelSize) +
                            " " + ref::RayStartName(start);
    // What a reader needs: the inputs that differ from the scene, the sun, the start.
    std::string label;
    for (size_t a = 0, b; a < mLastKey.size(); a = b + 1) {
        b = std::min(mLastKey.find(';', a), mLastKey.size());
        const std::string item = mLastKey.substr(a, b - a);
        if (!item.starts_with("warmup_steps=")) label += item + ", ";
    }
    label += "sun el " + Fmt("%.6g", scene.sun.elevationDeg) + " az " + Fmt("%.6g", scene.sun.azimuthDeg) +
             ", from the " + ref::RayStartName(start);
    auto it = mReferences.find(key);
    if (it == mReferences.end()) {
        auto r = ComputeReference(scene, in, start, mSession.Options().cpuThreads);
        if (!r) return std::unexpected(r.error());
        ReferenceRecord rec{label, r->tStats, r->gStats, r->buildSeconds, r->primitives};
        if (!mSession.Options().quiet)
            std::fprintf(stderr,
                         "reference for %s: %zu boxes built in %.3f s; T_ref %llu rays in %.3f s (%.2f M rays/s), "
                         "G_ref %llu rays in %.3f s\n",
                         label.c_str(), rec.primitives, rec.buildSeconds, (unsigned long long)rec.tStats.rays,
                         rec.tStats.seconds, rec.tStats.RaysPerSecond() / 1e6, (unsigned long long)rec.gStats.rays,
                         rec.gStats.seconds);
        mRecords.push_back(rec);
        KeepOnlyLast(mReferences, mLastReference);
        it = mReferences.emplace(key, std::move(*r)).first;
    }
    mLastReference = key;
    return &it->second;
}
Result<Evaluator::Point> Evaluator::Load(std::span<const SceneOverride> extra) {
    auto scene = mSession.LoadVariant(extra);
    if (!scene) return std::unexpected(scene.error());
    std::vector<SceneOverride> all = mSession.Options().overrides;
    all.insert(all.end(), extra.begin(), extra.end());
    auto in = Inputs(*scene, all);
    if (!in) return std::unexpected(in.error());
    auto reference = Reference(*scene, **in);
    if (!reference) return std::unexpected(reference.error());
    return Point{std::move(*scene), *in, *reference};
}

ImageReferences& Evaluator::Images() {
    if (!mImages) mImages = std::make_shared<ImageReferences>(*this, mSession);
    return *mImages;
}

ImageReferences::ImageReferences(Evaluator& eval, const Session& session) : mEval(eval), mSession(session) {}

Result<ImageReferences::Loaded> ImageReferences::Load(const std::vector<SceneOverride>& setting) {
    auto scene = mSession.LoadVariant(setting);
    if (!scene) return std::unexpected(scene.error());
    std::vector<SceneOverride> all = mSession.Options().overrides;
    all.insert(all.end(), setting.begin(), setting.end());
    auto in = mEval.Inputs(*scene, all);
    if (!in) return std::unexpected(in.error());
    std::vector<SceneOverride> physical;
    for (const SceneOverride& o : setting)
        if (!ReferenceRenderIgnores(o.path) && o.path != "phase.function") physical.push_back(o);
    if (VariesPhase(setting)) physical.push_back({"phase.function", "mie"});
    std::string key;
    for (const SceneOverride& o : physical) key += (key.empty() ? "" : " ") + o.path + "=" + o.value;
    auto it = mCache.find(key);
    if (it == mCache.end()) {
        auto refScene = mSession.LoadVariant(physical);
        if (!refScene) return std::unexpected(refScene.error());
        const float step = float(mEval.Measurement().referenceStep);
        if (!mSession.Options().quiet)
            std::fprintf(stderr, "reference render of %s%s%s at step %g voxel\n", scene->name.c_str(),
                         key.empty() ? "" : " with ", key.c_str(), double(step));
        auto r = ComputeImageReference(*refScene, **in, step, mSession.Options().cpuThreads);
        if (!r) return std::unexpected(r.error());
        if (mCache.size() >= 4) mCache.clear();  // bounds memory; the caller holds no pointer across calls
        it = mCache.emplace(key, std::move(*r)).first;
        json rec = {{"inputs", key.empty() ? "(scene)" : key},
                    {"phase", it->second.phase},
                    {"step_voxels", it->second.stepVoxels},
                    {"width", it->second.width},
                    {"height", it->second.height},
                    {"samples", it->second.result.samples},
                    {"light_rays", it->second.result.light.rays},
                    {"seconds", it->second.result.light.seconds},
                    {"rays_per_s", it->second.result.light.RaysPerSecond()},
                    {"build_s", it->second.result.buildSeconds},
                    {"boxes", it->second.result.primitives}};
        mRecords.push_back(rec);
    }
    return Loaded{std::move(*scene), *in, &it->second};
}

bool VariesPhase(const std::vector<SceneOverride>& setting) {
    return std::ranges::any_of(setting, [](const SceneOverride& o) { return o.path == "phase.function"; });
}

}  // namespace cb
