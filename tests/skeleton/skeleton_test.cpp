#include "sdfkit/core/shapes.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/reference/embree_backend.hpp"
#include "sdfkit/skeleton/models.hpp"
#include "sdfkit/skeleton/skeleton.hpp"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <map>

using namespace sdfkit;
namespace sk = sdfkit::skeleton;
namespace models = sdfkit::skeleton::models;

namespace {
void report(const char* name, const Mesh& m, bool sdf, const std::vector<models::Segment>* axis = nullptr) {
  reference::EmbreeBackend backend;
  sk::ContractionOptions co;
  co.sdf_term = sdf;
  sk::SkeletonOptions so;
  const auto t0 = std::chrono::steady_clock::now();
  const sk::ContractionResult c = sk::contract(m, sdf ? &backend : nullptr, co);
  const double cms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const sk::Skeleton s = sk::build_skeleton(m, c.contracted, c.first_sdf, so);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::map<std::size_t, int> degree_hist;
  std::vector<int> deg(s.nodes.size());
  for (auto& e : s.edges) { deg[e[0]]++; deg[e[1]]++; }
  for (int d : deg) degree_hist[static_cast<std::size_t>(d)]++;
  std::size_t sheet_nodes = 0;
  for (auto& n : s.nodes) sheet_nodes += n.sheet;
  double axis_mean = 0, axis_max = 0;
  if (axis) {
    for (auto& n : s.nodes) { float d = models::distance_to(*axis, n.position); axis_mean += d; axis_max = std::max<double>(axis_max, d); }
    axis_mean /= s.nodes.size();
  }
  std::printf("%s sdf=%d V=%zu: %.0f ms (contract %.0f, %s) it=%d nodes=%zu (sheet %zu) edges=%zu tris=%zu cycles=%d rel=%.3f curve_rel=%.3f axis mean %.4f max %.4f deg:",
              name, sdf, m.positions.size(), ms, cms, c.stop_reason.c_str(), c.iterations, s.nodes.size(), sheet_nodes, s.edges.size(),
              s.sheet_triangles.size(), sk::cycle_count(s), s.reliability, s.curve_reliability, axis_mean, axis_max);
  for (auto [d, cnt] : degree_hist) std::printf(" %zu:%d", d, cnt);
  std::printf("\n");
  for (auto& w : s.warnings) std::printf("   warning: %s\n", w.c_str());
}
}  // namespace

TEST(SkeletonProbe, DISABLED_Print) {
  set_log_level(LogLevel::Debug);
  const Mesh capsule = shapes::capsule(0.5f, 4.0f, 24, 24);
  std::vector<models::Segment> cax = {{glm::vec3(0, 0, -2), glm::vec3(0, 0, 2)}};
  for (bool sdf : {false, true}) {
    if (::testing::GTEST_FLAG(filter).find("Star") != std::string::npos) { auto star = models::five_armed_star(); report("star", star.mesh, sdf, &star.axis); continue; }
    report("capsule", capsule, sdf, &cax);
    report("torus", shapes::torus(2.0f, 0.5f, 48, 16), sdf);
    auto star = models::five_armed_star();
    report("star", star.mesh, sdf, &star.axis);
    auto g = models::genus2();
    report("genus2", g.mesh, sdf, &g.axis);
    report("C", models::c_shape().mesh, sdf);
    report("S", models::s_shape().mesh, sdf);
  }
}
