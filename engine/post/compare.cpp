#include "sdfkit/post/compare.hpp"

#include <algorithm>
#include <cmath>

namespace sdfkit {

double pearson(std::span<const float> a, std::span<const float> b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n == 0) return 0.0;
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= static_cast<double>(n);
  mb /= static_cast<double>(n);
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  if (saa <= 0 || sbb <= 0) return 0.0;
  return sab / std::sqrt(saa * sbb);
}

std::vector<double> relative_differences(std::span<const float> a, std::span<const float> b) {
  std::vector<double> r;
  const std::size_t n = std::min(a.size(), b.size());
  r.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (b[i] == 0.0f) continue;
    r.push_back((static_cast<double>(a[i]) - b[i]) / std::fabs(static_cast<double>(b[i])));
  }
  return r;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}

FieldComparison compare_fields(std::span<const float> a, std::span<const float> b) {
  FieldComparison c;
  c.points = std::min(a.size(), b.size());
  c.pearson = pearson(a, b);
  std::vector<double> signed_rel = relative_differences(a, b);
  std::vector<double> abs_rel(signed_rel.size());
  std::transform(signed_rel.begin(), signed_rel.end(), abs_rel.begin(), [](double x) { return std::fabs(x); });
  c.median_relative = quantile(abs_rel, 0.5);
  c.p95_relative = quantile(abs_rel, 0.95);
  c.max_relative = abs_rel.empty() ? 0.0 : *std::max_element(abs_rel.begin(), abs_rel.end());
  c.median_signed_relative = quantile(std::move(signed_rel), 0.5);
  std::vector<double> diff(c.points);
  for (std::size_t i = 0; i < c.points; ++i) diff[i] = static_cast<double>(a[i]) - b[i];
  c.median_signed = quantile(std::move(diff), 0.5);
  return c;
}

std::vector<std::size_t> histogram(std::span<const float> values, float lo, float hi, int bins) {
  std::vector<std::size_t> h(static_cast<std::size_t>(std::max(1, bins)), 0);
  const float range = hi - lo;
  for (float v : values) {
    if (!std::isfinite(v)) continue;
    int k = range > 0 ? static_cast<int>((v - lo) / range * static_cast<float>(h.size())) : 0;
    k = std::clamp(k, 0, static_cast<int>(h.size()) - 1);
    ++h[static_cast<std::size_t>(k)];
  }
  return h;
}

}  // namespace sdfkit
