// The plots of `cloudbench report` as inline SVG, drawn by the project: no
// plotting library, no script, the same bytes for the same data. Every plot's
// root is <svg class="plot" data-plot="KIND"> (box, history, pareto); its
// axes carry data-lo/data-hi/data-log and its marks carry the values they
// show as data-* attributes, so that tests read the numbers back from the
// markup (tests/HtmlPlotTest.cpp, tests/check_html_report.py).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "harness/report/XmlText.h"

namespace cb::html {

// A plot axis: the data range [lo, hi] shown, widened to round numbers, and
// its ticks. Linear: ticks every 1, 2 or 5 x 10^k, lo and hi multiples of the
// step. Log: lo and hi whole decades, a tick per decade.
struct Axis {
    double lo = 0, hi = 1;
    bool log = false;
    std::vector<double> ticks;
    // `value` mapped onto [pixelLo, pixelHi] (pixelLo at lo); values outside
    // the range are clamped to it, a log axis takes v <= 0 as lo.
    double ToPixel(double value, double pixelLo, double pixelHi) const;
};
// An axis covering [min, max] with about `targetTicks` ticks. A log axis
// needs min > 0 (otherwise it is linear); an empty or one-value range is
// widened around the value (to [0, 1] for no value at all: min > max). A
// linear axis of `whole` numbers (counts, record indices) has whole ticks.
Axis MakeAxis(double min, double max, bool log, int targetTicks = 5, bool whole = false);
// A tick label: up to 4 significant digits, no trailing zeros (0.05, 2, 1000, 1e+04).
std::string TickLabel(double value);

// A box of a box plot: the quartiles (NumPy's linear interpolation, as
// Summarize in harness/report/Report.h), Tukey whiskers (the furthest samples within
// 1.5 IQR of the box) and the samples beyond them.
struct BoxStats {
    size_t count = 0;
    double q1 = 0, median = 0, q3 = 0;
    double whiskerLo = 0, whiskerHi = 0;
    std::vector<double> outliers;
};
BoxStats BoxStatsOf(std::vector<double> samples);

// Distributions side by side: along x one group per label (a stage), in each
// group one box per series (a backend) that has samples.
struct BoxPlot {
    std::string title, yLabel;
    bool logY = true;
    std::vector<std::string> series;  // colour order
    struct Box {
        size_t series = 0;  // index into `series`
        std::vector<double> samples;
    };
    struct Group {
        std::string label;
        std::vector<Box> boxes;
    };
    std::vector<Group> groups;
};
std::string RenderBoxPlot(const BoxPlot& plot);

// Lines over x, one per series; `marks` are indices of points drawn as change
// points (a vertical dashed line and a ring, data-change-point="x").
struct Series {
    std::string name;
    std::vector<double> x, y;
    std::vector<std::string> pointLabels;  // tooltip of each point; may be empty
    std::vector<size_t> marks;
};
struct LinePlot {
    std::string title, xLabel, yLabel;
    std::vector<Series> series;
};
std::string RenderHistoryPlot(const LinePlot& plot);

// Points, one colour per series, the front drawn as a dashed line through
// `front` (sorted by x).
struct ScatterPlot {
    std::string title, xLabel, yLabel;
    bool logX = true, logY = true;  // logY falls back to linear when a y is <= 0
    std::vector<Series> series;
    std::vector<std::pair<double, double>> front;
};
std::string RenderParetoPlot(const ScatterPlot& plot);

// The points of `points` that no other point beats in both coordinates
// (smaller x and smaller y, one of them strictly), sorted by x.
std::vector<std::pair<double, double>> ParetoFront(std::vector<std::pair<double, double>> points);

}  // namespace cb::html
