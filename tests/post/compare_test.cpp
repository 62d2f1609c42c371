#include "sdfkit/post/compare.hpp"

#include <gtest/gtest.h>

using namespace sdfkit;

TEST(Compare, IdenticalFields) {
  const std::vector<float> a = {1, 2, 3, 4};
  const FieldComparison c = compare_fields(a, a);
  EXPECT_NEAR(c.pearson, 1.0, 1e-12);
  EXPECT_EQ(c.median_relative, 0.0);
  EXPECT_EQ(c.max_relative, 0.0);
}

TEST(Compare, ScaledFieldHasPerfectCorrelationAndKnownDifference) {
  const std::vector<float> b = {1, 2, 3, 4, 5};
  std::vector<float> a;
  for (float x : b) a.push_back(1.1f * x);
  const FieldComparison c = compare_fields(a, b);
  EXPECT_NEAR(c.pearson, 1.0, 1e-6);
  EXPECT_NEAR(c.median_relative, 0.1, 1e-6);
  EXPECT_NEAR(c.median_signed_relative, 0.1, 1e-6);
  EXPECT_NEAR(c.median_signed, 0.3, 1e-6);
}

TEST(Compare, AnticorrelatedAndConstant) {
  const std::vector<float> a = {1, 2, 3}, b = {3, 2, 1}, k = {2, 2, 2};
  EXPECT_NEAR(pearson(a, b), -1.0, 1e-12);
  EXPECT_EQ(pearson(a, k), 0.0);
}

TEST(Compare, QuantileIsNearestRank) {
  EXPECT_EQ(quantile({5, 1, 3}, 0.5), 3.0);
  EXPECT_EQ(quantile({}, 0.5), 0.0);
  EXPECT_EQ(quantile({1, 2, 3, 4, 5}, 1.0), 5.0);
}

TEST(Compare, HistogramClampsIntoTheEnds) {
  const std::vector<float> v = {-1, 0, 0.5f, 0.99f, 1, 7};
  const auto h = histogram(v, 0, 1, 2);
  EXPECT_EQ(h[0], 2u);
  EXPECT_EQ(h[1], 4u);
}
