// What a stage's descriptor says: what it reads and writes (resources), when
// it runs, and how two implementations of it are compared (CompareRule). Each
// stage's module (core/stages/<stage>/) holds its descriptor; the table of all
// of them, the schedule and the buffer plan are core/plan/StageGraph.h.
//
// Data flows through resources, never from stage to stage: "density needs q",
// whoever writes q (smooth, or a noise producer).
#pragma once

#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"
#include "core/scene/SectionReader.h"
#include "core/scene/Stage.h"

namespace cb {

// X(Enum, "name", format, "dump file stem"): the buffers that pass between
// stages (SPEC 0). An image has the stem "": it is one (3, width, height) buffer
// per camera, written as frames, not dumped. Any other resource is one buffer
// of the grid's extent unless ResourceExtent says otherwise.
#define CB_RESOURCES(X)                                                             \
    X(Region, "region", U8, "region") /* R: region weights, grid */                 \
    X(Hum, "hum", Bits, "hum")        /* automaton fields, grid */                  \
    X(Act, "act", Bits, "act")                                                      \
    X(Cld, "cld", Bits, "cld")                                                      \
    X(Q, "q", F32, "q")                   /* density in [0, 1], grid */             \
    X(ColumnSum, "D", F32, "density")     /* column sums, (nx, ny, 1) */            \
    X(Tiles, "tiles", U8, "tiles")        /* tile occupancy, (tx, ty, 1) */         \
    X(Bands, "bands", U8, "bands")        /* tile x band occupancy, (tx, ty, bz) */ \
    X(T, "T", F32, "T")                   /* transmittance toward the sun, grid */  \
    X(TSky, "T_sky", F32, "T_sky")        /* toward the sky light, grid */          \
    X(Shadow, "G", F32, "shadow")         /* ground shadow, (nx, ny, 1) */          \
    X(SplatImage, "image_splat", F32, "") /* (3, width, height) per camera */       \
    X(MarchImage, "image_march", F32, "")                                           \
    X(LayersImage, "image_layers", F32, "")

enum class Resource : uint8_t {
#define CB_RESOURCE_ENUM(name, text, format, file) name,
    CB_RESOURCES(CB_RESOURCE_ENUM)
#undef CB_RESOURCE_ENUM
};

inline constexpr std::array kAllResources = {
#define CB_RESOURCE_VALUE(name, text, format, file) Resource::name,
    CB_RESOURCES(CB_RESOURCE_VALUE)
#undef CB_RESOURCE_VALUE
};
inline constexpr size_t kResourceCount = kAllResources.size();

std::string_view ResourceName(Resource resource);
// The stem of the resource's array in a dump (`dump`: DIR/step_tttt/<stem>.npy);
// "" for images, which are written as frames.
std::string_view ResourceDumpStem(Resource resource);
BufferFormat ResourceFormat(Resource resource);
// The extent of one buffer of the resource in this scene.
Extent3 ResourceExtent(Resource resource, const Scene& scene);
// Images (dump stem ""): one buffer per camera; every other resource: one.
bool IsPerCamera(Resource resource);

// How two implementations of a stage are compared, as data (SPEC's rule for
// the stage). Integer and boolean outputs are bit-exact; floats within a
// tolerance; images by SPEC 8's (or SPEC 10's) pixel-share rule.
struct CompareRule {
    enum class Kind : uint8_t {
        BitExact,   // every element equal
        Absolute,   // |d| <= tolerance everywhere
        Quantised,  // |d| <= tolerance everywhere, and at most `share` of elements differ at all
        Image,      // per channel |d| <= tolerance on at least 1 - share of pixels, <= limit everywhere
        Codes,      // |code difference| <= tolerance everywhere, on the stored codes of `storage` (StorageCode)
    };
    Kind kind = Kind::BitExact;
    double tolerance = 0;
    double share = 0;
    double limit = 0;
    StorageFormat storage = StorageFormat::Fp32;  // Codes: the format whose codes are compared

    // As the tables print it, e.g. "bit-exact", "|dT| <= 1e-05"; `symbol` names the compared quantity.
    std::string Text(std::string_view symbol) const;
    // The tolerance alone, as Text writes it ("2/255" for an image rule's 8-bit steps, "%g" otherwise).
    std::string ToleranceText() const;
};

// A setting of a stage's section that takes one of a few values (shade.resolution: 1, 2 or 4): its
// scene path, its values as a scene file writes them, in the order conform's matrix and accuracy's
// options walk them, and the scene's value written the same way. The stage's reader reads the setting
// under `path` against the same values.
struct ChoiceSetting {
    std::string_view path;
    std::vector<std::string> (*values)();
    std::string (*current)(const Scene& scene);
};

// The names of a NamedValue table (core/base/NamedValues.h), in its order, as a choice's values.
template <const auto& kTable>
std::vector<std::string> TableNames() {
    std::vector<std::string> names;
    for (const auto& entry : kTable) names.emplace_back(entry.name);
    return names;
}
inline std::vector<std::string> BooleanValues() { return {"false", "true"}; }
inline std::string BooleanText(bool value) { return value ? "true" : "false"; }

// How a run writes an HDR frame as PNG: each channel ReinhardToneMap(C, exposure) (core/math/March.h), or
// min(exposure C, 1) without the tone map, before the sRGB encoding. The EXR stays linear.
struct FrameToneMap {
    bool reinhard = true;
    float exposure = 1;
};

// What a renderer's accuracy measurement (harness/accuracy) hands it: the volume, the image to draw, the camera
// and step, `shadedT`, which shades T on the same backend when the renderer reads it (untimed), and
// `shadedSkyT`, which shades the sky light's T_sky likewise (read with the sky light on).
struct AccuracyRenderInputs {
    const Buffer* q = nullptr;
    Buffer* image = nullptr;
    const CameraSettings* camera = nullptr;
    uint32_t step = 0;
    std::function<Result<const Buffer*>()> shadedT;
    std::function<Result<const Buffer*>()> shadedSkyT;
};
// The renderer's call, made ready: `call` draws the image once (the measurement times it, repeatedly);
// `prepMs` is the untimed work the renderer's inputs took (shading T, the density stage's occupancy).
struct AccuracyRender {
    std::function<Status()> call;
    double prepMs = 0;
};

// What the harness knows of a renderer, as data: how its output is named and shown, and what it can do.
// results.json, the reports, `run`, `dump`, the accuracy evaluator, the sweep and the scene checks walk these.
struct RendererDescriptor {
    std::string_view fileStem;    // its frames: frame-<fileStem>-<camera>[-<backend>].exr and .png
    std::string_view rowLabel;    // the text report's rows of a camera's frames: "<rowLabel> <camera>"
    std::string_view resultsKey;  // results.json's per-camera frames of a backend
    std::string_view recordKey;   // a saved step's frame keeps the counters under it ("": in the frame itself)
    std::span<const FrameCounterField> counters;  // FrameRecord::counters, in order
    // The PNG's tone map in this scene; nullptr: the image is LDR, written as it is.
    FrameToneMap (*toneMap)(const Scene& scene) = nullptr;
    // Reads q periodically, so it runs with grid.tiling (clouds to the horizon).
    bool honoursTiling = false;
    // Lights with T shaded once, for the first step's sun (relighting), in this scene: shade then runs once.
    // nullptr: it reads T shaded at each step's sun, and cannot run beside a renderer that relights.
    bool (*relights)(const Scene& scene) = nullptr;
    // The scene fields that decide `relights` (a sweep's shade rows depend on them).
    std::span<const std::string_view> relightFields;
    // The scene fields whose variation a sweep measures its image for (images cost a reference render each),
    // besides the light terms' sections (core/pipeline/LightTerms.h kLightTermFields), which every renderer takes.
    std::span<const std::string_view> imageFields;
    // Its fields that the exact reference render does not read (a change leaves the reference as it is).
    std::span<const std::string_view> referenceIgnores;
    // Its call for one image on `backend`, for the accuracy measurement.
    Result<AccuracyRender> (*accuracyRender)(Backend& backend, const Scene& scene,
                                             const AccuracyRenderInputs& in) = nullptr;
    // The exact reference render (SPEC 11, reference/) is a ray march with this renderer's parameters; nullptr for
    // every renderer but the one whose parameters it takes.
    MarchParams (*referenceParams)(const Scene& scene, const CameraSettings& camera, uint32_t step) = nullptr;
    // Its settings as conform.json's coverage records them for this scene; nullptr: none.
    nlohmann::json (*conformOptions)(const Scene& scene) = nullptr;
    // conform's built-in matrix tries every phase function when it runs (as it does when shade runs).
    bool conformVariesPhase = false;
    // The settings the accuracy measurement tries besides the scene's own, each a list of overrides, and what they
    // are, for `accuracy`'s help ("" for none).
    std::vector<std::vector<SceneOverride>> (*accuracyVariants)(const Scene& scene) = nullptr;
    std::string_view accuracyVariantsHelp;
};

struct StageDescriptor {
    Stage stage;
    std::string_view section;  // the scene section of its settings ("" for none)
    // The scene file's top-level keys its reader owns ({} where it reads fields of a shared section only, as
    // render_splat does of `render`), and the reader: it reads them into `scene` after the shared sections (grid,
    // steps, stages, sun, lighting, lightning, phase, render) and the readers of the stages before it in CB_STAGES.
    // `grid` is the grid's size, nullptr where that was not read. nullptr: the stage has no settings.
    std::span<const std::string_view> sceneKeys;
    void (*readSettings)(const scene_io::Json& root, scene_io::Validator& check, const Extent3* grid,
                         Scene& scene) = nullptr;
    std::vector<Resource> reads;  // this step's values (a stage that advances the state reads its own)
    // Read when some enabled stage writes them, and not needed otherwise
    // (density's cover comes from cld with an automaton, from q without).
    std::vector<Resource> optionalReads;
    // Inputs whose previous step's value it also reads in this scene
    // (interpolating renderers); nullptr for none.
    std::vector<Resource> (*readsPrevious)(const Scene& scene) = nullptr;
    std::vector<Resource> writes;
    // Writes step t+1's values of its outputs from step t's (the automaton):
    // it runs after every stage that reads them, and its outputs are double-buffered.
    bool advancesState = false;
    // Runs on output steps only (render steps, or every step when dumping).
    bool outputStepsOnly = false;
    // Skipped when none of its inputs changed since it last ran.
    bool skipsUnchangedInputs = false;
    // The sun's direction it receives at the step (a host input), nullptr: it reads none. With
    // skipsUnchangedInputs, a change of that direction counts as a changed input.
    Vec3 (*sunAt)(const Scene& scene, uint32_t step) = nullptr;
    // True when its outputs depend on the step itself in this scene (a time
    // coordinate): it then runs every step despite skipsUnchangedInputs.
    // nullptr: never (a stage with no inputs and no time runs once).
    bool (*dependsOnStep)(const Scene& scene) = nullptr;
    // Time-slicing (SPEC 13): how many shares its work at `step` splits into
    // (core/pipeline/Backend.h SliceRange); nullptr: it runs whole, as one share.
    uint32_t (*shareCount)(const Scene& scene, uint32_t step) = nullptr;
    // A renderer (writes one image per camera): what the harness knows of it; nullptr for other stages.
    const RendererDescriptor* renderer = nullptr;
    std::string_view symbol;  // the compared quantity in rule texts ("R", "T", ...)
    // The comparison for this scene (shade's tolerance depends on its storage format).
    CompareRule (*rule)(const Scene& scene) = nullptr;
    std::string_view ruleNote;  // how the rule depends on the scene, for the help ("" if it does not)
    std::span<const ChoiceSetting> choices;  // its settings with a few values each
    // The scene fields its output depends on besides its input resources and kFieldsEveryStageReads (and, for a
    // renderer, the light terms' sections, kLightTermFields), as
    // dotted paths of the scene file; a section ("shade") stands for every field in it. A field it reads
    // must be listed (sweep measures a stage once per distinct setting of these and of its inputs'
    // writers' fields); one listed that it does not read only repeats rows.
    std::span<const std::string_view> sceneFields;
    // Reads Scene::needs, what the enabled renderers ask of it: its output then also depends on the fields that
    // decide those (the renderers' relightFields).
    bool readsRendererNeeds = false;
};

// The fields every stage's output depends on: the grid's extent, the number of steps (the last step is
// the one measured) and the stage list.
inline constexpr std::string_view kFieldsEveryStageReads[] = {"grid.size", "steps", "stages"};

// Whether a change of the field `path` changes the field `listed`: they are equal or one holds the other
// ("shade" and "shade.storage", "render.cameras" and "render").
constexpr bool FieldsOverlap(std::string_view path, std::string_view listed) {
    const std::string_view shorter = path.size() < listed.size() ? path : listed;
    const std::string_view longer = path.size() < listed.size() ? listed : path;
    return longer.starts_with(shorter) && (longer.size() == shorter.size() || longer[shorter.size()] == '.');
}

// Helpers the stages' descriptors share.
CompareRule BitExactRule(const Scene& scene);
// SPEC 8's image rule: per channel 2/255 on 99.9 % of pixels, 8/255 everywhere (the LDR renderers' rule).
CompareRule ImageRuleSpec8(const Scene& scene = {});
// The share count of a stage whose shares are the slices k (time-slicing; SliceRange): nz.
uint32_t SharesOfSlicesK(const Scene& scene, uint32_t step);

}  // namespace cb
