// Skeleton benchmark: sdfkit's SDF-driven contraction (the SDF recomputed at every iteration
// with the Embree reference backend) side by side with CGAL's Mean_curvature_flow_skeletonization
// on the same meshes, in the same run. Prints a Markdown table.
//
// usage: sdfkit_skeleton_bench [MESH.off ...]   (default: CGAL's elephant, refined_elephant,
//                                                camel and hand, extracted into the build tree)

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"
#include "sdfkit/skeleton/skeleton.hpp"

#include <CGAL/Mean_curvature_flow_skeletonization.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <boost/graph/graph_traits.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using CgalMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Mcf = CGAL::Mean_curvature_flow_skeletonization<CgalMesh>;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct CgalRun {
  double seconds = 0.0;
  int iterations = 0;
  std::size_t nodes = 0, edges = 0;
};

// CGAL's contract_until_convergence(), spelled out with its public contract() step so that the
// iterations can be counted: stop when |area - last area| < area_variation_factor * original.
CgalRun run_cgal(const sdfkit::Mesh& mesh) {
  CgalMesh tm;
  std::vector<CgalMesh::Vertex_index> vi;
  for (const auto& p : mesh.positions) vi.push_back(tm.add_vertex(Kernel::Point_3(p.x, p.y, p.z)));
  for (const auto& t : mesh.triangles) tm.add_face(vi[t[0]], vi[t[1]], vi[t[2]]);
  CgalRun r;
  const auto t0 = std::chrono::steady_clock::now();
  Mcf mcf(tm);
  const double original = CGAL::Polygon_mesh_processing::area(tm);
  double last = 0.0;
  for (std::size_t it = 0; it < mcf.max_iterations(); ++it) {
    mcf.contract();
    ++r.iterations;
    const double area = CGAL::Polygon_mesh_processing::area(mcf.meso_skeleton());
    if (std::abs(last - area) / original < mcf.area_variation_factor()) break;
    last = area;
  }
  Mcf::Skeleton skeleton;
  mcf.convert_to_skeleton(skeleton);
  r.seconds = seconds_since(t0);
  r.nodes = boost::num_vertices(skeleton);
  r.edges = boost::num_edges(skeleton);
  return r;
}

struct SdfkitRun {
  double seconds = 0.0, contract_seconds = 0.0;
  int iterations = 0;
  std::size_t nodes = 0, edges = 0, sheet_triangles = 0;
  double reliability = 0.0, curve_reliability = 0.0;
  std::string stop;
};

SdfkitRun run_sdfkit(const sdfkit::Mesh& mesh, sdfkit::SdfBackend& backend) {
  namespace sk = sdfkit::skeleton;
  SdfkitRun r;
  sk::ContractionOptions co;
  // Experiment overrides (not part of the benchmark's published settings).
  if (const char* v = std::getenv("SDFKIT_BENCH_WL")) co.wl_scale = std::atof(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_WC")) co.wc = std::atof(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_RAYS")) co.sdf.rays = std::atoi(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_SDF_TERM")) co.sdf_term = std::atoi(v) != 0;
  if (const char* v = std::getenv("SDFKIT_BENCH_ITERATIONS")) co.max_iterations = std::atoi(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_SL")) co.sl = std::atof(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_STALL")) co.stall_ratio = std::atof(v);
  const sk::SkeletonOptions so;
  const auto t0 = std::chrono::steady_clock::now();
  const sk::ContractionResult c = sk::contract(mesh, &backend, co);
  r.contract_seconds = seconds_since(t0);
  const sk::Skeleton s = sk::build_skeleton(mesh, c.contracted, c.first_sdf, so);
  r.seconds = seconds_since(t0);
  r.iterations = c.iterations;
  r.stop = c.stop_reason;
  r.nodes = s.nodes.size();
  r.edges = s.edges.size();
  r.sheet_triangles = s.sheet_triangles.size();
  r.reliability = s.reliability;
  r.curve_reliability = s.curve_reliability;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) paths.emplace_back(argv[i]);
  if (paths.empty())
    for (const char* m : {"elephant.off", "refined_elephant.off", "camel.off", "hand.off"})
      paths.push_back(std::string(SDFKIT_SKELETON_BENCH_DATA) + "/" + m);
  if (std::getenv("SDFKIT_DEBUG")) sdfkit::set_log_level(sdfkit::LogLevel::Debug);
  try {
    sdfkit::reference::EmbreeBackend backend;
    std::printf("SDF backend: %s\n\n", backend.device_name().c_str());
    std::printf("| mesh | vertices | sdfkit s (contraction s) | sdfkit iterations | nodes / edges / "
                "sheet tris | curve reliability | CGAL MCF s | CGAL iterations | CGAL nodes / edges | "
                "sdfkit / CGAL time |\n|---|---|---|---|---|---|---|---|---|---|\n");
    for (const std::string& path : paths) {
      const sdfkit::io::Asset asset = sdfkit::io::load_asset(path);
      const SdfkitRun a = run_sdfkit(asset.mesh, backend);
      const CgalRun b = run_cgal(asset.mesh);
      const std::string name = path.substr(path.find_last_of('/') + 1);
      std::printf("| %s | %zu | %.2f (%.2f) | %d | %zu / %zu / %zu | %.1f%% | %.2f | %d | %zu / %zu | %.2f |\n",
                  name.c_str(), asset.mesh.positions.size(), a.seconds, a.contract_seconds,
                  a.iterations, a.nodes, a.edges, a.sheet_triangles, 100.0 * a.curve_reliability,
                  b.seconds, b.iterations, b.nodes, b.edges, a.seconds / b.seconds);
      std::fflush(stdout);
      sdfkit::log_info(name + ": sdfkit contraction stopped: " + a.stop);
    }
  } catch (const sdfkit::Error& e) {
    std::fprintf(stderr, "sdfkit_skeleton_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
