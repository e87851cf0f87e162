// A statistic's counters as a list (a renderer's SplatStats, MarchStats).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace cb {

// A renderer's counters as lists: each counter's member, its JSON name and
// where it is shown. The lists drive the read-back from an isolated child and
// a saved state (harness/run/RunTransfer.cpp), results.json and its schema
// (harness/report/ResultsJson.cpp, harness/report/InputFormats.cpp) and the
// text report (harness/report/TimingSection.cpp), so a new counter is its
// member and one line in its list; the static_asserts fail when a member is missing.
enum class CounterShown {
    ReadBack,          // travels with the record only (a child's result, a saved state)
    Results,           // also per frame in results.json
    ResultsAndReport,  // also the count the text report gives after a camera's frames (one per renderer)
};
template <typename Stats>
struct Counter {
    std::string_view name;  // the JSON key
    uint64_t Stats::*member;
    CounterShown shown;
};
// The one counter of `list` that the text report gives.
template <typename Stats, size_t N>
constexpr const Counter<Stats>& ReportedCounter(const Counter<Stats> (&list)[N]) {
    size_t found = N;
    for (size_t i = 0; i < N; ++i)
        if (list[i].shown == CounterShown::ResultsAndReport) found = found == N ? i : N + 1;
    if (found >= N) throw "a renderer's counters name exactly one ResultsAndReport";  // fails the constant evaluation
    return list[found];
}

// A frame's counters without their type, as the harness keeps them (FrameRecord): the values of its
// renderer's list, in the list's order (RendererDescriptor::counters names them).
inline constexpr size_t kMaxFrameCounters = 8;
using FrameCounters = std::array<uint64_t, kMaxFrameCounters>;

// One counter of a renderer's list without its member: its JSON key and where it is shown.
struct FrameCounterField {
    std::string_view name;
    CounterShown shown = CounterShown::ReadBack;
};

template <typename Stats, size_t N>
constexpr std::array<FrameCounterField, N> FrameCounterFields(const Counter<Stats> (&list)[N]) {
    static_assert(N <= kMaxFrameCounters, "raise kMaxFrameCounters");
    std::array<FrameCounterField, N> fields{};
    for (size_t i = 0; i < N; ++i) fields[i] = {list[i].name, list[i].shown};
    return fields;
}

template <typename Stats, size_t N>
FrameCounters ToFrameCounters(const Stats& stats, const Counter<Stats> (&list)[N]) {
    static_assert(N <= kMaxFrameCounters, "raise kMaxFrameCounters");
    FrameCounters values{};
    for (size_t i = 0; i < N; ++i) values[i] = stats.*list[i].member;
    return values;
}

// The index in `fields` of the one counter the text report gives (ReportedCounter's).
constexpr size_t ReportedCounterIndex(std::span<const FrameCounterField> fields) {
    for (size_t i = 0; i < fields.size(); ++i)
        if (fields[i].shown == CounterShown::ResultsAndReport) return i;
    return fields.size();
}

}  // namespace cb
