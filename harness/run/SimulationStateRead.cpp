// Reading a saved simulation state back: the manifest and the .npy buffers,
// each field checked (harness/run/SimulationState.h). The writer and the capture
// and restore are in harness/run/SimulationState.cpp.
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/base/PathPolicy.h"
#include "core/base/JsonDom.h"
#include "core/base/Npy.h"
#include "core/base/ShownText.h"
#include "harness/run/RunTransfer.h"
#include "harness/run/SimulationState.h"
#include "harness/run/SimulationStateDetail.h"

namespace cb {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace simulation_state_detail;

namespace {

std::optional<uint64_t> ParseHex64(const std::string& text) {
    if (text.empty() || text.size() > 16 || text.find_first_not_of("0123456789abcdef") != std::string::npos)
        return std::nullopt;
    return std::stoull(text, nullptr, 16);
}

std::string ShapeText(std::span<const uint64_t> shape) {
    std::string text = "[";
    for (size_t i = 0; i < shape.size(); ++i) text += (i ? ", " : "") + std::to_string(shape[i]);
    return text + "]";
}

// Reads the manifest's fields; the first failure is kept as "FILE: FIELD: reason".
class ManifestReader {
  public:
    explicit ManifestReader(std::string file) : mFile(std::move(file)) {}

    void Fail(const std::string& field, const std::string& reason) {
        if (!mError) mError = mFile + ": " + field + ": " + reason;
    }
    bool Failed() const { return mError.has_value(); }
    Error TakeError() const { return Error{*mError}; }

    const json* Find(const json& object, const std::string& key, const std::string& field) {
        if (!object.is_object() || !object.contains(key)) {
            Fail(field, "missing");
            return nullptr;
        }
        return &object[key];
    }
    std::optional<uint64_t> Unsigned(const json& v, const std::string& field, uint64_t max = UINT64_MAX) {
        if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0)) {
            Fail(field, "must be a non-negative integer, got " + v.dump());
            return std::nullopt;
        }
        const uint64_t n = v.get<uint64_t>();
        if (n > max) {
            Fail(field, "must be at most " + std::to_string(max) + ", got " + std::to_string(n));
            return std::nullopt;
        }
        return n;
    }
    std::optional<uint32_t> OptionalU32(const json& v, const std::string& field) {
        if (v.is_null()) return std::nullopt;
        return uint32_t(Unsigned(v, field, UINT32_MAX).value_or(0));
    }
    std::optional<double> Number(const json& v, const std::string& field) {
        if (!v.is_number()) {
            Fail(field, "must be a number, got " + v.dump());
            return std::nullopt;
        }
        return v.get<double>();
    }
    std::optional<std::string> Text(const json& v, const std::string& field) {
        if (!v.is_string()) {
            Fail(field, "must be a string, got " + v.dump());
            return std::nullopt;
        }
        return v.get<std::string>();
    }
    std::optional<bool> Bool(const json& v, const std::string& field) {
        if (!v.is_boolean()) {
            Fail(field, "must be true or false, got " + v.dump());
            return std::nullopt;
        }
        return v.get<bool>();
    }
    // An array of exactly `size` numbers (any size when 0).
    std::vector<double> Numbers(const json& v, const std::string& field, size_t size) {
        if (!v.is_array() || (size && v.size() != size)) {
            Fail(field, "must be an array of " + std::to_string(size) + " numbers, got " + v.dump());
            return std::vector<double>(size, 0.0);
        }
        std::vector<double> out;
        for (size_t i = 0; i < v.size(); ++i)
            out.push_back(Number(v[i], field + "[" + std::to_string(i) + "]").value_or(0));
        return out;
    }
    const json* Array(const json& object, const std::string& key, const std::string& field) {
        const json* v = Find(object, key, field);
        if (v && !v->is_array()) {
            Fail(field, "must be an array");
            return nullptr;
        }
        return v;
    }
    std::vector<RasterEllipsoid> Raster(const json& object, const std::string& key) {
        std::vector<RasterEllipsoid> list;
        const json* a = Array(object, key, key);
        if (!a) return list;
        for (size_t i = 0; i < a->size(); ++i) {
            const std::vector<double> v = Numbers((*a)[i], key + "[" + std::to_string(i) + "]", 8);
            RasterEllipsoid e{};
            for (int k = 0; k < 3; ++k) {
                e.center[k] = float(v[size_t(k)]);
                e.semiAxes[k] = float(v[size_t(k) + 3]);
            }
            e.cosYaw = float(v[6]);
            e.sinYaw = float(v[7]);
            list.push_back(e);
        }
        return list;
    }

  private:
    std::string mFile;
    std::optional<std::string> mError;
};

std::optional<Resource> ResourceByName(std::string_view name) {
    for (Resource r : kAllResources)
        if (ResourceName(r) == name) return r;
    return std::nullopt;
}

std::optional<BufferRole> RoleByName(std::string_view name) {
    for (BufferRole role : {BufferRole::Current, BufferRole::Next, BufferRole::Previous, BufferRole::Pending})
        if (BufferRoleName(role) == name) return role;
    return std::nullopt;
}

}  // namespace

Result<SimulationState> ReadSimulationState(const std::string& dir, const Scene& scene, std::string_view sceneHash) {
    const std::string manifestPath = (fs::path(dir) / std::string(kSimulationStateManifest)).string();
    json m;
    {
        Result<std::string> text = ReadInputBeneath(dir, std::string(kSimulationStateManifest), kDocumentInput);
        if (!text) return std::unexpected(text.error());
        scene_io::JsonDocument doc = scene_io::ParseJsonDocument(*text);
        if (doc.failure || !doc.root.is_object())
            return MakeError(manifestPath + ": not a JSON object (a damaged file?)");
        if (!doc.duplicates.empty())
            return MakeError(manifestPath + ": " + ShownText(doc.duplicates.front(), false, 200) + ": duplicate key");
        m = std::move(doc.root);
    }
    ManifestReader read(manifestPath);
    SimulationState s;
    // Format and version first: nothing else is read from a file of another format.
    const json* format = read.Find(m, "format", "format");
    if (format && *format != json(std::string(kSimulationStateFormat)))
        read.Fail("format", "must be \"" + std::string(kSimulationStateFormat) + "\", got " + format->dump());
    if (read.Failed()) return std::unexpected(read.TakeError());
    if (const json* v = read.Find(m, "version", "version"); v && *v != json(kSimulationStateVersion))
        read.Fail("version",
                  "this build reads version " + std::to_string(kSimulationStateVersion) + ", got " + v->dump());
    if (read.Failed()) return std::unexpected(read.TakeError());
    if (const json* sc = read.Find(m, "scene", "scene")) {
        if (const json* n = read.Find(*sc, "name", "scene.name"))
            s.sceneName = read.Text(*n, "scene.name").value_or("");
        if (const json* h = read.Find(*sc, "settings_hash", "scene.settings_hash"))
            s.sceneHash = read.Text(*h, "scene.settings_hash").value_or("");
    }
    if (!read.Failed() && s.sceneName != scene.name)
        read.Fail("scene.name", "saved from scene '" + s.sceneName + "', not '" + scene.name + "'");
    if (!read.Failed() && s.sceneHash != sceneHash)
        read.Fail(
            "scene.settings_hash",
            "saved with other scene settings (" + s.sceneHash + "; this run's: " + std::string(sceneHash) +
                "): resume with the scene file and --set options the state was saved with (only steps may differ)");
    if (const json* v = read.Find(m, "step", "step"))
        s.step = uint32_t(read.Unsigned(*v, "step", UINT32_MAX).value_or(0));
    if (!read.Failed() && s.step >= scene.steps)
        read.Fail("step", "the state is at step " + std::to_string(s.step) + ", so the resumed run needs steps > " +
                              std::to_string(s.step) + " (got " + std::to_string(scene.steps) + ")");
    if (read.Failed()) return std::unexpected(read.TakeError());

    // The host state.
    if (const json* e = read.Find(m, "ellipsoids", "ellipsoids")) {
        if (const json* rng = read.Find(*e, "rng", "ellipsoids.rng")) {
            for (auto [key, out] : {std::pair{"state", &s.rngState}, std::pair{"increment", &s.rngIncrement}}) {
                const std::string field = std::string("ellipsoids.rng.") + key;
                if (const json* v = read.Find(*rng, key, field)) {
                    auto n = v->is_string() ? ParseHex64(v->get<std::string>()) : std::nullopt;
                    if (n)
                        *out = *n;
                    else
                        read.Fail(field, "must be 1 to 16 lowercase hex digits, got " + v->dump());
                }
            }
        }
        // Absent from states saved before placed ellipsoids (whose scenes had none to place): 0.
        if (e->is_object() && e->contains("list_step"))
            s.listStep = uint32_t(read.Unsigned((*e)["list_step"], "ellipsoids.list_step", UINT32_MAX).value_or(0));
        if (const json* items = read.Array(*e, "items", "ellipsoids.items")) {
            for (size_t i = 0; i < items->size(); ++i) {
                const json& it = (*items)[i];
                const std::string field = "ellipsoids.items[" + std::to_string(i) + "]";
                Ellipsoid el{};
                if (const json* c = read.Find(it, "center", field + ".center")) {
                    const auto v = read.Numbers(*c, field + ".center", 3);
                    std::copy(v.begin(), v.end(), el.center);
                }
                if (const json* a = read.Find(it, "semi_axes", field + ".semi_axes")) {
                    const auto v = read.Numbers(*a, field + ".semi_axes", 3);
                    std::copy(v.begin(), v.end(), el.semiAxes);
                }
                if (const json* y = read.Find(it, "yaw", field + ".yaw"))
                    el.yaw = read.Number(*y, field + ".yaw").value_or(0);
                if (const json* a = read.Find(it, "age", field + ".age"))
                    el.age = uint32_t(read.Unsigned(*a, field + ".age", UINT32_MAX).value_or(0));
                if (const json* l = read.Find(it, "lifetime", field + ".lifetime"))
                    el.lifetime = uint32_t(read.Unsigned(*l, field + ".lifetime", UINT32_MAX).value_or(0));
                s.ellipsoids.push_back(el);
            }
        }
    }
    s.raster = read.Raster(m, "raster");
    s.rasterAhead = read.Raster(m, "raster_ahead");
    if (const json* v = read.Find(m, "last_rendered_step", "last_rendered_step"))
        s.lastRendered = read.OptionalU32(*v, "last_rendered_step");
    // Absent from states saved before frames were numbered: none drawn.
    if (m.is_object() && m.contains("frames_drawn"))
        s.framesDrawn = uint32_t(read.Unsigned(m["frames_drawn"], "frames_drawn", UINT32_MAX).value_or(0));
    if (const json* v = read.Find(m, "last_covered_columns", "last_covered_columns"))
        s.lastCoveredColumns = read.OptionalU32(*v, "last_covered_columns");
    if (const json* res = read.Find(m, "resources", "resources")) {
        for (Resource r : kAllResources) {
            const std::string field = "resources." + std::string(ResourceName(r));
            const json* entry = read.Find(*res, std::string(ResourceName(r)), field);
            if (!entry) break;
            if (const json* v = read.Find(*entry, "version", field + ".version"))
                s.versions[size_t(r)] = read.Unsigned(*v, field + ".version").value_or(0);
            if (const json* v = read.Find(*entry, "ahead", field + ".ahead"))
                s.ahead[size_t(r)] = read.Bool(*v, field + ".ahead").value_or(false);
            if (const json* v = read.Find(*entry, "previous_is_current", field + ".previous_is_current"))
                s.previousIsCurrent[size_t(r)] = read.Bool(*v, field + ".previous_is_current").value_or(false);
        }
    }
    if (const json* inputs = read.Find(m, "inputs_at_last_run", "inputs_at_last_run")) {
        if (!inputs->is_object()) read.Fail("inputs_at_last_run", "must be an object");
        for (auto it = inputs->begin(); inputs->is_object() && it != inputs->end(); ++it) {
            const std::string field = "inputs_at_last_run." + it.key();
            const std::optional<Stage> stage = ParseStage(it.key());
            if (!stage) {
                read.Fail(field, "not a stage");
                break;
            }
            if (!it->is_array()) {
                read.Fail(field, "must be an array of integers");
                break;
            }
            std::vector<uint64_t> versions;
            for (size_t i = 0; i < it->size(); ++i)
                versions.push_back(read.Unsigned((*it)[i], field + "[" + std::to_string(i) + "]").value_or(0));
            s.inputsAtLastRun[size_t(*stage)] = std::move(versions);
        }
    }
    if (const json* ts = read.Find(m, "time_slicing", "time_slicing")) {
        if (const json* v = read.Find(*ts, "ahead_computed", "time_slicing.ahead_computed"))
            s.aheadComputed = read.Bool(*v, "time_slicing.ahead_computed").value_or(false);
        if (const json* v = read.Find(*ts, "advance_owed", "time_slicing.advance_owed"))
            s.advanceOwed = read.Bool(*v, "time_slicing.advance_owed").value_or(false);
        if (const json* v = read.Find(*ts, "ahead_record", "time_slicing.ahead_record")) {
            try {
                s.aheadRecord = transfer::StepFromJson(*v);
            } catch (const std::exception& e) {
                read.Fail("time_slicing.ahead_record", std::string("not a step record: ") + e.what());
            }
        }
    }
    if ((s.aheadComputed || s.advanceOwed) && scene.render.slicesPerFrame == 0)
        read.Fail("time_slicing", "the state was saved time-sliced; this scene is not");
    if (read.Failed()) return std::unexpected(read.TakeError());

    // The buffers: exactly those the scene's simulation holds and the state needs, each whole and as listed.
    struct Expected {
        PlannedBuffer planned;
        bool listed = false;
    };
    std::vector<Expected> expected;
    for (const PlannedBuffer& p : PlanBuffers(scene)) {
        const bool thirdSet = p.role == BufferRole::Next || p.role == BufferRole::Pending;
        const bool needed = p.role == BufferRole::Current || (thirdSet && s.ahead[size_t(p.resource)]);
        if (needed) expected.push_back({p});
    }
    const json* list = read.Array(m, "buffers", "buffers");
    if (read.Failed()) return std::unexpected(read.TakeError());
    for (size_t i = 0; i < list->size() && !read.Failed(); ++i) {
        const json& b = (*list)[i];
        const std::string field = "buffers[" + std::to_string(i) + "]";
        std::string resourceName, roleName, fileName, hash;
        uint32_t camera = 0;
        if (const json* v = read.Find(b, "resource", field + ".resource"))
            resourceName = read.Text(*v, field + ".resource").value_or("");
        if (const json* v = read.Find(b, "role", field + ".role"))
            roleName = read.Text(*v, field + ".role").value_or("");
        if (const json* v = read.Find(b, "camera", field + ".camera"))
            camera = uint32_t(read.Unsigned(*v, field + ".camera", UINT32_MAX).value_or(0));
        if (const json* v = read.Find(b, "file", field + ".file"))
            fileName = read.Text(*v, field + ".file").value_or("");
        if (const json* v = read.Find(b, "fnv1a64", field + ".fnv1a64"))
            hash = read.Text(*v, field + ".fnv1a64").value_or("");
        if (read.Failed()) break;
        const std::optional<Resource> resource = ResourceByName(resourceName);
        const std::optional<BufferRole> role = RoleByName(roleName);
        if (!resource) {
            read.Fail(field + ".resource", "not a resource: '" + resourceName + "'");
            break;
        }
        if (!role) {
            read.Fail(field + ".role", "not a buffer role: '" + roleName + "'");
            break;
        }
        if (fileName != FileOf(*resource, *role, camera)) {
            read.Fail(field + ".file", "must be '" + FileOf(*resource, *role, camera) + "', got '" + fileName + "'");
            break;
        }
        Expected* match = nullptr;
        for (Expected& e : expected)
            if (e.planned.resource == *resource && e.planned.role == *role && e.planned.camera == camera) match = &e;
        if (!match) {
            read.Fail(field, fileName + ": the scene's simulation holds no such buffer (or needs none now)");
            break;
        }
        if (match->listed) {
            read.Fail(field, fileName + " listed twice");
            break;
        }
        match->listed = true;
        const PlannedBuffer& p = match->planned;
        const std::string path = (fs::path(dir) / fileName).string();
        const uint64_t bytes = p.extent.Count() * 4;  // the widest dtype: a wrong one is named as such below
        // Beneath the state's folder (core/base/PathPolicy.h): a link out of it is refused.
        Result<OpenedInput> opened = OpenInputBeneath(dir, fileName, kArrayInput);
        if (!opened) return std::unexpected(opened.error());
        // A header is at most a few hundred bytes; a bigger file is not this buffer (nor read whole into memory).
        if (opened->Bytes() > bytes + 4096)
            return MakeError(path + ": size: " + std::to_string(opened->Bytes()) + " bytes, more than a " +
                             ShapeText(ShapeOf(p.extent)) + " array takes");
        Result<std::string> file = ReadOpenedInput(*opened, path, kArrayInput);
        if (!file) return std::unexpected(file.error());
        auto npy = ParseNpy(*file, path);
        if (!npy) {
            std::string reason = npy.error().message;
            if (reason.starts_with(path + ": ")) reason = reason.substr(path.size() + 2);
            return MakeError(path + ": npy: " + reason);
        }
        const NpyType type = p.format == BufferFormat::F32 ? NpyType::F32 : NpyType::U8;
        if (npy->type != type)
            return MakeError(path + ": dtype: expected " + std::string(type == NpyType::F32 ? "<f4" : "|u1") + " for " +
                             std::string(FormatName(p.format)) + " data");
        if (npy->shape != ShapeOf(p.extent))
            return MakeError(path + ": shape: expected " + ShapeText(ShapeOf(p.extent)) + " (the scene's " +
                             std::string(ResourceName(p.resource)) + "), got " + ShapeText(npy->shape));
        if (Hex64(Fnv1a64(npy->data)) != hash)
            return MakeError(path + ": fnv1a64: the data do not match the manifest's hash (a changed or damaged file)");
        s.buffers.push_back({p.resource, p.role, p.camera, p.format, p.extent, std::move(npy->data)});
    }
    if (read.Failed()) return std::unexpected(read.TakeError());
    for (const Expected& e : expected)
        if (!e.listed) {
            read.Fail("buffers", "no entry for " + FileOf(e.planned.resource, e.planned.role, e.planned.camera));
            break;
        }
    if (read.Failed()) return std::unexpected(read.TakeError());
    return s;
}

}  // namespace cb
