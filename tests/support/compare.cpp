#include "compare.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace sdfkit::test {

double pearson(std::span<const float> a, std::span<const float> b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n == 0) return 0.0;
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= n;
  mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  if (saa <= 0 || sbb <= 0) return 0.0;
  return sab / std::sqrt(saa * sbb);
}

namespace {
std::vector<double> relative(std::span<const float> a, std::span<const float> b, bool absolute) {
  std::vector<double> r;
  const std::size_t n = std::min(a.size(), b.size());
  r.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (b[i] == 0.0f) continue;
    const double d = (static_cast<double>(a[i]) - b[i]) / std::fabs(static_cast<double>(b[i]));
    r.push_back(absolute ? std::fabs(d) : d);
  }
  return r;
}
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * (v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}
}  // namespace

double median_relative_difference(std::span<const float> a, std::span<const float> b) {
  return quantile(relative(a, b, true), 0.5);
}
double quantile_relative_difference(std::span<const float> a, std::span<const float> b, double q) {
  return quantile(relative(a, b, true), q);
}
double median_signed_relative_difference(std::span<const float> a, std::span<const float> b) {
  return quantile(relative(a, b, false), 0.5);
}

}  // namespace sdfkit::test
