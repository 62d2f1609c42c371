// The Embree reference on real meshes from CGAL's data set: sane values everywhere, invariance
// under rotation, scaling and translation, per-vertex and per-face fields that agree, and the
// open and degenerate meshes of the set.
#include "analytic.hpp"
#include "compare.hpp"

#include "sdfkit/core/topology.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>

using namespace sdfkit;
using reference::EmbreeBackend;

namespace {

Mesh load(const std::string& name) { return io::load_asset(test::data_mesh(name)).mesh; }

RawSdf run(const Mesh& m, SdfDomain domain = SdfDomain::Vertex) {
  EmbreeBackend b;
  b.set_mesh(m);
  SdfOptions o;
  o.domain = domain;
  return b.compute(make_query(m, domain), o);
}

Mesh with_transform(const Mesh& m, const glm::mat4& t) {
  float f[16];
  std::memcpy(f, glm::value_ptr(t), sizeof f);
  return transformed(m, f);
}

std::uint64_t total_kept(const RawSdf& r) {
  return std::accumulate(r.kept_rays.begin(), r.kept_rays.end(), std::uint64_t{0});
}

// Closes the one hole of `m` (a boundary loop) with a fan, oriented like the rest of the mesh.
Mesh close_single_hole(const Mesh& m) {
  // Directed boundary edges a -> b: used by one triangle in that direction and none reversed.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const Triangle& t : m.triangles)
    for (int k = 0; k < 3; ++k) directed[{t[k], t[(k + 1) % 3]}]++;
  std::map<std::uint32_t, std::uint32_t> next;
  for (const auto& [e, count] : directed)
    if (!directed.contains({e.second, e.first})) next[e.first] = e.second;
  Mesh out = m;
  if (next.empty()) return out;
  std::vector<std::uint32_t> loop{next.begin()->first};
  while (next.at(loop.back()) != loop.front()) loop.push_back(next.at(loop.back()));
  // The hole's triangles run the loop backwards.
  for (std::size_t k = 1; k + 1 < loop.size(); ++k)
    out.triangles.push_back({loop[0], loop[k + 1], loop[k]});
  return out;
}

}  // namespace

TEST(EmbreeRealMeshes, SaneValuesPerVertexAndPerFace) {
  // Every point gets a value (at most one face in a thousand has all its rays dropped), and
  // every value is positive and below the bounding-box diagonal.
  // The two large meshes per vertex only, to keep the test short.
  for (const char* name : {"cow.off", "elephant.off", "bunny00.off", "armadillo.off"}) {
    SCOPED_TRACE(name);
    const Mesh m = load(name);
    const float diagonal = bounding_box(m.positions).diagonal();
    const bool large = m.face_count() > 20000;
    for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
      if (large && domain == SdfDomain::Face) continue;
      const SdfQuery q = make_query(m, domain);
      const RawSdf r = run(m, domain);
      std::size_t valid = 0, valued = 0;
      for (std::size_t i = 0; i < q.size(); ++i) {
        ASSERT_TRUE(std::isfinite(r.values[i])) << i;
        if (!q.valid[i]) continue;
        ++valid;
        if (r.kept_rays[i] == 0) continue;
        ++valued;
        EXPECT_GT(r.values[i], 0.0f) << i;
        EXPECT_LT(r.values[i], diagonal) << i;
      }
      EXPECT_GE(valued, valid - valid / 1000);
    }
  }
}

TEST(EmbreeRealMeshes, RotationNoiseIsSamplingNoiseThatShrinksWithMoreRays) {
  // A rotated mesh is probed at other ray azimuths (the tangent frame is not
  // rotation-equivariant). On the cow, measured median |rel. diff| 2.1% at 30 rays, 0.73% at 120
  // and 0.27% at 480 (Pearson 0.990, 0.9989, 0.9998): noise of the 30-ray sampling, which
  // shrinks as rays are added, not a systematic change.
  const Mesh m = load("cow.off");
  const Mesh rotated =
      with_transform(m, glm::rotate(glm::mat4(1.0f), 1.1f, glm::normalize(glm::vec3(0.3f, 1.0f, -0.5f))));
  double median_at[2] = {0, 0};
  int k = 0;
  for (int rays : {30, 120}) {
    SdfOptions o;
    o.rays = rays;
    EmbreeBackend b;
    b.set_mesh(m);
    const RawSdf a = b.compute(make_query(m, SdfDomain::Vertex), o);
    b.set_mesh(rotated);
    const RawSdf r = b.compute(make_query(rotated, SdfDomain::Vertex), o);
    median_at[k++] = test::median_relative_difference(r.values, a.values);
    EXPECT_GT(test::pearson(r.values, a.values), rays == 30 ? 0.98 : 0.995) << rays;
  }
  EXPECT_LT(median_at[0], 0.03);
  EXPECT_LT(median_at[1], 0.01);
  EXPECT_LT(median_at[1], 0.5 * median_at[0]);
}

TEST(EmbreeRealMeshes, ScalesWithTheMeshAndIgnoresTranslation) {
  // Directions do not change and the start offset follows the bounding box, so values scale
  // exactly up to float rounding. A few rays whose hit normal is within rounding of the 90-degree
  // cut-off may flip (measured: 99% of points within 6e-5, a handful off by up to 30%).
  const Mesh m = load("elephant.off");
  const RawSdf a = run(m);
  const RawSdf b = run(with_transform(
      m, glm::translate(glm::scale(glm::mat4(1.0f), glm::vec3(3.0f)), glm::vec3(5.0f, -2.0f, 1.0f))));
  std::vector<float> scaled(a.values);
  for (float& x : scaled) x *= 3.0f;
  EXPECT_LT(test::median_relative_difference(b.values, scaled), 1e-5);
  EXPECT_LT(test::quantile_relative_difference(b.values, scaled, 0.99), 1e-3);
}

TEST(EmbreeRealMeshes, PerVertexAndPerFaceFieldsAgree) {
  // A vertex's value against the mean of its faces' values: the same thickness measured from
  // nearby points (measured Pearson 0.975 cow, 0.983 elephant, 0.988 armadillo).
  for (const char* name : {"cow.off", "elephant.off"}) {
    const Mesh m = load(name);
    const RawSdf v = run(m), f = run(m, SdfDomain::Face);
    std::vector<double> sum(m.vertex_count(), 0.0);
    std::vector<int> count(m.vertex_count(), 0);
    for (std::size_t i = 0; i < m.face_count(); ++i)
      for (std::uint32_t k : m.triangles[i]) {
        sum[k] += f.values[i];
        ++count[k];
      }
    std::vector<float> face_mean(m.vertex_count());
    for (std::size_t i = 0; i < face_mean.size(); ++i)
      face_mean[i] = count[i] ? static_cast<float>(sum[i] / count[i]) : 0.0f;
    EXPECT_GT(test::pearson(face_mean, v.values), 0.95) << name;
    EXPECT_LT(test::median_relative_difference(face_mean, v.values), 0.06) << name;
  }
}

TEST(EmbreeRealMeshes, OpenCubeHasFiniteValuesAndFewerRays) {
  // CGAL's cube-ouvert: a 2-cube without one side, plus an isolated vertex.
  const Mesh open = load("cube-ouvert.off");
  const MeshReport report = analyze(open);
  ASSERT_EQ(report.boundary_edges, 4u);
  ASSERT_EQ(report.isolated_vertices, 1u);
  const Mesh closed = close_single_hole(open);
  ASSERT_EQ(analyze(closed).boundary_edges, 0u);
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    SdfOptions o;
    o.domain = domain;
    const RawSdf ro = run(open, domain), rc = run(closed, domain);
    EXPECT_LT(total_kept(ro), total_kept(rc));
    EmbreeBackend b;
    b.set_mesh(open);
    const SdfField field = compute_sdf(b, open, o);
    for (float x : field.values) {
      EXPECT_TRUE(std::isfinite(x));
      EXPECT_GT(x, 0.0f);  // the isolated vertex gets the mean of the valued ones
      EXPECT_LT(x, 2.0f * std::sqrt(3.0f));
    }
    if (domain == SdfDomain::Vertex) {
      EXPECT_EQ(field.filled_count, 1u);
    }
  }
}

TEST(EmbreeRealMeshes, FlatMeshWithDegenerateTrianglesGivesZerosNotNaN) {
  // CGAL's degtri_sliding: a flat patch (z = 0) with collinear triangles. Nothing is ever hit,
  // the degenerate faces are no origins, and the fill has nothing to spread: zeros.
  const Mesh m = load("degtri_sliding.off");
  const std::vector<std::uint8_t> degenerate = degenerate_faces(m);
  ASSERT_EQ(std::count(degenerate.begin(), degenerate.end(), 1), 4);
  for (SdfDomain domain : {SdfDomain::Vertex, SdfDomain::Face}) {
    SdfOptions o;
    o.domain = domain;
    EmbreeBackend b;
    b.set_mesh(m);
    const SdfQuery q = make_query(m, domain);
    if (domain == SdfDomain::Face) {
      for (std::size_t f = 0; f < m.face_count(); ++f) EXPECT_EQ(q.valid[f], !degenerate[f]) << f;
    }
    const SdfField field = compute_sdf(b, m, o);
    EXPECT_EQ(field.filled_count, field.values.size());
    for (float x : field.values) EXPECT_EQ(x, 0.0f);
  }
}
