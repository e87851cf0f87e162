#include "harness/accuracy/SweepPareto.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "core/plan/StageGraph.h"

namespace cb {
namespace {

bool SweepClearlyFaster(const Row& a, const Row& b) { return a.result.timeMs.q3 < b.result.timeMs.q1; }

bool SweepOnFront(const Row& r, std::string_view metric) {
    return r.result.status == "ok" && MetricApplies(metric, r.stage);
}

// The row's error as the tables print it (kErrorFormat, or kPsnrFormat for psnr; "inf" for an infinite PSNR).
std::string PrintedError(const Row& r, std::string_view metric) {
    const double loss = MetricLoss(r, metric);
    if (metric == "psnr" && std::isinf(loss)) return "inf";
    char text[64];
    std::snprintf(text, sizeof text, metric == "psnr" ? kPsnrFormat : kErrorFormat, metric == "psnr" ? -loss : loss);
    return text;
}

}  // namespace

bool SameParetoFront(Stage a, Stage b) { return a == b || (Describe(a).renderer && Describe(b).renderer); }

bool IsSweepMetric(std::string_view metric) {
    return metric == "max" || metric == "mean" || metric == "p99" || metric == "psnr";
}

bool MetricApplies(std::string_view metric, Stage stage) {
    return IsSweepMetric(metric) && (metric != "psnr" || Describe(stage).renderer);
}

double MetricLoss(const Row& row, std::string_view metric) {
    const ErrorStats& e = row.result.all;
    if (metric == "psnr") return row.result.psnrDb ? -*row.result.psnrDb : -std::numeric_limits<double>::infinity();
    return metric == "mean" ? e.mean : metric == "p99" ? e.p99 : e.max;
}

bool ErrorsAlike(const Row& a, const Row& b, std::string_view metric) {
    return PrintedError(a, metric) == PrintedError(b, metric);
}

bool ParetoBeats(const Row& a, const Row& b, std::string_view metric) {
    const double la = MetricLoss(a, metric), lb = MetricLoss(b, metric);
    const bool alike = ErrorsAlike(a, b, metric);
    if (!(la <= lb || alike) || SweepClearlyFaster(b, a)) return false;
    return SweepClearlyFaster(a, b) || (la < lb && !alike);
}

void MarkPareto(std::vector<Row>& rows, const std::string& metric) {
    for (Row& r : rows) {
        r.pareto = false;
        r.paretoTie = false;
        if (!SweepOnFront(r, metric)) continue;
        r.pareto = true;
        for (const Row& o : rows)
            if (&o != &r && SweepOnFront(o, metric) && SameParetoFront(o.stage, r.stage) &&
                ParetoBeats(o, r, metric)) {
                r.pareto = false;
                break;
            }
    }
    for (Row& r : rows) {
        if (!r.pareto) continue;
        for (const Row& o : rows)
            if (&o != &r && o.pareto && SameParetoFront(o.stage, r.stage) && ErrorsAlike(o, r, metric) &&
                !SweepClearlyFaster(o, r) && !SweepClearlyFaster(r, o)) {
                r.paretoTie = true;
                break;
            }
    }
}

bool WithinBound(const Row& row, std::string_view metric, double bound) {
    return SweepOnFront(row, metric) && MetricLoss(row, metric) <= (metric == "psnr" ? -bound : bound);
}

std::vector<const Row*> FastestWithin(const std::vector<Row>& rows, const std::string& metric, double bound) {
    std::vector<const Row*> fastest;  // one per front and backend, in first-appearance order
    for (const Row& r : rows) {
        if (!WithinBound(r, metric, bound)) continue;
        auto same = std::ranges::find_if(
            fastest, [&](const Row* f) { return f->backend == r.backend && SameParetoFront(f->stage, r.stage); });
        if (same == fastest.end())
            fastest.push_back(&r);
        else if (r.result.timeMs.median < (*same)->result.timeMs.median)
            *same = &r;
    }
    return fastest;
}

}  // namespace cb
