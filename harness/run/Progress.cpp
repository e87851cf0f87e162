#include "harness/run/Progress.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace cb {
namespace {

double ProgressSteadySeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void ProgressToStderr(std::string_view text) {
    std::fwrite(text.data(), 1, text.size(), stderr);
    std::fflush(stderr);
}

}  // namespace

std::optional<double> ProgressEstimate::SecondsLeft(uint32_t done, uint32_t total, double nowS) const {
    if (!firstDone || done < *firstDone || done == 0) return std::nullopt;
    if (done >= total) return 0.0;
    // Past the first reported step, the rate since it; before, that one step's time.
    const double perStep = done > *firstDone ? (nowS - firstDoneS) / double(done - *firstDone) : firstDoneS - startS;
    return std::max(0.0, perStep) * double(total - done);
}

std::string ProgressDuration(double seconds) {
    char text[64];
    const long long s = std::llround(std::max(0.0, seconds));
    if (s < 60)
        std::snprintf(text, sizeof text, "%lld s", s);
    else if (s < 3600)
        std::snprintf(text, sizeof text, "%lld min %02lld s", s / 60, s % 60);
    else
        std::snprintf(text, sizeof text, "%lld h %02lld min", s / 3600, (s % 3600) / 60);
    return text;
}

Progress::Progress(std::string label, uint32_t total, bool quiet)
    : Progress(std::move(label), total, quiet, isatty(STDERR_FILENO) != 0, ProgressSteadySeconds, ProgressToStderr) {}

Progress::Progress(std::string label, uint32_t total, bool quiet, bool terminal, Clock clock, Write write)
    : mLabel(std::move(label)),
      mTotal(total),
      mQuiet(quiet),
      mTerminal(terminal),
      mClock(std::move(clock)),
      mWrite(std::move(write)) {
    mEstimate.startS = mClock();
    mLastS = mEstimate.startS;
}

Progress::~Progress() { Finish(); }

void Progress::Update(uint32_t done) {
    if (mQuiet || mFinished) return;
    const double now = mClock();
    if (!mEstimate.firstDone) {
        mEstimate.firstDone = done;
        mEstimate.firstDoneS = now;
    }
    mDone = done;
    if (done >= mTotal || now - mLastS < (mTerminal ? kTerminalIntervalS : kLogIntervalS)) return;
    std::string text = mLabel + ": step " + std::to_string(done) + " of " + std::to_string(mTotal);
    if (const auto left = mEstimate.SecondsLeft(done, mTotal, now))
        text += ", about " + ProgressDuration(*left) + " left";
    Emit(text, false);
    mLastS = now;
}

void Progress::Finish() {
    if (mQuiet || mFinished) return;
    mFinished = true;
    const double took = mClock() - mEstimate.startS;
    char tenths[32];  // a short run's time in tenths of a second
    std::snprintf(tenths, sizeof tenths, "%.1f s", took);
    const std::string time = took < 10 ? tenths : ProgressDuration(took);
    const uint32_t before = mEstimate.firstDone ? *mEstimate.firstDone - 1 : 0;  // a resumed run's
    if (mDone < mTotal)
        Emit(mLabel + ": stopped after " + std::to_string(mDone) + " of " + std::to_string(mTotal) + " steps, " + time,
             true);
    else if (before == 0)
        Emit(mLabel + ": " + std::to_string(mTotal) + " steps in " + time, true);
    else
        Emit(mLabel + ": steps " + std::to_string(before + 1) + " to " + std::to_string(mTotal) + " in " + time, true);
}

void Progress::Emit(const std::string& text, bool final) {
    if (!mTerminal) {
        mWrite(text + "\n");
        return;
    }
    // One line, rewritten: padded over the longer line it replaces; the last one ends it.
    std::string line = "\r" + text;
    if (mShown > text.size()) line += std::string(mShown - text.size(), ' ');
    mShown = final ? 0 : text.size();
    mWrite(line + (final ? "\n" : ""));
}

}  // namespace cb
