#pragma once
// Test-side names for the engine's field comparison (sdfkit/post/compare.hpp), kept so tests
// read as assertions: backend against reference, rotated against unrotated.

#include <span>

namespace sdfkit::test {

// Pearson correlation coefficient; 0 when either side is constant.
double pearson(std::span<const float> a, std::span<const float> b);
// Median over points of |a - b| / |b| (b the reference; points with b == 0 skipped).
double median_relative_difference(std::span<const float> a, std::span<const float> b);
// The q-quantile (0..1, nearest rank) of |a - b| / |b|.
double quantile_relative_difference(std::span<const float> a, std::span<const float> b, double q);
// Median of (a - b) / b: the signed bias.
double median_signed_relative_difference(std::span<const float> a, std::span<const float> b);

}  // namespace sdfkit::test
