#include "sdfkit/core/sdf.hpp"
#include "sdfkit/core/shapes.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace sdfkit;

TEST(Fill, GapsTakeTheMeanOfValuedNeighboursRingByRing) {
  // A strip of vertices 0-1-2-3-4 (triangles along a line): only vertex 0 and 4 have values.
  Mesh m;
  for (int i = 0; i < 5; ++i) {
    m.positions.push_back({float(i), 0, 0});
    m.positions.push_back({float(i), 1, 0});
  }
  for (std::uint32_t i = 0; i < 4; ++i) {
    m.triangles.push_back({2 * i, 2 * i + 2, 2 * i + 1});
    m.triangles.push_back({2 * i + 1, 2 * i + 2, 2 * i + 3});
  }
  RawSdf raw;
  raw.values.assign(10, 0.0f);
  raw.kept_rays.assign(10, 0u);
  raw.values[0] = 2.0f;
  raw.kept_rays[0] = 5;
  raw.values[9] = 4.0f;
  raw.kept_rays[9] = 5;
  raw.values[5] = NAN;  // a NaN with a ray count still counts as no value
  raw.kept_rays[5] = 3;
  const SdfField f = finish_field(m, SdfDomain::Vertex, raw);
  EXPECT_EQ(f.filled_count, 8u);
  for (float v : f.values) {
    EXPECT_TRUE(std::isfinite(v));
    EXPECT_GE(v, 2.0f);
    EXPECT_LE(v, 4.0f);
  }
  EXPECT_FLOAT_EQ(f.values[1], 2.0f);  // vertex 1 touches only vertex 0 among valued points
  EXPECT_EQ(f.filled[0], 0);
  EXPECT_EQ(f.filled[5], 1);
}

TEST(Fill, ComponentWithoutValuesGetsGlobalMean) {
  Mesh a = shapes::box(1, 1, 1, 1);
  const Mesh b = shapes::box(1, 1, 1, 1);
  const auto off = static_cast<std::uint32_t>(a.positions.size());
  for (auto p : b.positions) a.positions.push_back(p + glm::vec3(5, 0, 0));
  for (auto t : b.triangles) a.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
  RawSdf raw;
  raw.values.assign(a.positions.size(), 0.0f);
  raw.kept_rays.assign(a.positions.size(), 0u);
  for (std::uint32_t i = 0; i < off; ++i) {
    raw.values[i] = 1.0f + i;
    raw.kept_rays[i] = 1;
  }
  const SdfField f = finish_field(a, SdfDomain::Vertex, raw);
  const float mean = (1.0f + off) / 2.0f;
  for (std::uint32_t i = off; i < a.positions.size(); ++i) EXPECT_FLOAT_EQ(f.values[i], mean);
}

TEST(Fill, NothingValuedGivesZeros) {
  const Mesh m = shapes::box(1, 1, 1, 1);
  RawSdf raw;
  raw.values.assign(m.triangles.size(), 0.0f);
  raw.kept_rays.assign(m.triangles.size(), 0u);
  const SdfField f = finish_field(m, SdfDomain::Face, raw);
  EXPECT_EQ(f.filled_count, m.triangles.size());
  for (float v : f.values) EXPECT_EQ(v, 0.0f);
}

TEST(Normalized, MapsToUnitRange) {
  const float v[] = {2, 4, 3};
  const auto n = normalized(v);
  EXPECT_FLOAT_EQ(n[0], 0.0f);
  EXPECT_FLOAT_EQ(n[1], 1.0f);
  EXPECT_FLOAT_EQ(n[2], 0.5f);
  const float c[] = {3, 3};
  for (float x : normalized(c)) EXPECT_EQ(x, 0.0f);
}

TEST(Query, InvalidPointsAreDegenerateFacesAndIsolatedVertices) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {7, 7, 7}};
  m.triangles = {{0, 1, 2}, {0, 1, 3}};
  const SdfQuery v = make_query(m, SdfDomain::Vertex);
  EXPECT_EQ(v.valid, (std::vector<std::uint8_t>{1, 1, 1, 0, 0}));
  const SdfQuery f = make_query(m, SdfDomain::Face);
  EXPECT_EQ(f.valid, (std::vector<std::uint8_t>{1, 0}));
  EXPECT_GT(f.origin_offset, 0.0f);
}

TEST(Query, VertexOriginsViewTheMeshAndFaceOriginsOutliveCopies) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  // The vertex query's points are the mesh's own array (no 12 bytes per vertex beside it).
  const SdfQuery v = make_query(m, SdfDomain::Vertex);
  EXPECT_EQ(v.origins.data(), m.positions.data());
  EXPECT_EQ(v.size(), m.positions.size());
  EXPECT_EQ(v.origin_storage, nullptr);
  // The face query's centroids are its own, and a copy made before the original is gone still
  // reads them.
  SdfQuery copy;
  {
    const SdfQuery f = make_query(m, SdfDomain::Face);
    ASSERT_NE(f.origin_storage, nullptr);
    EXPECT_EQ(f.origins.data(), f.origin_storage->data());
    copy = f;
  }
  ASSERT_EQ(copy.size(), 4u);
  EXPECT_EQ(copy.origins[3], (m.positions[1] + m.positions[2] + m.positions[3]) / 3.0f);
  EXPECT_EQ(copy.origins[0], (m.positions[0] + m.positions[2] + m.positions[1]) / 3.0f);
}
