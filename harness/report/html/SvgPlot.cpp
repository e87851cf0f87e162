#include "harness/report/html/SvgPlot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <tuple>

namespace cb::html {
namespace {

// The plot frame in SVG pixels.
constexpr double kWidth = 760, kHeight = 360;
constexpr double kLeft = 72, kRight = 16, kTop = 44, kBottom = 64;
constexpr double kPlotLeft = kLeft, kPlotRight = kWidth - kRight, kPlotTop = kTop, kPlotBottom = kHeight - kBottom;

// One colour per series, in series order (matplotlib's first colours, so that
// sweep.png and the report agree).
constexpr std::array<const char*, 8> kColours = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                                 "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};
const char* Colour(size_t series) { return kColours[series % kColours.size()]; }

// A coordinate in the markup: 0.1 px.
std::string Px(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", value);
    return text;
}

// A data value in a data-* attribute: enough digits to read it back.
std::string Num(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", value);
    return text;
}

std::string Attr(const std::string& name, const std::string& value) {
    return " " + name + "=\"" + EscapeXml(value) + "\"";
}

std::string Text(double x, double y, const std::string& text, const std::string& extra = "") {
    return "<text x=\"" + Px(x) + "\" y=\"" + Px(y) + "\"" + extra + ">" + EscapeXml(text) + "</text>\n";
}

std::string Line(double x1, double y1, double x2, double y2, const std::string& extra) {
    return "<line x1=\"" + Px(x1) + "\" y1=\"" + Px(y1) + "\" x2=\"" + Px(x2) + "\" y2=\"" + Px(y2) + "\"" + extra +
           "/>\n";
}

std::string Open(const std::string& kind, const std::string& title) {
    return "<svg class=\"plot\"" + Attr("data-plot", kind) + " viewBox=\"0 0 " + Px(kWidth) + " " + Px(kHeight) +
           "\" width=\"" + Px(kWidth) + "\" height=\"" + Px(kHeight) + "\" role=\"img\"" + Attr("aria-label", title) +
           ">\n<title>" + EscapeXml(title) + "</title>\n" +
           Text(kWidth / 2, 18, title, " text-anchor=\"middle\" class=\"plot-title\"");
}

// The y axis: grid lines, ticks and labels at the left, the label turned.
std::string YAxis(const Axis& axis, const std::string& label) {
    std::string out = "<g class=\"axis\" data-axis=\"y\"" + Attr("data-lo", Num(axis.lo)) +
                      Attr("data-hi", Num(axis.hi)) + Attr("data-log", axis.log ? "1" : "0") + ">\n";
    for (double tick : axis.ticks) {
        const double y = axis.ToPixel(tick, kPlotBottom, kPlotTop);
        out += Line(kPlotLeft, y, kPlotRight, y, " class=\"grid\"");
        out += Text(kPlotLeft - 6, y + 4, TickLabel(tick), " text-anchor=\"end\"");
    }
    out += Line(kPlotLeft, kPlotTop, kPlotLeft, kPlotBottom, " class=\"frame\"");
    const double mid = (kPlotTop + kPlotBottom) / 2;
    out += Text(16, mid, label, " text-anchor=\"middle\" transform=\"rotate(-90 16 " + Px(mid) + ")\"");
    return out + "</g>\n";
}

// A numeric x axis: ticks and labels below the plot.
std::string XAxis(const Axis& axis, const std::string& label) {
    std::string out = "<g class=\"axis\" data-axis=\"x\"" + Attr("data-lo", Num(axis.lo)) +
                      Attr("data-hi", Num(axis.hi)) + Attr("data-log", axis.log ? "1" : "0") + ">\n";
    for (double tick : axis.ticks) {
        const double x = axis.ToPixel(tick, kPlotLeft, kPlotRight);
        out += Line(x, kPlotTop, x, kPlotBottom, " class=\"grid\"");
        out += Text(x, kPlotBottom + 16, TickLabel(tick), " text-anchor=\"middle\"");
    }
    out += Line(kPlotLeft, kPlotBottom, kPlotRight, kPlotBottom, " class=\"frame\"");
    out += Text((kPlotLeft + kPlotRight) / 2, kHeight - 14, label, " text-anchor=\"middle\"");
    return out + "</g>\n";
}

// The series' names with their colours, in a row above the plot.
std::string Legend(const std::vector<std::string>& names) {
    std::string out = "<g class=\"legend\">\n";
    double x = kPlotLeft;
    for (size_t i = 0; i < names.size(); ++i) {
        out += "<rect x=\"" + Px(x) + "\" y=\"27\" width=\"10\" height=\"10\" fill=\"" + Colour(i) + "\"/>\n";
        out += Text(x + 14, 36, names[i]);
        x += 24 + 7.0 * double(names[i].size());
    }
    return out + "</g>\n";
}

// The range of `values`, only positive ones when `positive`: {min, max}, min > max when none.
std::pair<double, double> RangeOf(const std::vector<double>& values, bool positive) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (double v : values)
        if (std::isfinite(v) && (!positive || v > 0)) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    return {lo, hi};
}

double Quantile(const std::vector<double>& sorted, double p) {
    const double pos = p * double(sorted.size() - 1);
    const size_t lo = size_t(std::floor(pos));
    const size_t hi = std::min(lo + 1, sorted.size() - 1);
    return sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - double(lo));
}

// Every series' x and y values pooled (for the axes' ranges), and the series' names (for the legend).
struct PooledSeries {
    std::vector<double> xs, ys;
    std::vector<std::string> names;
};
PooledSeries Pooled(const std::vector<Series>& series) {
    PooledSeries out;
    for (const Series& s : series) {
        out.xs.insert(out.xs.end(), s.x.begin(), s.x.end());
        out.ys.insert(out.ys.end(), s.y.begin(), s.y.end());
        out.names.push_back(s.name);
    }
    return out;
}

}  // namespace

double Axis::ToPixel(double value, double pixelLo, double pixelHi) const {
    double t;
    if (log)
        t = value <= 0 ? 0 : (std::log10(value) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
    else
        t = (value - lo) / (hi - lo);
    t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0);
    return pixelLo + t * (pixelHi - pixelLo);
}

Axis MakeAxis(double min, double max, bool log, int targetTicks, bool whole) {
    Axis axis;
    if (!(min <= max)) min = 0, max = 1;  // no value (also NaN)
    if (log && min > 0) {
        axis.log = true;
        int first = int(std::floor(std::log10(min) + 1e-9)), last = int(std::ceil(std::log10(max) - 1e-9));
        if (last <= first) last = first + 1;
        const int stride = std::max(1, (last - first + 7) / 8);  // at most about 8 labelled decades
        axis.lo = std::pow(10.0, first);
        axis.hi = std::pow(10.0, last);
        for (int e = first; e <= last; e += stride) axis.ticks.push_back(std::pow(10.0, e));
        return axis;
    }
    if (min == max) {
        const double pad = min == 0 ? 1 : std::abs(min) * 0.1;
        min -= min == 0 ? 0 : pad;
        max += pad;
    }
    const double raw = (max - min) / std::max(1, targetTicks);
    const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
    const double r = raw / magnitude;
    const double round = (r <= 1 ? 1 : r <= 2 ? 2 : r <= 5 ? 5 : 10) * magnitude;
    const double step = whole ? std::max(1.0, round) : round;
    const double first = std::floor(min / step + 1e-9), last = std::ceil(max / step - 1e-9);
    axis.lo = first * step;
    axis.hi = last * step;
    for (double k = first; k <= last + 0.5; k += 1) axis.ticks.push_back(k * step);
    return axis;
}

std::string TickLabel(double value) {
    if (std::abs(value) < 1e-12) return "0";
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", value);
    return text;
}

BoxStats BoxStatsOf(std::vector<double> samples) {
    BoxStats s;
    s.count = samples.size();
    if (samples.empty()) return s;
    std::sort(samples.begin(), samples.end());
    s.q1 = Quantile(samples, 0.25);
    s.median = Quantile(samples, 0.5);
    s.q3 = Quantile(samples, 0.75);
    const double iqr = s.q3 - s.q1, lowFence = s.q1 - 1.5 * iqr, highFence = s.q3 + 1.5 * iqr;
    s.whiskerLo = s.q1;
    s.whiskerHi = s.q3;
    for (double v : samples) {
        if (v < lowFence || v > highFence)
            s.outliers.push_back(v);
        else {
            s.whiskerLo = std::min(s.whiskerLo, v);
            s.whiskerHi = std::max(s.whiskerHi, v);
        }
    }
    return s;
}

std::string RenderBoxPlot(const BoxPlot& plot) {
    std::vector<double> all;
    for (const BoxPlot::Group& g : plot.groups)
        for (const BoxPlot::Box& b : g.boxes) all.insert(all.end(), b.samples.begin(), b.samples.end());
    auto [lo, hi] = RangeOf(all, plot.logY);
    const bool log = plot.logY && lo <= hi;
    if (!log) std::tie(lo, hi) = RangeOf(all, false);
    const Axis y = MakeAxis(lo, hi, log);
    std::string out = Open("box", plot.title) + Legend(plot.series) + YAxis(y, plot.yLabel);
    out += Line(kPlotLeft, kPlotBottom, kPlotRight, kPlotBottom, " class=\"frame\"");
    const double groupWidth = (kPlotRight - kPlotLeft) / double(std::max<size_t>(1, plot.groups.size()));
    const double slot = groupWidth / double(std::max<size_t>(1, plot.series.size()) + 1);
    for (size_t g = 0; g < plot.groups.size(); ++g) {
        const BoxPlot::Group& group = plot.groups[g];
        const double left = kPlotLeft + groupWidth * double(g);
        out += Text(left + groupWidth / 2, kPlotBottom + 16, group.label, " text-anchor=\"middle\"");
        for (const BoxPlot::Box& box : group.boxes) {
            if (box.samples.empty()) continue;
            const BoxStats s = BoxStatsOf(box.samples);
            const double cx = left + slot * (double(box.series) + 1), half = slot * 0.35;
            auto py = [&](double v) { return y.ToPixel(v, kPlotBottom, kPlotTop); };
            const std::string series = box.series < plot.series.size() ? plot.series[box.series] : "";
            const std::string colour = Colour(box.series);
            out += "<g class=\"box\"" + Attr("data-group", group.label) + Attr("data-series", series) +
                   Attr("data-count", std::to_string(s.count)) + Attr("data-q1", Num(s.q1)) +
                   Attr("data-median", Num(s.median)) + Attr("data-q3", Num(s.q3)) +
                   Attr("data-whisker-lo", Num(s.whiskerLo)) + Attr("data-whisker-hi", Num(s.whiskerHi)) +
                   Attr("data-outliers", std::to_string(s.outliers.size())) + ">\n";
            out += "<title>" +
                   EscapeXml(group.label + " " + series + ": median " + TickLabel(s.median) + ", quartiles " +
                             TickLabel(s.q1) + " to " + TickLabel(s.q3) + ", " + std::to_string(s.count) + " samples") +
                   "</title>\n";
            out += Line(cx, py(s.whiskerLo), cx, py(s.q1), " stroke=\"" + colour + "\"");
            out += Line(cx, py(s.q3), cx, py(s.whiskerHi), " stroke=\"" + colour + "\"");
            out += Line(cx - half / 2, py(s.whiskerLo), cx + half / 2, py(s.whiskerLo), " stroke=\"" + colour + "\"");
            out += Line(cx - half / 2, py(s.whiskerHi), cx + half / 2, py(s.whiskerHi), " stroke=\"" + colour + "\"");
            out += "<rect x=\"" + Px(cx - half) + "\" y=\"" + Px(py(s.q3)) + "\" width=\"" + Px(2 * half) +
                   "\" height=\"" + Px(std::max(0.5, py(s.q1) - py(s.q3))) + "\" fill=\"" + colour +
                   "\" fill-opacity=\"0.35\" stroke=\"" + colour + "\"/>\n";
            out += Line(cx - half, py(s.median), cx + half, py(s.median),
                        " class=\"median\" stroke=\"" + colour + "\" stroke-width=\"2\"");
            for (double v : s.outliers)
                out += "<circle cx=\"" + Px(cx) + "\" cy=\"" + Px(py(v)) + "\" r=\"2\" fill=\"none\" stroke=\"" +
                       colour + "\"/>\n";
            out += "</g>\n";
        }
    }
    return out + "</svg>\n";
}

std::string RenderHistoryPlot(const LinePlot& plot) {
    const auto [xs, ys, names] = Pooled(plot.series);
    auto [xlo, xhi] = RangeOf(xs, false);
    auto [ylo, yhi] = RangeOf(ys, false);
    const Axis x = MakeAxis(xlo, xhi, false, 8, /*whole=*/true);  // record indices
    const Axis y = MakeAxis(std::min(0.0, ylo), yhi, false);      // times from 0: a step reads at its true size
    std::string out = Open("history", plot.title) + Legend(names) + YAxis(y, plot.yLabel) + XAxis(x, plot.xLabel);
    for (size_t i = 0; i < plot.series.size(); ++i) {
        const Series& s = plot.series[i];
        const std::string colour = Colour(i);
        out += "<g class=\"series\"" + Attr("data-series", s.name) + Attr("data-points", std::to_string(s.y.size())) +
               ">\n";
        std::string points;
        for (size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
            if (!points.empty()) points += ' ';
            points += Px(x.ToPixel(s.x[k], kPlotLeft, kPlotRight)) + "," + Px(y.ToPixel(s.y[k], kPlotBottom, kPlotTop));
        }
        out += "<polyline points=\"" + points + "\" fill=\"none\" stroke=\"" + colour + "\"/>\n";
        for (size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
            const double px = x.ToPixel(s.x[k], kPlotLeft, kPlotRight), py = y.ToPixel(s.y[k], kPlotBottom, kPlotTop);
            out += "<circle cx=\"" + Px(px) + "\" cy=\"" + Px(py) + "\" r=\"2.5\" fill=\"" + colour + "\"" +
                   Attr("data-x", Num(s.x[k])) + Attr("data-y", Num(s.y[k])) + ">";
            if (k < s.pointLabels.size()) out += "<title>" + EscapeXml(s.pointLabels[k]) + "</title>";
            out += "</circle>\n";
        }
        for (size_t k : s.marks) {
            if (k >= s.x.size() || k >= s.y.size()) continue;
            const double px = x.ToPixel(s.x[k], kPlotLeft, kPlotRight), py = y.ToPixel(s.y[k], kPlotBottom, kPlotTop);
            out += "<g class=\"change-point\"" + Attr("data-change-point", Num(s.x[k])) + ">" +
                   Line(px, kPlotTop, px, kPlotBottom, " stroke=\"" + colour + "\" stroke-dasharray=\"4 3\"") +
                   "<circle cx=\"" + Px(px) + "\" cy=\"" + Px(py) + "\" r=\"6\" fill=\"none\" stroke=\"" + colour +
                   "\" stroke-width=\"2\"/></g>\n";
        }
        out += "</g>\n";
    }
    return out + "</svg>\n";
}

std::vector<std::pair<double, double>> ParetoFront(std::vector<std::pair<double, double>> points) {
    // Sorted by x, then y: a point is on the front when its y is below every y before it.
    std::sort(points.begin(), points.end());
    std::vector<std::pair<double, double>> front;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& p : points)
        if (p.second < best) {
            front.push_back(p);
            best = p.second;
        }
    return front;
}

std::string RenderParetoPlot(const ScatterPlot& plot) {
    const auto [xs, ys, names] = Pooled(plot.series);
    auto [xlo, xhi] = RangeOf(xs, plot.logX);
    const bool logX = plot.logX && xlo <= xhi && RangeOf(xs, false).first > 0;
    if (!logX) std::tie(xlo, xhi) = RangeOf(xs, false);
    auto [ylo, yhi] = RangeOf(ys, plot.logY);
    const bool logY = plot.logY && ylo <= yhi && RangeOf(ys, false).first > 0;
    if (!logY) std::tie(ylo, yhi) = RangeOf(ys, false);
    const Axis x = MakeAxis(xlo, xhi, logX), y = MakeAxis(logY ? ylo : std::min(0.0, ylo), yhi, logY);
    std::string out = Open("pareto", plot.title) + Legend(names) + YAxis(y, plot.yLabel) + XAxis(x, plot.xLabel);
    auto px = [&](double v) { return x.ToPixel(v, kPlotLeft, kPlotRight); };
    auto py = [&](double v) { return y.ToPixel(v, kPlotBottom, kPlotTop); };
    if (!plot.front.empty()) {
        std::string points;
        for (const auto& [fx, fy] : plot.front) points += (points.empty() ? "" : " ") + Px(px(fx)) + "," + Px(py(fy));
        out += "<polyline class=\"front\"" + Attr("data-points", std::to_string(plot.front.size())) + " points=\"" +
               points + "\" fill=\"none\" stroke=\"#000\" stroke-dasharray=\"5 4\"/>\n";
        for (const auto& [fx, fy] : plot.front)
            out += "<circle class=\"front-point\" cx=\"" + Px(px(fx)) + "\" cy=\"" + Px(py(fy)) +
                   "\" r=\"7\" fill=\"none\" stroke=\"#000\"/>\n";
    }
    for (size_t i = 0; i < plot.series.size(); ++i) {
        const Series& s = plot.series[i];
        out += "<g class=\"series\"" + Attr("data-series", s.name) + Attr("data-points", std::to_string(s.y.size())) +
               ">\n";
        for (size_t k = 0; k < s.x.size() && k < s.y.size(); ++k) {
            out += "<circle cx=\"" + Px(px(s.x[k])) + "\" cy=\"" + Px(py(s.y[k])) + "\" r=\"3.5\" fill=\"" + Colour(i) +
                   "\"" + Attr("data-x", Num(s.x[k])) + Attr("data-y", Num(s.y[k])) + ">";
            if (k < s.pointLabels.size()) out += "<title>" + EscapeXml(s.pointLabels[k]) + "</title>";
            out += "</circle>\n";
        }
        out += "</g>\n";
    }
    return out + "</svg>\n";
}

}  // namespace cb::html
