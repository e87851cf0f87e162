// The Pareto front of `cloudbench sweep` and `merge` over measured rows, with
// ties within the timing noise (docs/accuracy.md, "Sweeps: which rows, the
// Pareto front and ties").
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "harness/accuracy/Measurement.h"

namespace cb {

// The error metrics a sweep's front may use: max, mean and p99 of |error| (lower is better) and psnr (the
// renderers' images only; higher is better).
bool IsSweepMetric(std::string_view metric);
// Whether rows of stages `a` and `b` share a front: a stage's own, and every renderer's together (their images
// answer to one reference).
bool SameParetoFront(Stage a, Stage b);
// Whether `metric` is defined for a row of `stage` (psnr: renderers only).
bool MetricApplies(std::string_view metric, Stage stage);

// An ok row's error on `metric` as a loss, lower is better: the statistic over all elements, or -PSNR in dB
// (-infinity for an image equal to the reference, whose PSNR is infinite).
double MetricLoss(const Row& row, std::string_view metric);

// Whether two ok rows' errors on `metric` print the same in the tables (kErrorFormat, kPsnrFormat): a
// difference the tables do not show is no difference on the front.
bool ErrorsAlike(const Row& a, const Row& b, std::string_view metric);

// Whether ok row `a` beats ok row `b` on the front: a's loss is at most b's (or alike) and b is not clearly
// faster, and a is clearly faster or its loss is smaller and not alike. Clearly faster: its time's q3 is below
// the other's q1 (the q1-q3 intervals do not overlap).
bool ParetoBeats(const Row& a, const Row& b, std::string_view metric);

// Marks the front per stage (the renderers share one: they make the same image): a row is on it (pareto)
// when it is ok, its metric applies, and no other such row beats it; a front row whose error is alike another
// front row's and whose q1-q3 time interval overlaps that row's is a tie (paretoTie) for both.
void MarkPareto(std::vector<Row>& rows, const std::string& metric);

// Whether an ok row's error on `metric` is within `bound`: |error| at most `bound`, or for psnr at least
// `bound` dB.
bool WithinBound(const Row& row, std::string_view metric, double bound);

// The answer to "the fastest setting within an error bound": per front (a stage; the renderers together) and
// backend, the ok row within `bound` with the least median time (the first on a tie), in the order the fronts
// and backends first appear in `rows`; a front and backend with no row within the bound has none.
std::vector<const Row*> FastestWithin(const std::vector<Row>& rows, const std::string& metric, double bound);

}  // namespace cb
