// A statistic's counters as a list (a renderer's SplatStats, MarchStats).
#pragma once

#include <cstddef>
#include <cstdint>
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

}  // namespace cb
