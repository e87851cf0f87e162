// Progress of a command's steps on stderr (docs/cli.md, "run"): the step, the
// steps to go and an estimate of the time left, at most once per interval,
// and a closing line. The clock and the output can be injected (tests).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace cb {

// Seconds left, from the steps done since the first step that was reported
// (the first step, with its compilation and set-up, is left out of the rate
// as soon as a second one is done): (now - firstStepEnd) / (done - firstDone)
// per step; with one step done, that step's time. nullopt with nothing done.
struct ProgressEstimate {
    double startS = 0;                  // the clock when counting began
    std::optional<uint32_t> firstDone;  // steps done at the first report
    double firstDoneS = 0;              // the clock at the first report
    std::optional<double> SecondsLeft(uint32_t done, uint32_t total, double nowS) const;
};

// "12 s", "2 min 05 s", "1 h 03 min".
std::string ProgressDuration(double seconds);

class Progress {
  public:
    using Clock = std::function<double()>;                // seconds, from any fixed origin
    using Write = std::function<void(std::string_view)>;  // receives whole lines, "\r"-led on a terminal

    // Stderr and the steady clock; a terminal rewrites one line every second,
    // anything else gets a line every 10 s.
    Progress(std::string label, uint32_t total, bool quiet);
    Progress(std::string label, uint32_t total, bool quiet, bool terminal, Clock clock, Write write);

    ~Progress();  // Finish(), if not called
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    // `done` steps are complete (a resumed run's first call may be above 1).
    void Update(uint32_t done);
    // The end, once, whatever the interval: "LABEL: N steps in T", or "LABEL:
    // stopped after N of M steps, T" short of the total.
    void Finish();

    static constexpr double kTerminalIntervalS = 1;
    static constexpr double kLogIntervalS = 10;

  private:
    void Emit(const std::string& text, bool final);

    std::string mLabel;
    uint32_t mTotal;
    bool mQuiet, mTerminal;
    Clock mClock;
    Write mWrite;
    ProgressEstimate mEstimate;
    double mLastS;       // the clock at the last line (at the start before any)
    uint32_t mDone = 0;  // the last Update's
    size_t mShown = 0;   // terminal: the length of the line on screen
    bool mFinished = false;
};

}  // namespace cb
