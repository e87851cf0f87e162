// What every record an isolated backend's child sends back to its parent
// (harness/platform/Isolation.h) is made of in JSON: doubles that keep their
// exact value, non-finite ones included, and optional values as null. Each
// wing's records have their round trip beside them (harness/run/RunTransfer.h,
// harness/report/ReportTransfer.h, harness/conform/ConformTransfer.h,
// harness/accuracy/AccuracyTransfer.h): FromJson(ToJson(x)) == x for every
// field the commands read.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <type_traits>

namespace cb::transfer {

using nlohmann::json;

// A double, non-finite values included (JSON numbers cannot hold them).
inline json D(double v) {
    if (std::isfinite(v)) return v;
    return std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
}
inline double FromD(const json& j) {
    if (j.is_number()) return j.get<double>();
    const std::string text = j.get<std::string>();
    if (text == "nan") return std::numeric_limits<double>::quiet_NaN();
    return text == "inf" ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
}

inline json Optional(const std::optional<double>& value) { return value ? D(*value) : json(nullptr); }
inline json Optional(const std::optional<uint32_t>& value) { return value ? json(*value) : json(nullptr); }
template <typename T>
std::optional<T> OptionalFrom(const json& j) {
    if (j.is_null()) return std::nullopt;
    if constexpr (std::is_same_v<T, double>)
        return FromD(j);
    else
        return j.get<T>();
}

}  // namespace cb::transfer
