#include "compare.hpp"

#include "sdfkit/post/compare.hpp"

#include <cmath>

namespace sdfkit::test {

double pearson(std::span<const float> a, std::span<const float> b) { return sdfkit::pearson(a, b); }

double median_relative_difference(std::span<const float> a, std::span<const float> b) {
  return compare_fields(a, b).median_relative;
}

double quantile_relative_difference(std::span<const float> a, std::span<const float> b, double q) {
  std::vector<double> r = relative_differences(a, b);
  for (double& x : r) x = std::fabs(x);
  return quantile(std::move(r), q);
}

double median_signed_relative_difference(std::span<const float> a, std::span<const float> b) {
  return compare_fields(a, b).median_signed_relative;
}

}  // namespace sdfkit::test
