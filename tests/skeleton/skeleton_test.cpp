// Skeletons of shapes with a known medial axis and topology, computed with the Embree reference
// as the SDF backend (recomputed at every contraction iteration).

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"
#include "sdfkit/skeleton/models.hpp"
#include "sdfkit/skeleton/skeleton.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "analytic.hpp"

#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>

using namespace sdfkit;
namespace sk = sdfkit::skeleton;
namespace models = sdfkit::skeleton::models;

namespace {

sk::Skeleton run(const Mesh& mesh, bool sdf_term, bool sheets) {
  reference::EmbreeBackend backend;
  sk::ContractionOptions co;
  co.sdf_term = sdf_term;
  sk::SkeletonOptions so;
  so.sheets = sheets;
  return sk::extract(mesh, &backend, co, so);
}

std::vector<int> degrees(const sk::Skeleton& s) {
  std::vector<int> d(s.nodes.size(), 0);
  for (const auto& e : s.edges) ++d[e[0]], ++d[e[1]];
  return d;
}

int count_degree(const sk::Skeleton& s, int degree) {
  const auto d = degrees(s);
  return static_cast<int>(std::count(d.begin(), d.end(), degree));
}

// Generalized winding number of a closed mesh at p (solid angles, Van Oosterom & Strackee):
// independent of the library's ray-based inside test.
double winding_number(const Mesh& m, const glm::vec3& p) {
  double total = 0.0;
  for (const Triangle& t : m.triangles) {
    const glm::dvec3 a = glm::dvec3(m.positions[t[0]]) - glm::dvec3(p);
    const glm::dvec3 b = glm::dvec3(m.positions[t[1]]) - glm::dvec3(p);
    const glm::dvec3 c = glm::dvec3(m.positions[t[2]]) - glm::dvec3(p);
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double num = glm::dot(a, glm::cross(b, c));
    const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
    total += 2.0 * std::atan2(num, den);
  }
  return total / (4.0 * M_PI);
}

// Every input vertex in exactly one node; every node inside the solid.
void expect_partition_and_inside(const Mesh& mesh, const sk::Skeleton& s) {
  std::vector<int> count(mesh.positions.size(), 0);
  for (const sk::Node& n : s.nodes) {
    EXPECT_FALSE(n.vertices.empty());
    for (std::uint32_t v : n.vertices) ++count[v];
    EXPECT_GT(winding_number(mesh, n.position), 0.5)
        << "node at " << n.position.x << ' ' << n.position.y << ' ' << n.position.z;
    EXPECT_TRUE(std::isfinite(n.radius));
    EXPECT_GT(n.radius, 0.0f);
  }
  for (int c : count) ASSERT_EQ(c, 1);
  for (const auto& e : s.edges) {
    ASSERT_LT(e[0], e[1]);
    ASSERT_LT(e[1], s.nodes.size());
  }
}

// Connected parts of the skeleton (curve edges and sheet triangles).
int parts(const sk::Skeleton& s) {
  std::vector<std::uint32_t> p(s.nodes.size());
  std::iota(p.begin(), p.end(), 0u);
  auto find = [&](std::uint32_t x) {
    while (p[x] != x) x = p[x] = p[p[x]];
    return x;
  };
  for (const auto& e : s.edges) p[find(e[0])] = find(e[1]);
  for (const Triangle& t : s.sheet_triangles) p[find(t[0])] = find(t[1]), p[find(t[1])] = find(t[2]);
  int count = 0;
  for (std::uint32_t i = 0; i < p.size(); ++i) count += find(i) == i;
  return count;
}

double mean_distance(const sk::Skeleton& s, const std::vector<models::Segment>& axis) {
  double sum = 0.0;
  for (const sk::Node& n : s.nodes) sum += models::distance_to(axis, n.position);
  return sum / static_cast<double>(s.nodes.size());
}

}  // namespace

TEST(Skeleton, CapsuleGivesOneCurveNearItsAxis) {
  const float radius = 0.5f, length = 4.0f;
  const Mesh mesh = shapes::capsule(radius, length, 24, 24);
  const sk::Skeleton s = run(mesh, true, true);
  expect_partition_and_inside(mesh, s);
  ASSERT_GE(s.nodes.size(), 2u);
  EXPECT_EQ(s.edges.size(), s.nodes.size() - 1);  // a tree ...
  EXPECT_EQ(sk::cycle_count(s), 0);
  EXPECT_EQ(parts(s), 1);
  EXPECT_EQ(count_degree(s, 1), 2);               // ... with two ends: one curve
  EXPECT_EQ(count_degree(s, 2), static_cast<int>(s.nodes.size()) - 2);
  EXPECT_TRUE(s.sheet_triangles.empty());
  const float total = length + 2.0f * radius;
  for (const sk::Node& n : s.nodes) {
    EXPECT_LT(std::hypot(n.position.x, n.position.y), 0.02f * total);
    EXPECT_LT(std::abs(n.position.z), 0.5f * total);
    EXPECT_NEAR(n.radius, radius, 0.35f * radius);  // SDF/2 of a tube is its radius (ends: less)
  }
  EXPECT_DOUBLE_EQ(s.reliability, 1.0);
}

TEST(Skeleton, TorusGivesOneCycle) {
  const Mesh mesh = shapes::torus(2.0f, 0.5f, 48, 16);
  const sk::Skeleton s = run(mesh, true, true);
  expect_partition_and_inside(mesh, s);
  EXPECT_EQ(sk::cycle_count(s), 1);
  EXPECT_EQ(count_degree(s, 2), static_cast<int>(s.nodes.size()));
  for (const sk::Node& n : s.nodes)
    EXPECT_NEAR(std::hypot(n.position.x, n.position.y), 2.0f, 0.1f);
}

TEST(Skeleton, Genus2GivesTwoCycles) {
  const auto g = models::genus2();
  const sk::Skeleton s = run(g.mesh, true, false);
  expect_partition_and_inside(g.mesh, s);
  EXPECT_EQ(sk::cycle_count(s), 2);
  EXPECT_EQ(parts(s), 1);
  EXPECT_TRUE(s.sheet_triangles.empty());
}

TEST(Skeleton, StarGivesFiveBranchesFromOneJunction) {
  const auto star = models::five_armed_star();
  const sk::Skeleton s = run(star.mesh, true, false);
  expect_partition_and_inside(star.mesh, s);
  EXPECT_EQ(sk::cycle_count(s), 0);
  EXPECT_EQ(count_degree(s, 1), 5);
  EXPECT_EQ(count_degree(s, 5), 1);
  EXPECT_EQ(count_degree(s, 1) + count_degree(s, 2) + count_degree(s, 5),
            static_cast<int>(s.nodes.size()));
  // The junction sits at the centre of the star, each end near its arm's end.
  const auto d = degrees(s);
  for (std::size_t i = 0; i < s.nodes.size(); ++i)
    if (d[i] == 5) {
      EXPECT_LT(glm::length(s.nodes[i].position), 0.3f);
    }
}

TEST(Skeleton, SdfTermBringsNodesCloserToTheMedialAxis) {
  const auto star = models::five_armed_star();
  ASSERT_GT(star.mesh.positions.size(), sk::ContractionOptions{}.proxy_vertices);  // the proxy path
  const double with = mean_distance(run(star.mesh, true, false), star.axis);
  const double without = mean_distance(run(star.mesh, false, false), star.axis);
  std::printf("star: mean node distance to the medial axis: with SDF term %.4f, without %.4f\n",
              with, without);
  EXPECT_LT(with, without);
}

TEST(SkeletonContraction, SdfTermContractsTheStarCloserToItsMedialAxis) {
  // The contracted surface itself, over all 3888 vertices (the node comparison above is decided
  // by the one or two of its ~8 nodes nearest the junction).
  const auto star = models::five_armed_star();
  double mean[2], median[2];
  for (int term = 0; term < 2; ++term) {
    reference::EmbreeBackend backend;
    sk::ContractionOptions co;
    co.sdf_term = term == 1;
    const sk::ContractionResult r = sk::contract(star.mesh, &backend, co);
    std::vector<double> d;
    for (const glm::vec3& p : r.contracted.positions) d.push_back(models::distance_to(star.axis, p));
    mean[term] = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(d.size());
    std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
    median[term] = d[d.size() / 2];
  }
  std::printf("star: contracted vertices' distance to the medial axis: with SDF term mean %.4f median "
              "%.4f, without mean %.4f median %.4f\n", mean[1], median[1], mean[0], median[0]);
  EXPECT_LT(mean[1], 0.8 * mean[0]);
  EXPECT_LT(median[1], 0.8 * median[0]);
}

TEST(Skeleton, SheetsMakeTheCAndSShapesFullyReliable) {
  for (const auto& plate : {models::c_shape(), models::s_shape()}) {
    const sk::Skeleton curves = run(plate.mesh, true, false);
    const sk::Skeleton sheets = run(plate.mesh, true, true);
    std::printf("plate: curve reliability %.3f, with sheets %.3f (%zu sheet triangles)\n",
                curves.reliability, sheets.reliability, sheets.sheet_triangles.size());
    EXPECT_LT(curves.reliability, 0.9);  // a curve cannot serve a non-convex cross-section
    EXPECT_DOUBLE_EQ(sheets.reliability, 1.0);
    EXPECT_FALSE(sheets.sheet_triangles.empty());
    EXPECT_EQ(parts(curves), 1);
    EXPECT_EQ(parts(sheets), 1);  // curve and sheet are joined where they touch
    EXPECT_EQ(sk::cycle_count(sheets), 0);  // genus 0: the sheets' triangles close no cycle
    expect_partition_and_inside(plate.mesh, sheets);
  }
}

TEST(Skeleton, OpenMeshIsRefusedWithAClearError) {
  Mesh open = shapes::capsule(0.5f, 2.0f, 16, 8);
  open.triangles.pop_back();
  try {
    run(open, true, true);
    FAIL() << "an open mesh was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("boundary edges"), std::string::npos) << e.what();
  }
}

TEST(Skeleton, SeveralComponentsGiveOnePartEach) {
  Mesh a = shapes::capsule(0.4f, 2.0f, 16, 12);
  const Mesh b = shapes::torus(1.5f, 0.4f, 32, 12);
  const auto offset = static_cast<std::uint32_t>(a.positions.size());
  for (glm::vec3 p : b.positions) a.positions.push_back(p + glm::vec3(5.0f, 0.0f, 0.0f));
  for (Triangle t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const sk::Skeleton s = run(a, true, false);
  expect_partition_and_inside(a, s);
  EXPECT_EQ(sk::cycle_count(s), 1);  // the torus' cycle; the capsule's tree adds none
  EXPECT_EQ(parts(s), 2);
  for (const sk::Node& n : s.nodes) {
    const bool first = n.vertices.front() < offset;
    for (std::uint32_t v : n.vertices) EXPECT_EQ(v < offset, first);  // no node spans both
  }
  for (const auto& e : s.edges)
    EXPECT_EQ(s.nodes[e[0]].vertices.front() < offset, s.nodes[e[1]].vertices.front() < offset);
}

// Vertices no triangle uses (one before the surface's, one after) are not the surface's: the
// skeleton is the one of the surface alone, node for node, with the vertex indices shifted; they
// belong to no node and their SDF is 0. Before, each became a node of its own outside the solid,
// and the far one stretched the bounding box the skeleton's scales come from.
TEST(Skeleton, VerticesNoTriangleUsesAreLeftOut) {
  const Mesh surface = shapes::capsule(0.5f, 3.0f, 16, 12);
  Mesh padded;
  padded.positions.push_back({20.0f, 20.0f, 20.0f});
  padded.positions.insert(padded.positions.end(), surface.positions.begin(), surface.positions.end());
  padded.positions.push_back({-30.0f, 0.0f, 0.0f});
  for (Triangle t : surface.triangles) padded.triangles.push_back({t[0] + 1, t[1] + 1, t[2] + 1});
  const sk::Skeleton a = run(surface, true, true), b = run(padded, true, true);
  ASSERT_EQ(b.nodes.size(), a.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i) {
    EXPECT_EQ(b.nodes[i].position, a.nodes[i].position) << i;
    EXPECT_EQ(b.nodes[i].radius, a.nodes[i].radius) << i;
    ASSERT_EQ(b.nodes[i].vertices.size(), a.nodes[i].vertices.size()) << i;
    for (std::size_t k = 0; k < a.nodes[i].vertices.size(); ++k)
      EXPECT_EQ(b.nodes[i].vertices[k], a.nodes[i].vertices[k] + 1) << i;
  }
  EXPECT_EQ(b.edges, a.edges);
  EXPECT_EQ(b.sheet_triangles.size(), a.sheet_triangles.size());
  ASSERT_EQ(b.sdf.size(), padded.positions.size());
  EXPECT_EQ(b.sdf.front(), 0.0f);
  EXPECT_EQ(b.sdf.back(), 0.0f);
  for (std::size_t v = 0; v < a.sdf.size(); ++v) EXPECT_EQ(b.sdf[v + 1], a.sdf[v]) << v;
  ASSERT_FALSE(b.warnings.empty());
  EXPECT_NE(b.warnings.front().find("2 vertices no triangle uses"), std::string::npos) << b.warnings.front();
  expect_partition_and_inside(surface, a);
}

// cycle_count is the first Betti number of curves plus sheets: a closed sheet (a tetrahedron's
// surface) encloses a void and adds no cycle, a disc adds none, a ring of curve edges or a curve
// edge across a sheet's open wedge adds one.
TEST(Skeleton, CycleCountIsTheFirstBettiNumberOfCurvesAndSheets) {
  auto with_nodes = [](std::size_t n) {
    sk::Skeleton s;
    s.nodes.resize(n);
    return s;
  };
  sk::Skeleton tetra = with_nodes(4);
  tetra.sheet_triangles = {{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {2, 3, 0}};
  EXPECT_EQ(sk::cycle_count(tetra), 0);  // E - V + C - F would be -1
  sk::Skeleton disc = with_nodes(5);  // a fan of three triangles around node 0
  disc.sheet_triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}};
  EXPECT_EQ(sk::cycle_count(disc), 0);
  disc.edges = {{4, 1}};  // closes the open wedge 0-4-1 with a curve edge: one cycle
  EXPECT_EQ(sk::cycle_count(disc), 1);
  sk::Skeleton ring = with_nodes(6);
  ring.edges = {{0, 1}, {1, 2}, {2, 0}, {2, 3}};
  ring.sheet_triangles = {{3, 4, 5}};
  EXPECT_EQ(sk::cycle_count(ring), 1);
  sk::Skeleton two_tetras = with_nodes(8);  // two closed sheets joined by a curve edge
  for (std::uint32_t o : {0u, 4u})
    for (const auto& t : tetra.sheet_triangles) two_tetras.sheet_triangles.push_back({t[0] + o, t[1] + o, t[2] + o});
  two_tetras.edges = {{0, 4}};
  EXPECT_EQ(sk::cycle_count(two_tetras), 0);
}

TEST(Skeleton, JsonAndObjCarryNodesEdgesAndSheets) {
  const auto plate = models::c_shape();
  const sk::Skeleton s = run(plate.mesh, true, true);
  const auto j = nlohmann::json::parse(sk::to_json(s));
  ASSERT_EQ(j["nodes"].size(), s.nodes.size());
  EXPECT_EQ(j["edges"].size(), s.edges.size());
  EXPECT_EQ(j["sheet_triangles"].size(), s.sheet_triangles.size());
  EXPECT_EQ(j["nodes"][0]["vertices"].size(), s.nodes[0].vertices.size());
  EXPECT_FLOAT_EQ(j["nodes"][0]["position"][0].get<float>(), s.nodes[0].position.x);
  std::ostringstream obj;
  sk::write_obj(obj, s);
  std::size_t v = 0, l = 0, f = 0;
  std::istringstream in(obj.str());
  for (std::string line; std::getline(in, line);) {
    v += line.rfind("v ", 0) == 0;
    l += line.rfind("l ", 0) == 0;
    f += line.rfind("f ", 0) == 0;
  }
  EXPECT_EQ(v, s.nodes.size());
  EXPECT_EQ(l, s.edges.size());
  EXPECT_EQ(f, s.sheet_triangles.size());
}

namespace {
// Forwards to the Embree reference and counts the calls: the contraction must keep one session
// (set_mesh once) and move its vertices (update_positions) before every later SDF.
class CountingBackend final : public SdfBackend {
public:
  std::string name() const override { return "counting"; }
  std::string device_name() const override { return inner.device_name(); }
  void set_mesh(const Mesh& m) override { ++set_mesh_calls, inner.set_mesh(m); }
  void update_positions(std::span<const glm::vec3> p) override {
    ++update_calls, inner.update_positions(p);
  }
  RawSdf compute(const SdfQuery& q, const SdfOptions& o) override {
    ++compute_calls;
    return inner.compute(q, o);
  }
  reference::EmbreeBackend inner;
  int set_mesh_calls = 0, update_calls = 0, compute_calls = 0;
};
}  // namespace

TEST(SkeletonContraction, RecomputesTheSdfOnTheContractingMeshInOneSession) {
  const Mesh mesh = shapes::capsule(0.5f, 3.0f, 16, 12);
  CountingBackend backend;
  const sk::ContractionResult r = sk::contract(mesh, &backend, {});
  ASSERT_GE(r.iterations, 3);
  EXPECT_EQ(backend.set_mesh_calls, 1);
  // One SDF per iteration (a rejected last step also measured its SDF first).
  EXPECT_GE(backend.compute_calls, r.iterations);
  EXPECT_LE(backend.compute_calls, r.iterations + 1);
  EXPECT_EQ(backend.update_calls, backend.compute_calls - 1);
  ASSERT_EQ(r.first_sdf.size(), mesh.positions.size());
  ASSERT_EQ(r.last_sdf.size(), mesh.positions.size());
  // The capsule's SDF is about its diameter; the contracted mesh is far thinner.
  std::vector<float> first = r.first_sdf, last = r.last_sdf;
  std::nth_element(first.begin(), first.begin() + first.size() / 2, first.end());
  std::nth_element(last.begin(), last.begin() + last.size() / 2, last.end());
  EXPECT_NEAR(first[first.size() / 2], 1.0f, 0.15f);
  EXPECT_LT(last[last.size() / 2], 0.2f * first[first.size() / 2]);
}

// The holding weights' SDF factor comes from the input's SDF (Initial, the default: the system
// is then assembled and factorized while the iteration's SDF is measured) or from the thinnest
// SDF measured so far (Current: factorized after it). Both contract without NaN, the option is
// honoured (the contracted surfaces differ), and a run repeated gives the same bits.
TEST(SkeletonContraction, HoldingWeightsFromTheInputOrTheCurrentSdf) {
  const auto star = models::five_armed_star();
  auto run_with = [&](sk::HoldingSdf holding) {
    reference::EmbreeBackend backend;
    sk::ContractionOptions co;
    co.holding_sdf = holding;
    return sk::contract(star.mesh, &backend, co);
  };
  const sk::ContractionResult initial = run_with(sk::HoldingSdf::Initial);
  const sk::ContractionResult again = run_with(sk::HoldingSdf::Initial);
  const sk::ContractionResult current = run_with(sk::HoldingSdf::Current);
  for (const auto* r : {&initial, &current}) {
    EXPECT_GE(r->iterations, 3);
    EXPECT_LT(r->area_ratio, 0.5);  // the star stops where a step would grow the area (~0.12-0.15)
    for (const glm::vec3& p : r->contracted.positions) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z));
  }
  EXPECT_EQ(initial.iterations, again.iterations);
  EXPECT_TRUE(initial.contracted.positions == again.contracted.positions);
  float largest = 0.0f;
  for (std::size_t i = 0; i < star.mesh.positions.size(); ++i)
    largest = std::max(largest, glm::length(initial.contracted.positions[i] - current.contracted.positions[i]));
  EXPECT_GT(largest, 1e-3f);
  std::printf("star: Initial %d iterations (area ratio %.4f), Current %d (%.4f), largest difference %.4f\n",
              initial.iterations, initial.area_ratio, current.iterations, current.area_ratio, largest);
}

// Real meshes: real_mesh_test.cpp.

namespace {
// Records the ray count of every SDF the contraction asks for.
class RayCountingBackend final : public SdfBackend {
public:
  std::string name() const override { return "ray-counting"; }
  std::string device_name() const override { return inner.device_name(); }
  void set_mesh(const Mesh& m) override { vertices.push_back(m.positions.size()), inner.set_mesh(m); }
  void update_positions(std::span<const glm::vec3> p) override { inner.update_positions(p); }
  RawSdf compute(const SdfQuery& q, const SdfOptions& o) override {
    rays.push_back(o.rays);
    return inner.compute(q, o);
  }
  reference::EmbreeBackend inner;
  std::vector<int> rays;
  std::vector<std::size_t> vertices;  // per set_mesh call: the mesh's vertex count
};
}  // namespace

TEST(SkeletonContraction, FirstSdfAtFullQualityLaterOnesWithIterationRays) {
  const Mesh mesh = shapes::capsule(0.5f, 3.0f, 16, 12);
  RayCountingBackend backend;
  sk::ContractionOptions o;
  o.sdf.rays = 24;
  o.iteration_rays = 6;
  const sk::ContractionResult r = sk::contract(mesh, &backend, o);
  ASSERT_GE(backend.rays.size(), 3u);
  EXPECT_EQ(backend.rays.front(), 24);
  for (std::size_t i = 1; i < backend.rays.size(); ++i) EXPECT_EQ(backend.rays[i], 6);
  EXPECT_GT(r.sdf_seconds, 0.0);
  EXPECT_GT(r.solve_seconds, 0.0);
  o.iteration_rays = 0;  // 0 = sdf.rays throughout
  backend.rays.clear();
  sk::contract(mesh, &backend, o);
  for (int n : backend.rays) EXPECT_EQ(n, 24);
}

TEST(Skeleton, FineCapsuleGoesThroughTheProxyAndKeepsItsProperties) {
  // 4k vertices, above the proxy threshold: the contraction runs on a ~1k-vertex proxy, the
  // skeleton is still the input's (every input vertex in one node, nodes inside the input,
  // radii and Skeleton::sdf from the input's SDF).
  const float radius = 0.5f, length = 4.0f;
  const Mesh mesh = shapes::capsule(radius, length, 64, 64);
  RayCountingBackend backend;
  sk::ContractionOptions co;
  co.proxy_vertices = 1000;
  ASSERT_GT(mesh.positions.size(), 4 * co.proxy_vertices);
  const sk::Skeleton s = sk::extract(mesh, &backend, co, {});
  EXPECT_LE(s.contracted_vertices, co.proxy_vertices);
  EXPECT_GT(s.contracted_vertices, co.proxy_vertices / 2);
  // The input's SDF is measured once at full quality, then the proxy is contracted from the
  // input's values (no second full-quality SDF) with iteration_rays at every later iteration.
  ASSERT_EQ(backend.vertices.size(), 2u);
  EXPECT_EQ(backend.vertices[0], mesh.positions.size());
  EXPECT_EQ(backend.vertices[1], s.contracted_vertices);
  ASSERT_EQ(backend.rays.size(), static_cast<std::size_t>(s.iterations));
  EXPECT_EQ(backend.rays.front(), co.sdf.rays);
  for (std::size_t k = 1; k < backend.rays.size(); ++k) EXPECT_EQ(backend.rays[k], co.iteration_rays);
  ASSERT_EQ(s.sdf.size(), mesh.positions.size());
  std::vector<float> sdf = s.sdf;
  std::nth_element(sdf.begin(), sdf.begin() + sdf.size() / 2, sdf.end());
  EXPECT_NEAR(sdf[sdf.size() / 2], 2.0f * radius, 0.15f);

  expect_partition_and_inside(mesh, s);
  ASSERT_GE(s.nodes.size(), 2u);
  EXPECT_EQ(s.edges.size(), s.nodes.size() - 1);
  EXPECT_EQ(sk::cycle_count(s), 0);
  EXPECT_EQ(parts(s), 1);
  EXPECT_EQ(count_degree(s, 1), 2);
  EXPECT_EQ(count_degree(s, 2), static_cast<int>(s.nodes.size()) - 2);
  EXPECT_TRUE(s.sheet_triangles.empty());
  const float total = length + 2.0f * radius;
  for (const sk::Node& n : s.nodes) {
    EXPECT_LT(std::hypot(n.position.x, n.position.y), 0.02f * total);
    EXPECT_NEAR(n.radius, radius, 0.35f * radius);
  }
  EXPECT_DOUBLE_EQ(s.reliability, 1.0);
  EXPECT_DOUBLE_EQ(s.curve_reliability, 1.0);
}
