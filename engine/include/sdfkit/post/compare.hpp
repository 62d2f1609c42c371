#pragma once
// Comparing two per-point fields on the same mesh (`sdfkit compare`, backend agreement tests,
// rotation invariance): correlation, relative differences, histograms.

#include <cstddef>
#include <span>
#include <vector>

namespace sdfkit {

// Pearson correlation coefficient of a and b (same length); 0 when either is constant.
double pearson(std::span<const float> a, std::span<const float> b);

// Per point (a - b) / |b|, b the reference; points with b == 0 are skipped.
std::vector<double> relative_differences(std::span<const float> a, std::span<const float> b);

// Nearest-rank q-quantile (q in [0, 1]) of the values; 0 for empty input.
double quantile(std::vector<double> values, double q);

struct FieldComparison {
  std::size_t points = 0;
  double pearson = 0;
  double median_relative = 0;     // median |a - b| / |b|
  double p95_relative = 0;        // 95th percentile of |a - b| / |b|
  double max_relative = 0;
  double median_signed_relative = 0;  // median (a - b) / |b|
  double median_signed = 0;       // median a - b, model units
};
FieldComparison compare_fields(std::span<const float> a, std::span<const float> b);

// Counts of values in `bins` equal bins over [lo, hi]; values outside are clamped into the ends.
std::vector<std::size_t> histogram(std::span<const float> values, float lo, float hi, int bins);

}  // namespace sdfkit
