// Scene loading: JSON text -> overrides -> validation -> Scene. Every check
// reports into one list of "label: field: reason" lines, so a user sees all
// problems of a file at once. The format is documented in docs/scenes.md.
#include "core/Scene.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <string_view>
#include <utility>

#include "core/JsonDom.h"
#include "core/SceneMemory.h"

namespace cb {
namespace {

using scene_io::PhysicalMemoryBytes;

using scene_io::IndexField;
using scene_io::JoinField;
using scene_io::Json;
using scene_io::JsonDom;

constexpr int64_t kU32Max = std::numeric_limits<uint32_t>::max();
constexpr int64_t kI32Min = std::numeric_limits<int32_t>::min();
constexpr int64_t kI32Max = std::numeric_limits<int32_t>::max();
constexpr int64_t kSeed64Max = int64_t(1) << 53;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr size_t kMaxShownChars = 60;  // longest value text quoted in an error

constexpr Stage kDefaultStages[] = {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density};

// ---- Small formatting helpers ---------------------------------------------------------------------------------

// Shortest text that reads back as the same double ("0.35", "400", "100000", "1e+20", "inf").
std::string FormatNumber(double value) {
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char buffer[64];
    // Whole numbers below 1e15 are written out ("100000", not the shorter "1e+05").
    const bool whole = value == std::floor(value) && std::fabs(value) < 1e15;
    auto [end, ec] = whole ? std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::fixed)
                           : std::to_chars(buffer, buffer + sizeof(buffer), value);
    if (ec != std::errc()) return "?";
    return std::string(buffer, end);
}

// A JSON value as it appears in an error: strings quoted, long values cut short.
std::string Describe(const Json& value) {
    std::string text;
    if (value.is_number_float()) {
        text = FormatNumber(value.get<double>());
    } else {
        text = value.dump(-1, ' ', false, Json::error_handler_t::replace);
    }
    if (text.size() > kMaxShownChars) text = text.substr(0, kMaxShownChars - 3) + "...";
    return text;
}

std::string Quote(std::string_view text) {
    // Built with append rather than operator+: GCC 12 raises a false -Wrestrict
    // on "literal" + std::string (GCC bug 105651).
    std::string quoted;
    quoted.reserve(text.size() + 2);
    quoted.append(1, '"').append(text).append(1, '"');
    return quoted;
}

// Case-insensitive edit distance, for "did you mean" suggestions.
size_t EditDistance(std::string_view a, std::string_view b) {
    auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; };
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t above = row[j];
            const size_t substitute = diagonal + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1);
            row[j] = std::min({above + 1, row[j - 1] + 1, substitute});
            diagonal = above;
        }
    }
    return row[b.size()];
}

// " (did you mean "x"?)" when one known name is close to `name`, else "".
std::string Suggestion(std::string_view name, std::span<const std::string_view> known) {
    // A name that one known name starts with ("fov" for "fov_deg") is a shortening, not a misspelling.
    if (name.size() >= 3) {
        std::string_view extended;
        size_t matches = 0;
        for (std::string_view candidate : known) {
            if (candidate.size() > name.size() && EditDistance(candidate.substr(0, name.size()), name) == 0) {
                extended = candidate;
                ++matches;
            }
        }
        if (matches == 1) return " (did you mean " + Quote(extended) + "?)";
    }
    std::string_view best;
    size_t bestDistance = std::numeric_limits<size_t>::max();
    for (std::string_view candidate : known) {
        const size_t d = EditDistance(name, candidate);
        if (d < bestDistance) {
            bestDistance = d;
            best = candidate;
        }
    }
    // Close means at most two edits, and fewer edits than the shorter name has letters.
    if (best.empty() || bestDistance > 2 || bestDistance >= std::min(name.size(), best.size())) return "";
    return " (did you mean " + Quote(best) + "?)";
}

std::string FormatGiB(uint64_t bytes) {
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "%.1f", double(bytes) / double(uint64_t(1) << 30));
    return buffer;
}

// ---- Validation ----------------------------------------------------------------------------------------------

// Collects error lines "label: field: reason" and reads typed values out of the document.
class Validator {
  public:
    explicit Validator(std::string label) : mLabel(std::move(label)) {}

    void MarkOverridden(std::string path) { mOverridden.push_back(std::move(path)); }

    // Adds one error line; fields under an override (--set, --vary) get " (set on the command line)".
    void Fail(std::string_view field, std::string_view reason) {
        std::string line = mLabel + ": " + std::string(field) + ": " + std::string(reason);
        if (IsOverridden(field)) line += " (set on the command line)";
        mErrors.push_back(std::move(line));
    }

    // An error with no field (malformed JSON, unreadable file).
    void FailWhole(std::string_view reason) { mErrors.push_back(mLabel + ": " + std::string(reason)); }

    size_t ErrorCount() const { return mErrors.size(); }

    std::string Message() const {
        std::string message;
        for (const std::string& line : mErrors) {
            if (!message.empty()) message += '\n';
            message += line;
        }
        return message;
    }

    // Reports every key of `object` that is not in `known`.
    void CheckKeys(const Json& object, std::string_view field, std::span<const std::string_view> known) {
        for (const auto& [key, value] : object.items()) {
            if (std::find(known.begin(), known.end(), key) == known.end())
                Fail(JoinField(field, key), "unknown field" + Suggestion(key, known));
        }
    }

    // The member `key` of `object`, or nullptr when absent.
    static const Json* Find(const Json& object, std::string_view key) {
        auto it = object.find(std::string(key));
        return it == object.end() ? nullptr : &*it;
    }

    // The object section `key` of `parent` after checking its type and keys; nullptr when absent or wrong.
    const Json* Section(const Json& parent, std::string_view parentField, std::string_view key,
                        std::span<const std::string_view> known) {
        const Json* section = Find(parent, key);
        if (!section) return nullptr;
        const std::string field = JoinField(parentField, key);
        if (!section->is_object()) {
            Fail(field, "expected an object, got " + Describe(*section));
            return nullptr;
        }
        CheckKeys(*section, field, known);
        return section;
    }

    // A whole number in [lo, hi]; integral floats such as 1e6 are accepted.
    std::optional<int64_t> Integer(const Json& value, std::string_view field, int64_t lo, int64_t hi) {
        int64_t result = 0;
        bool inRange = true;
        if (value.is_number_unsigned()) {
            const uint64_t u = value.get<uint64_t>();
            inRange = u <= uint64_t(std::numeric_limits<int64_t>::max());
            result = inRange ? int64_t(u) : 0;
        } else if (value.is_number_integer()) {
            result = value.get<int64_t>();
        } else if (value.is_number_float()) {
            const double d = value.get<double>();
            if (!std::isfinite(d)) {
                Fail(field, "must be a finite integer, got " + Describe(value));
                return std::nullopt;
            }
            if (d != std::floor(d)) {
                Fail(field, "expected an integer, got " + Describe(value));
                return std::nullopt;
            }
            inRange = d >= -9.2e18 && d <= 9.2e18;
            result = inRange ? int64_t(d) : 0;
        } else {
            Fail(field, "expected an integer, got " + Describe(value));
            return std::nullopt;
        }
        if (!inRange || result < lo || result > hi) {
            Fail(field, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                            Describe(value));
            return std::nullopt;
        }
        return result;
    }

    // Allowed interval of a number; infinite bounds mean "no bound", open bounds exclude the value.
    struct Range {
        double lo = -kInf;
        bool loOpen = false;
        double hi = kInf;
        bool hiOpen = false;
    };

    // A finite number inside `range`.
    std::optional<double> Number(const Json& value, std::string_view field, Range range) {
        if (!value.is_number()) {
            Fail(field, "expected a number, got " + Describe(value));
            return std::nullopt;
        }
        const double d = value.get<double>();
        if (!std::isfinite(d)) {
            Fail(field, "must be a finite number, got " + Describe(value));
            return std::nullopt;
        }
        const bool loOk = range.loOpen ? d > range.lo : d >= range.lo;
        const bool hiOk = range.hiOpen ? d < range.hi : d <= range.hi;
        if (loOk && hiOk) return d;
        std::string reason;
        if (std::isinf(range.hi)) {
            reason = std::string("must be ") + (range.loOpen ? "> " : ">= ") + FormatNumber(range.lo);
        } else if (std::isinf(range.lo)) {
            reason = std::string("must be ") + (range.hiOpen ? "< " : "<= ") + FormatNumber(range.hi);
        } else {
            reason = std::string("must be in ") + (range.loOpen ? "(" : "[") + FormatNumber(range.lo) + ", " +
                     FormatNumber(range.hi) + (range.hiOpen ? ")" : "]");
        }
        Fail(field, reason + ", got " + Describe(value));
        return std::nullopt;
    }

    std::optional<std::string> String(const Json& value, std::string_view field) {
        if (!value.is_string()) {
            Fail(field, "expected a string, got " + Describe(value));
            return std::nullopt;
        }
        return value.get<std::string>();
    }

    // A JSON true or false; numbers and strings such as 1 or "true" are refused.
    std::optional<bool> Boolean(const Json& value, std::string_view field) {
        if (!value.is_boolean()) {
            Fail(field, "expected true or false, got " + Describe(value));
            return std::nullopt;
        }
        return value.get<bool>();
    }

    // One of a fixed set of strings (case-sensitive), mapped to its value.
    template <typename T, size_t N>
    std::optional<T> Choice(const Json& value, std::string_view field,
                            const std::pair<std::string_view, T> (&options)[N]) {
        if (value.is_string()) {
            const std::string& text = value.get_ref<const std::string&>();
            for (const auto& [name, result] : options)
                if (name == text) return result;
        }
        std::array<std::string_view, N> names;
        std::string list;
        for (size_t i = 0; i < N; ++i) {
            names[i] = options[i].first;
            list += (i == 0 ? "" : ", ") + Quote(options[i].first);
        }
        std::string reason = "must be one of " + list + ", got " + Describe(value);
        if (value.is_string()) reason += Suggestion(value.get_ref<const std::string&>(), names);
        Fail(field, reason);
        return std::nullopt;
    }

    // A whole number from a short list; `allowedText` reads e.g. "1, 2 or 4".
    std::optional<int64_t> IntegerChoice(const Json& value, std::string_view field, std::span<const int64_t> allowed,
                                         std::string_view allowedText) {
        // Whole numbers beyond int64 are simply not in the list (rather than outside int64's range).
        const bool huge = (value.is_number_unsigned() &&
                           value.get<uint64_t>() > uint64_t(std::numeric_limits<int64_t>::max())) ||
                          (value.is_number_float() && std::isfinite(value.get<double>()) &&
                           value.get<double>() == std::floor(value.get<double>()) &&
                           std::fabs(value.get<double>()) > 9.2e18);
        std::optional<int64_t> n;
        if (!huge) {
            n = Integer(value, field, std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max());
            if (!n) return std::nullopt;  // not an integer: already reported
            if (std::find(allowed.begin(), allowed.end(), *n) != allowed.end()) return n;
        }
        Fail(field, "must be " + std::string(allowedText) + ", got " + Describe(value));
        return std::nullopt;
    }

    // An array of exactly N numbers, each inside `range`.
    template <size_t N>
    std::optional<std::array<double, N>> Numbers(const Json& value, std::string_view field, Range range) {
        if (!value.is_array() || value.size() != N) {
            Fail(field, "expected an array of " + std::to_string(N) + " numbers, got " + Describe(value));
            return std::nullopt;
        }
        std::array<double, N> result{};
        bool ok = true;
        for (size_t i = 0; i < N; ++i) {
            auto d = Number(value[i], IndexField(field, i), range);
            if (d) result[i] = *d;
            ok = ok && d.has_value();
        }
        return ok ? std::optional(result) : std::nullopt;
    }

    // An array of exactly N integers, each in [lo, hi].
    template <size_t N>
    std::optional<std::array<int64_t, N>> Integers(const Json& value, std::string_view field, int64_t lo,
                                                   int64_t hi) {
        if (!value.is_array() || value.size() != N) {
            Fail(field, "expected an array of " + std::to_string(N) + " integers, got " + Describe(value));
            return std::nullopt;
        }
        std::array<int64_t, N> result{};
        bool ok = true;
        for (size_t i = 0; i < N; ++i) {
            auto n = Integer(value[i], IndexField(field, i), lo, hi);
            if (n) result[i] = *n;
            ok = ok && n.has_value();
        }
        return ok ? std::optional(result) : std::nullopt;
    }

  private:
    // True when `field` is an overridden path or lies under one.
    bool IsOverridden(std::string_view field) const {
        for (const std::string& path : mOverridden) {
            if (!field.starts_with(path)) continue;
            if (field.size() == path.size() || field[path.size()] == '.' || field[path.size()] == '[') return true;
        }
        return false;
    }

    std::string mLabel;
    std::vector<std::string> mErrors;
    std::vector<std::string> mOverridden;
};

using Range = Validator::Range;
constexpr Range kFinite{};
constexpr Range kPositive{.lo = 0, .loOpen = true};
constexpr Range kNonNegative{.lo = 0};
constexpr Range kProbability{.lo = 0, .hi = 1};

// Applies one --set to the document. Missing objects along the path are created.
void ApplyOverride(Json& root, const SceneOverride& item, Validator& check) {
    const std::string where = "--set " + item.path;
    std::vector<std::string> keys;
    for (size_t start = 0;;) {
        const size_t dot = item.path.find('.', start);
        keys.push_back(item.path.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
        if (dot == std::string::npos) break;
        start = dot + 1;
    }
    for (const std::string& key : keys) {
        if (key.empty()) {
            check.Fail(where, "expected a dotted field path such as ca.seed");
            return;
        }
    }

    // The value is JSON text; anything that does not parse is taken as a string.
    JsonDom parsed = scene_io::ParseJsonDom(item.value);
    if (parsed.failure && parsed.failure->IsNumberOverflow()) {
        // Number overflow (1e999) is a number, not a bare word: refuse it rather than take it as a string.
        check.MarkOverridden(item.path);
        check.Fail(item.path, "the number " + parsed.failure->token + " is out of range (not finite)");
        return;
    }
    Json value = parsed.failure ? Json(item.value) : std::move(parsed.root);

    Json* node = &root;
    std::string prefix;
    for (size_t i = 0; i + 1 < keys.size(); ++i) {
        prefix = JoinField(prefix, keys[i]);
        auto it = node->find(keys[i]);
        if (it == node->end()) {
            node = &((*node)[keys[i]] = Json::object());
        } else if (it->is_object()) {
            node = &*it;
        } else {
            check.Fail(where, Quote(prefix) + " is not an object");
            return;
        }
    }
    (*node)[keys.back()] = std::move(value);
    check.MarkOverridden(item.path);
    if (!parsed.failure) {
        for (const std::string& duplicate : parsed.duplicates)
            check.Fail(JoinField(item.path, duplicate), "duplicate field");
    }
}

// ---- The sections ---------------------------------------------------------------------------------------------

constexpr std::string_view kTopKeys[] = {"name",  "description", "grid",   "steps",   "warmup_steps", "stages",
                                         "ca",    "ellipsoids",  "smooth", "density", "sun",          "lighting",
                                         "phase", "shade",       "shadow", "render"};
constexpr std::string_view kGridKeys[] = {"size", "voxel_size", "origin"};
constexpr std::string_view kCaKeys[] = {"seed", "hum0", "act0", "p_ext", "p_hum", "p_act", "wind_shift"};
constexpr std::string_view kEllipsoidKeys[] = {
    "seed",          "target_count",      "density_adaption", "size_mean", "size_variance", "lifetime_mean",
    "lifetime_variance", "shrink_steps", "margin",           "height_range", "wind",        "jitter"};
constexpr std::string_view kWindGridKeys[] = {"grid", "vectors"};
constexpr std::string_view kSmoothKeys[] = {"radius"};
constexpr std::string_view kDensityKeys[] = {"tile", "band"};
constexpr std::string_view kSunKeys[] = {"elevation_deg", "azimuth_deg", "color", "intensity"};
constexpr std::string_view kLightingKeys[] = {"ambient", "background"};
constexpr std::string_view kPhaseKeys[] = {"function", "g"};
constexpr std::string_view kShadeKeys[] = {"attenuation", "sigma",   "thesis_ar", "filter",
                                           "resolution",  "storage", "scattering"};
constexpr std::string_view kScatteringKeys[] = {"enabled", "albedo", "solid_angle"};
constexpr std::string_view kShadowKeys[] = {"form", "kappa"};
constexpr std::string_view kRenderKeys[] = {"width", "height",  "q_min",    "splat_scale", "opacity",
                                            "alpha", "culling", "skipping", "every_steps", "cameras"};
constexpr std::string_view kCameraKeys[] = {"name", "eye", "target", "up", "fov_deg", "near", "far"};

constexpr std::pair<std::string_view, PhaseKind> kPhaseKinds[] = {
    {"none", PhaseKind::None},
    {"henyey-greenstein", PhaseKind::HenyeyGreenstein},
    {"cornette-shanks", PhaseKind::CornetteShanks}};
constexpr std::pair<std::string_view, AttenuationKind> kAttenuationKinds[] = {{"beer", AttenuationKind::Beer},
                                                                              {"thesis", AttenuationKind::Thesis}};
constexpr std::pair<std::string_view, SampleFilter> kFilters[] = {{"bilinear", SampleFilter::Bilinear},
                                                                  {"nearest", SampleFilter::Nearest}};
constexpr std::pair<std::string_view, StorageFormat> kStorageFormats[] = {
    {"fp32", StorageFormat::Fp32}, {"fp16", StorageFormat::Fp16}, {"unorm8", StorageFormat::Unorm8}};
constexpr int64_t kShadeResolutions[] = {1, 2, 4};
constexpr int64_t kMaxImageEdge = 16384;

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
        if (auto d = check.Number(*v, "grid.voxel_size", kPositive)) grid.voxelSize = *d;
    }
    if (const Json* v = Validator::Find(*section, "origin")) {
        if (auto a = check.Numbers<3>(*v, "grid.origin", kFinite)) grid.origin = *a;
    }
    return sizeOk;
}

void ReadStages(const Json& root, Validator& check, StageSet& stages) {
    const Json* list = Validator::Find(root, "stages");
    if (!list) {
        for (Stage stage : kDefaultStages) stages.Add(stage);
        return;
    }
    if (!list->is_array()) {
        check.Fail("stages", "expected an array of stage names, got " + Describe(*list));
        return;
    }
    if (list->empty()) {
        check.Fail("stages", "must name at least one stage, got []");
        return;
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
    // Dependencies are checked only on a clean list, so one typo does not cascade.
    if (!allOk) return;
    constexpr std::pair<Stage, Stage> kNeeds[] = {
        {Stage::Ca, Stage::Region},         {Stage::Smooth, Stage::Ca},          {Stage::Density, Stage::Smooth},
        {Stage::Shade, Stage::Smooth},      {Stage::Shadow, Stage::Density},     {Stage::RenderSplat, Stage::Shade},
        {Stage::RenderSplat, Stage::Density}};
    for (auto [stage, needed] : kNeeds) {
        if (stages.Has(stage) && !stages.Has(needed))
            check.Fail("stages", Quote(StageName(stage)) + " needs " + Quote(StageName(needed)));
    }
}

// Reads ca; the wind shift stays as written (one pair or nz pairs) until the size checks passed.
void ReadCa(const Json& root, Validator& check, std::optional<uint32_t> nz, CaSettings& ca) {
    const Json* section = check.Section(root, "", "ca", kCaKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "seed")) {
        if (auto n = check.Integer(*v, "ca.seed", 0, kU32Max)) ca.seed = uint32_t(*n);
    }
    const std::pair<std::string_view, double*> probabilities[] = {
        {"hum0", &ca.hum0}, {"act0", &ca.act0}, {"p_ext", &ca.pExt}, {"p_hum", &ca.pHum}, {"p_act", &ca.pAct}};
    for (auto [key, target] : probabilities) {
        if (const Json* v = Validator::Find(*section, key)) {
            if (auto d = check.Number(*v, JoinField("ca", key), kProbability)) *target = *d;
        }
    }
    const Json* shifts = Validator::Find(*section, "wind_shift");
    if (!shifts) return;
    if (!shifts->is_array()) {
        check.Fail("ca.wind_shift", "expected an array of [sx, sy] integer pairs, got " + Describe(*shifts));
        return;
    }
    if (nz && shifts->size() != 0 && shifts->size() != 1 && shifts->size() != *nz) {
        check.Fail("ca.wind_shift", "expected 1 pair (for every slice) or nz = " + std::to_string(*nz) +
                                        " pairs, got " + std::to_string(shifts->size()));
    }
    ca.windShift.clear();
    for (size_t i = 0; i < shifts->size(); ++i) {
        if (auto pair = check.Integers<2>((*shifts)[i], IndexField("ca.wind_shift", i), kI32Min, kI32Max))
            ca.windShift.push_back(SliceShift{int32_t((*pair)[0]), int32_t((*pair)[1])});
    }
}

void ReadWind(const Json& value, Validator& check, EllipsoidWind& wind) {
    const std::string field = "ellipsoids.wind";
    if (value.is_array()) {
        if (auto v = check.Numbers<2>(value, field, kFinite)) wind.vector = *v;
        return;
    }
    if (!value.is_object()) {
        check.Fail(field, "expected [wx, wy] or {\"grid\": [gx, gy], \"vectors\": [[wx, wy], ...]}, got " +
                              Describe(value));
        return;
    }
    check.CheckKeys(value, field, kWindGridKeys);
    const Json* grid = Validator::Find(value, "grid");
    const Json* vectors = Validator::Find(value, "vectors");
    if (!grid) check.Fail(field + ".grid", "required field is missing");
    if (!vectors) check.Fail(field + ".vectors", "required field is missing");

    std::optional<std::array<int64_t, 2>> size;
    if (grid) size = check.Integers<2>(*grid, field + ".grid", 1, kU32Max);
    if (!vectors) return;
    if (!vectors->is_array()) {
        check.Fail(field + ".vectors", "expected an array of [wx, wy] pairs, got " + Describe(*vectors));
        return;
    }
    if (size) {
        const uint64_t expected = uint64_t((*size)[0]) * uint64_t((*size)[1]);
        if (vectors->size() != expected) {
            check.Fail(field + ".vectors", "expected " + std::to_string(expected) + " pairs (grid " +
                                               std::to_string((*size)[0]) + " x " + std::to_string((*size)[1]) +
                                               "), got " + std::to_string(vectors->size()));
        }
        wind.gridNx = uint32_t((*size)[0]);
        wind.gridNy = uint32_t((*size)[1]);
    }
    wind.grid.clear();
    for (size_t i = 0; i < vectors->size(); ++i) {
        if (auto v = check.Numbers<2>((*vectors)[i], IndexField(field + ".vectors", i), kFinite))
            wind.grid.push_back(*v);
    }
}

void ReadEllipsoids(const Json& root, Validator& check, EllipsoidSettings& e) {
    const Json* section = check.Section(root, "", "ellipsoids", kEllipsoidKeys);
    if (!section) return;
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    auto field = [](std::string_view key) { return JoinField("ellipsoids", key); };

    if (const Json* v = find("seed")) {
        if (auto n = check.Integer(*v, field("seed"), 0, kSeed64Max)) e.seed = uint64_t(*n);
    }
    if (const Json* v = find("target_count")) {
        if (auto n = check.Integer(*v, field("target_count"), 0, 100000)) e.targetCount = uint32_t(*n);
    }
    if (const Json* v = find("density_adaption")) {
        if (auto n = check.Integer(*v, field("density_adaption"), 0, 100000)) e.densityAdaption = uint32_t(*n);
    }
    // Each variance must not exceed its mean; the message names whichever of the two the file gave.
    bool sizeMeanOk = true, sizeVarianceOk = true;
    if (const Json* v = find("size_mean")) {
        auto a = check.Numbers<3>(*v, field("size_mean"), kPositive);
        if (a) e.sizeMean = *a;
        sizeMeanOk = a.has_value();
    }
    const Json* sizeVariance = find("size_variance");
    if (sizeVariance) {
        auto a = check.Numbers<3>(*sizeVariance, field("size_variance"), kNonNegative);
        if (a) e.sizeVariance = *a;
        sizeVarianceOk = a.has_value();
    }
    for (size_t i = 0; sizeMeanOk && sizeVarianceOk && i < 3; ++i) {
        if (e.sizeVariance[i] <= e.sizeMean[i]) continue;
        const std::string index = "[" + std::to_string(i) + "]";
        if (sizeVariance)
            check.Fail(field("size_variance") + index, "must be <= size_mean" + index + " (" +
                                                           FormatNumber(e.sizeMean[i]) + "), got " +
                                                           FormatNumber(e.sizeVariance[i]));
        else
            check.Fail(field("size_mean") + index, "must be >= size_variance" + index + " (" +
                                                       FormatNumber(e.sizeVariance[i]) + "), got " +
                                                       FormatNumber(e.sizeMean[i]));
    }
    bool lifetimeMeanOk = true, lifetimeVarianceOk = true;
    if (const Json* v = find("lifetime_mean")) {
        auto d = check.Number(*v, field("lifetime_mean"), Range{.lo = 1});
        if (d) e.lifetimeMean = *d;
        lifetimeMeanOk = d.has_value();
    }
    const Json* lifetimeVariance = find("lifetime_variance");
    if (lifetimeVariance) {
        auto d = check.Number(*lifetimeVariance, field("lifetime_variance"), kNonNegative);
        if (d) e.lifetimeVariance = *d;
        lifetimeVarianceOk = d.has_value();
    }
    if (lifetimeMeanOk && lifetimeVarianceOk && e.lifetimeVariance >= e.lifetimeMean) {
        if (lifetimeVariance)
            check.Fail(field("lifetime_variance"), "must be < lifetime_mean (" + FormatNumber(e.lifetimeMean) +
                                                       "), got " + FormatNumber(e.lifetimeVariance));
        else
            check.Fail(field("lifetime_mean"), "must be > lifetime_variance (" + FormatNumber(e.lifetimeVariance) +
                                                   "), got " + FormatNumber(e.lifetimeMean));
    }
    if (const Json* v = find("shrink_steps")) {
        if (auto n = check.Integer(*v, field("shrink_steps"), 0, kU32Max)) e.shrinkSteps = uint32_t(*n);
    }
    if (const Json* v = find("margin")) {
        if (auto d = check.Number(*v, field("margin"), kNonNegative)) e.margin = *d;
    }
    if (const Json* v = find("height_range")) {
        if (auto a = check.Numbers<2>(*v, field("height_range"), kProbability)) {
            if ((*a)[0] > (*a)[1])
                check.Fail(field("height_range"), "lo must be <= hi, got " + Describe(*v));
            else
                e.heightRange = *a;
        }
    }
    if (const Json* v = find("wind")) ReadWind(*v, check, e.wind);
    if (const Json* v = find("jitter")) {
        if (auto d = check.Number(*v, field("jitter"), kNonNegative)) e.jitter = *d;
    }
}

void ReadSun(const Json& root, Validator& check, SunSettings& sun) {
    const Json* section = check.Section(root, "", "sun", kSunKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "elevation_deg")) {
        if (auto d = check.Number(*v, "sun.elevation_deg", Range{.lo = -90, .hi = 90})) sun.elevationDeg = *d;
    }
    if (const Json* v = Validator::Find(*section, "azimuth_deg")) {
        if (auto d = check.Number(*v, "sun.azimuth_deg", kFinite)) sun.azimuthDeg = *d;
    }
    if (const Json* v = Validator::Find(*section, "color")) {
        if (auto a = check.Numbers<3>(*v, "sun.color", kNonNegative)) sun.color = *a;
    }
    if (const Json* v = Validator::Find(*section, "intensity")) {
        if (auto d = check.Number(*v, "sun.intensity", kNonNegative)) sun.intensity = *d;
    }
}

void ReadLighting(const Json& root, Validator& check, LightingSettings& lighting) {
    const Json* section = check.Section(root, "", "lighting", kLightingKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "ambient")) {
        if (auto a = check.Numbers<3>(*v, "lighting.ambient", kNonNegative)) lighting.ambient = *a;
    }
    if (const Json* v = Validator::Find(*section, "background")) {
        if (auto a = check.Numbers<3>(*v, "lighting.background", kNonNegative)) lighting.background = *a;
    }
}

void ReadPhase(const Json& root, Validator& check, PhaseParams& phase) {
    const Json* section = check.Section(root, "", "phase", kPhaseKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "function")) {
        if (auto kind = check.Choice(*v, "phase.function", kPhaseKinds)) phase.kind = *kind;
    }
    if (const Json* v = Validator::Find(*section, "g")) {
        if (auto d = check.Number(*v, "phase.g", Range{.lo = -1, .loOpen = true, .hi = 1, .hiOpen = true})) {
            // g is kept as a float: a value within 2^-25 of +-1 would become +-1 there.
            if (std::fabs(float(*d)) >= 1.0f)
                check.Fail("phase.g", "must be in (-1, 1) in single precision, got " + Describe(*v));
            else
                phase.g = float(*d);
        }
    }
}

void ReadShade(const Json& root, Validator& check, ShadeSettings& shade) {
    const Json* section = check.Section(root, "", "shade", kShadeKeys);
    if (!section) return;
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    if (const Json* v = find("attenuation")) {
        if (auto kind = check.Choice(*v, "shade.attenuation", kAttenuationKinds)) shade.attenuation = *kind;
    }
    if (const Json* v = find("sigma")) {
        if (auto d = check.Number(*v, "shade.sigma", kNonNegative)) shade.sigma = *d;
    }
    if (const Json* v = find("thesis_ar")) {
        if (auto d = check.Number(*v, "shade.thesis_ar", kProbability)) shade.thesisAr = *d;
    }
    if (const Json* v = find("filter")) {
        if (auto filter = check.Choice(*v, "shade.filter", kFilters)) shade.filter = *filter;
    }
    if (const Json* v = find("resolution")) {
        if (auto n = check.IntegerChoice(*v, "shade.resolution", kShadeResolutions, "1, 2 or 4"))
            shade.resolution = int(*n);
    }
    if (const Json* v = find("storage")) {
        if (auto format = check.Choice(*v, "shade.storage", kStorageFormats)) shade.storage = *format;
    }
    const Json* scattering = check.Section(*section, "shade", "scattering", kScatteringKeys);
    if (!scattering) return;
    if (const Json* v = Validator::Find(*scattering, "enabled")) {
        if (auto b = check.Boolean(*v, "shade.scattering.enabled")) shade.scattering = *b;
    }
    if (const Json* v = Validator::Find(*scattering, "albedo")) {
        if (auto d = check.Number(*v, "shade.scattering.albedo", kProbability)) shade.albedo = *d;
    }
    if (const Json* v = Validator::Find(*scattering, "solid_angle")) {
        const Range solidAngle{.lo = 0, .loOpen = true, .hi = 4 * std::numbers::pi};
        if (auto d = check.Number(*v, "shade.scattering.solid_angle", solidAngle)) shade.solidAngle = *d;
    }
}

void ReadShadow(const Json& root, Validator& check, ShadowSettings& shadow) {
    const Json* section = check.Section(root, "", "shadow", kShadowKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "form")) {
        if (auto kind = check.Choice(*v, "shadow.form", kAttenuationKinds)) shadow.form = *kind;
    }
    if (const Json* v = Validator::Find(*section, "kappa")) {
        if (auto d = check.Number(*v, "shadow.kappa", kNonNegative)) shadow.kappa = *d;
    }
}

// One entry of render.cameras; nullopt when anything in it is wrong (all of it reported).
std::optional<CameraSettings> ReadCamera(const Json& value, const std::string& field, size_t index,
                                         Validator& check) {
    if (!value.is_object()) {
        check.Fail(field, "expected a camera object, got " + Describe(value));
        return std::nullopt;
    }
    const size_t errorsBefore = check.ErrorCount();
    check.CheckKeys(value, field, kCameraKeys);
    auto find = [&](std::string_view key) { return Validator::Find(value, key); };
    auto sub = [&](std::string_view key) { return JoinField(field, key); };

    CameraSettings camera;
    camera.name = "view" + std::to_string(index);
    if (const Json* v = find("name")) {
        if (auto s = check.String(*v, sub("name"))) {
            if (s->empty())
                check.Fail(sub("name"), "must not be empty");
            else
                camera.name = *s;
        }
    }
    std::optional<std::array<double, 3>> eye, target;
    if (const Json* v = find("eye")) {
        eye = check.Numbers<3>(*v, sub("eye"), kFinite);
    } else {
        check.Fail(sub("eye"), "required field is missing");
    }
    if (const Json* v = find("target")) {
        target = check.Numbers<3>(*v, sub("target"), kFinite);
    } else {
        check.Fail(sub("target"), "required field is missing");
    }
    if (eye && target && *eye == *target) check.Fail(sub("target"), "must differ from eye");
    if (eye) camera.eye = *eye;
    if (target) camera.target = *target;
    if (const Json* v = find("up")) {
        if (auto a = check.Numbers<3>(*v, sub("up"), kFinite)) {
            if ((*a)[0] == 0 && (*a)[1] == 0 && (*a)[2] == 0)
                check.Fail(sub("up"), "must not be all zero, got " + Describe(*v));
            else
                camera.up = *a;
        }
    }
    if (const Json* v = find("fov_deg")) {
        const Range fov{.lo = 0, .loOpen = true, .hi = 180, .hiOpen = true};
        if (auto d = check.Number(*v, sub("fov_deg"), fov)) camera.fovDeg = *d;
    }
    // far must exceed near; the message names whichever of the two the file gave (far when both).
    bool nearOk = true, farOk = true;
    if (const Json* v = find("near")) {
        auto d = check.Number(*v, sub("near"), kPositive);
        if (d) camera.nearPlane = *d;
        nearOk = d.has_value();
    }
    const Json* far = find("far");
    if (far) {
        auto d = check.Number(*far, sub("far"), kFinite);
        if (d) camera.farPlane = *d;
        farOk = d.has_value();
    }
    if (nearOk && farOk && camera.farPlane <= camera.nearPlane) {
        if (far)
            check.Fail(sub("far"), "must be > near (" + FormatNumber(camera.nearPlane) + "), got " +
                                       FormatNumber(camera.farPlane));
        else
            check.Fail(sub("near"), "must be < far (" + FormatNumber(camera.farPlane) + "), got " +
                                        FormatNumber(camera.nearPlane));
    }
    if (check.ErrorCount() != errorsBefore) return std::nullopt;
    return camera;
}

// Reads render; returns false when render.cameras was given but is wrong (so "needs a camera" is not piled on).
bool ReadRender(const Json& root, Validator& check, RenderSettings& render) {
    const Json* section = check.Section(root, "", "render", kRenderKeys);
    if (!section) return true;
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    auto field = [](std::string_view key) { return JoinField("render", key); };

    if (const Json* v = find("width")) {
        if (auto n = check.Integer(*v, field("width"), 1, kMaxImageEdge)) render.width = uint32_t(*n);
    }
    if (const Json* v = find("height")) {
        if (auto n = check.Integer(*v, field("height"), 1, kMaxImageEdge)) render.height = uint32_t(*n);
    }
    if (const Json* v = find("q_min")) {
        if (auto d = check.Number(*v, field("q_min"), kNonNegative)) render.qMin = *d;
    }
    if (const Json* v = find("splat_scale")) {
        if (auto d = check.Number(*v, field("splat_scale"), kPositive)) render.splatScale = *d;
    }
    if (const Json* v = find("opacity")) {
        if (auto d = check.Number(*v, field("opacity"), kProbability)) render.opacity = *d;
    }
    if (const Json* v = find("alpha")) {
        if (auto d = check.Number(*v, field("alpha"), kProbability)) render.alpha = *d;
    }
    if (const Json* v = find("culling")) {
        if (auto b = check.Boolean(*v, field("culling"))) render.culling = *b;
    }
    if (const Json* v = find("skipping")) {
        if (auto b = check.Boolean(*v, field("skipping"))) render.skipping = *b;
    }
    if (const Json* v = find("every_steps")) {
        if (auto n = check.Integer(*v, field("every_steps"), 0, kU32Max)) render.everySteps = uint32_t(*n);
    }

    const Json* cameras = find("cameras");
    if (!cameras) return true;
    if (!cameras->is_array()) {
        check.Fail(field("cameras"), "expected an array of camera objects, got " + Describe(*cameras));
        return false;
    }
    bool allOk = true;
    render.cameras.clear();
    for (size_t i = 0; i < cameras->size(); ++i) {
        const std::string cameraField = IndexField(field("cameras"), i);
        std::optional<CameraSettings> camera = ReadCamera((*cameras)[i], cameraField, i, check);
        if (!camera) {
            allOk = false;
            continue;
        }
        const bool duplicate = std::any_of(render.cameras.begin(), render.cameras.end(),
                                           [&](const CameraSettings& c) { return c.name == camera->name; });
        if (duplicate) {
            // A defaulted name ("view1") can clash with a name given earlier; say so, since the file has no name here.
            const bool given = Validator::Find((*cameras)[i], "name") != nullptr;
            check.Fail(JoinField(cameraField, "name"), "duplicate camera name " + Quote(camera->name) +
                                                           (given ? "" : " (its default name)"));
            allOk = false;
            continue;
        }
        render.cameras.push_back(std::move(*camera));
    }
    return allOk;
}

// The whole validation after parsing and overrides; `scene` holds defaults on entry.
void ReadScene(const Json& root, const std::string& label, Validator& check, Scene& scene) {
    check.CheckKeys(root, "", kTopKeys);

    scene.name = std::filesystem::path(label).stem().string();
    if (const Json* v = Validator::Find(root, "name")) {
        if (auto s = check.String(*v, "name")) {
            if (s->empty())
                check.Fail("name", "must not be empty");
            else
                scene.name = *s;
        }
    }
    if (const Json* v = Validator::Find(root, "description")) check.String(*v, "description");

    const bool sizeOk = ReadGrid(root, check, scene.grid);

    bool stepsOk = true;
    if (const Json* v = Validator::Find(root, "steps")) {
        auto n = check.Integer(*v, "steps", 1, 10000000);
        if (n) scene.steps = uint32_t(*n);
        stepsOk = n.has_value();
    }
    if (const Json* v = Validator::Find(root, "warmup_steps")) {
        if (auto n = check.Integer(*v, "warmup_steps", 0, kU32Max)) {
            scene.warmupSteps = uint32_t(*n);
            if (stepsOk && scene.warmupSteps >= scene.steps)
                check.Fail("warmup_steps", "must be < steps (" + std::to_string(scene.steps) + "), got " +
                                               std::to_string(scene.warmupSteps));
        }
    }

    ReadStages(root, check, scene.stages);
    ReadCa(root, check, sizeOk ? std::optional(scene.grid.size.nz) : std::nullopt, scene.ca);

    // The ellipsoid seed follows ca.seed unless given.
    scene.ellipsoids.seed = scene.ca.seed;
    ReadEllipsoids(root, check, scene.ellipsoids);

    if (const Json* section = check.Section(root, "", "smooth", kSmoothKeys)) {
        if (const Json* v = Validator::Find(*section, "radius")) {
            if (auto n = check.Integer(*v, "smooth.radius", 0, 2)) scene.smooth.radius = int(*n);
        }
    }
    if (const Json* section = check.Section(root, "", "density", kDensityKeys)) {
        if (const Json* v = Validator::Find(*section, "tile")) {
            if (auto n = check.Integer(*v, "density.tile", 1, kU32Max)) scene.density.tile = uint32_t(*n);
        }
        if (const Json* v = Validator::Find(*section, "band")) {
            if (auto n = check.Integer(*v, "density.band", 1, kU32Max)) scene.density.band = uint32_t(*n);
        }
    }

    ReadSun(root, check, scene.sun);
    ReadLighting(root, check, scene.lighting);
    ReadPhase(root, check, scene.phase);
    ReadShade(root, check, scene.shade);
    ReadShadow(root, check, scene.shadow);
    const bool camerasOk = ReadRender(root, check, scene.render);
    if (scene.stages.Has(Stage::RenderSplat) && camerasOk && scene.render.cameras.empty())
        check.Fail("render.cameras", Quote(StageName(Stage::RenderSplat)) + " needs at least one camera");

    // Size checks, before anything grid-sized exists.
    if (!sizeOk) return;
    const Extent3& size = scene.grid.size;
    const uint64_t count = size.Count();
    if (count > kU32Max) {
        check.Fail("grid.size", "[" + std::to_string(size.nx) + ", " + std::to_string(size.ny) + ", " +
                                    std::to_string(size.nz) + "] is " + std::to_string(count) +
                                    " voxels; the voxel index is 32-bit, so at most " + std::to_string(kU32Max));
        return;
    }
    const uint64_t needed = EstimateSceneBytes(scene);
    if (std::optional<uint64_t> physical = PhysicalMemoryBytes(); physical && needed > *physical) {
        check.Fail("grid.size", "the enabled stages need " + FormatGiB(needed) + " GiB, more than this machine's " +
                                    FormatGiB(*physical) + " GiB");
    }
}

Result<Scene> ParseSceneChecked(const std::string& text, const std::string& label,
                                const std::vector<SceneOverride>& overrides) {
    Validator check(label);
    JsonDom dom = scene_io::ParseJsonDom(text);
    if (dom.failure) {
        check.FailWhole(scene_io::DescribeParseFailure(text, *dom.failure));
        return MakeError(check.Message());
    }
    Json& root = dom.root;
    for (const std::string& duplicate : dom.duplicates) check.Fail(duplicate, "duplicate field");
    if (!root.is_object()) {
        check.FailWhole("expected a JSON object at the top level, got " + Describe(root));
        return MakeError(check.Message());
    }
    for (const SceneOverride& item : overrides) ApplyOverride(root, item, check);

    Scene scene;
    ReadScene(root, label, check, scene);
    if (check.ErrorCount() > 0) return MakeError(check.Message());

    // One pair means "the same shift for every slice"; expanded only now that nz is known to be sane.
    if (scene.ca.windShift.size() == 1 && scene.grid.size.nz > 1)
        scene.ca.windShift.assign(scene.grid.size.nz, scene.ca.windShift[0]);
    return scene;
}

}  // namespace

Result<Scene> ParseScene(const std::string& text, const std::string& label,
                         const std::vector<SceneOverride>& overrides) {
    try {
        return ParseSceneChecked(text, label, overrides);
    } catch (const std::exception& e) {
        return MakeError(label + ": internal error while reading the scene: " + e.what());
    } catch (...) {
        return MakeError(label + ": internal error while reading the scene");
    }
}

Result<Scene> LoadScene(const std::string& path, const std::vector<SceneOverride>& overrides) {
    try {
        std::FILE* file = std::fopen(path.c_str(), "rb");
        if (!file) return MakeError(path + ": cannot read the file: " + std::strerror(errno));
        std::string text;
        char buffer[1 << 16];
        size_t n;
        while ((n = std::fread(buffer, 1, sizeof(buffer), file)) > 0) text.append(buffer, n);
        const bool failed = std::ferror(file) != 0;
        const int error = errno;
        std::fclose(file);
        if (failed) return MakeError(path + ": cannot read the file: " + std::strerror(error));

        Result<Scene> scene = ParseScene(text, path, overrides);
        if (scene) scene->path = path;
        return scene;
    } catch (const std::exception& e) {
        return MakeError(path + ": internal error while reading the scene: " + e.what());
    } catch (...) {
        return MakeError(path + ": internal error while reading the scene");
    }
}

}  // namespace cb
