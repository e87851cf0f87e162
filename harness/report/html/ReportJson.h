// The tolerant JSON readers of `cloudbench report` (internal to harness/html):
// a missing key or one of another type reads as empty, so that a partial
// input still gives a page.
#pragma once

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace cb::html {

using nlohmann::json;

inline const json& EmptyObject() {
    static const json empty = json::object();
    return empty;
}

// doc[key] when it is an object, else an empty object: the inputs are read tolerantly.
inline const json& Obj(const json& doc, const char* key) {
    if (!doc.is_object()) return EmptyObject();
    auto it = doc.find(key);
    return it != doc.end() && it->is_object() ? *it : EmptyObject();
}

inline const json& Arr(const json& doc, const char* key) {
    static const json empty = json::array();
    if (!doc.is_object()) return empty;
    auto it = doc.find(key);
    return it != doc.end() && it->is_array() ? *it : empty;
}

// doc[key] as text: a string as it is, a number or boolean as JSON writes it, else `fallback`.
inline std::string Str(const json& doc, const char* key, const std::string& fallback = "") {
    if (!doc.is_object()) return fallback;
    auto it = doc.find(key);
    if (it == doc.end() || it->is_null() || it->is_object() || it->is_array()) return fallback;
    return it->is_string() ? it->get<std::string>() : it->dump();
}

inline std::optional<double> Number(const json& doc, const char* key) {
    if (!doc.is_object()) return std::nullopt;
    auto it = doc.find(key);
    if (it == doc.end() || !it->is_number()) return std::nullopt;
    return it->get<double>();
}

inline std::vector<double> Numbers(const json& doc, const char* key) {
    std::vector<double> out;
    for (const json& v : Arr(doc, key))
        if (v.is_number()) out.push_back(v.get<double>());
    return out;
}

inline std::string FileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

inline std::string Fixed(double value, const char* format = "%.3f") {
    char text[64];
    std::snprintf(text, sizeof text, format, value);
    return text;
}

}  // namespace cb::html
