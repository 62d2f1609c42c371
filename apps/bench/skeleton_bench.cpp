// Skeleton benchmark: sdfkit's SDF-driven skeleton extraction (the SDF recomputed at every
// contraction iteration) side by side with CGAL's Mean_curvature_flow_skeletonization on the
// same meshes, in the same run. Prints a Markdown table.
//
// usage: sdfkit_skeleton_bench [--backend opencl|embree] [--runs N] [MESH.off ...]
//        sdfkit_skeleton_bench [--backend ...] --eval DIR [--filter TEXT] [--dump DIR]
//                              [--cgal-from DIR | --cgal-remesh PCT] [--max-vertices N]
//                              [--no-sdf-off] [--no-models]
//   --eval     the evaluation (skeleton_eval.cpp): every closed mesh under DIR (CGAL's data set:
//              the build tree's skeleton_eval_data) up to --max-vertices (100000) vertices plus
//              the procedural models, with the SDF terms on and off, beside CGAL's MCF
//   --dump     write our skeletons and CGAL's as OBJ files into DIR (created)
//   --cgal-from  read CGAL's skeletons from an earlier --dump instead of computing them
//   --cgal-remesh  give CGAL an isotropically remeshed copy (edges PCT % of the diagonal): on
//              coarse CAD meshes MCF on the mesh as it is collapses to a stub
//   --backend  the SDF backend: the engine's OpenCL ray caster (the default when built and a
//              device works; PoCL on a CPU) or the Embree CPU reference
//   --runs     run each side N times and report the fastest (default 1)
//   meshes     default: CGAL's elephant, refined_elephant, camel and hand (build tree)
#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"
#include "sdfkit/skeleton/skeleton.hpp"
#include "skeleton_eval.hpp"
#ifdef SDFKIT_SKELETON_BENCH_OPENCL
#include "sdfkit/opencl/opencl_backend.hpp"
#endif

#include <CGAL/Mean_curvature_flow_skeletonization.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <boost/graph/graph_traits.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <memory>
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
  double seconds = 0.0;
  sdfkit::skeleton::Skeleton::Timings stages;
  int iterations = 0;
  std::size_t contracted_vertices = 0;
  std::size_t nodes = 0, edges = 0, sheet_triangles = 0;
  double reliability = 0.0, curve_reliability = 0.0;
};

// The published settings are the library's defaults; the SDFKIT_BENCH_* variables override
// them for experiments only.
sdfkit::skeleton::ContractionOptions contraction_options() {
  sdfkit::skeleton::ContractionOptions co;
  if (const char* v = std::getenv("SDFKIT_BENCH_WL")) co.wl_scale = std::atof(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_WC")) co.wc = std::atof(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_RAYS")) co.sdf.rays = std::atoi(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_ITERATION_RAYS")) co.iteration_rays = std::atoi(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_PROXY")) co.proxy_vertices = std::strtoul(v, nullptr, 10);
  if (const char* v = std::getenv("SDFKIT_BENCH_SDF_TERM")) co.sdf_term = std::atoi(v) != 0;
  if (const char* v = std::getenv("SDFKIT_BENCH_ITERATIONS")) co.max_iterations = std::atoi(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_SL")) co.sl = std::atof(v);
  if (const char* v = std::getenv("SDFKIT_BENCH_STALL")) co.stall_ratio = std::atof(v);
  return co;
}

SdfkitRun run_sdfkit(const sdfkit::Mesh& mesh, sdfkit::SdfBackend& backend) {
  namespace sk = sdfkit::skeleton;
  SdfkitRun r;
  const auto t0 = std::chrono::steady_clock::now();
  const sk::Skeleton s = sk::extract(mesh, &backend, contraction_options(), {});
  r.seconds = seconds_since(t0);
  r.stages = s.seconds;
  r.iterations = s.iterations;
  r.contracted_vertices = s.contracted_vertices;
  r.nodes = s.nodes.size();
  r.edges = s.edges.size();
  r.sheet_triangles = s.sheet_triangles.size();
  r.reliability = s.reliability;
  r.curve_reliability = s.curve_reliability;
  return r;
}

std::unique_ptr<sdfkit::SdfBackend> make_backend(const std::string& name) {
  if (name == "embree") return std::make_unique<sdfkit::reference::EmbreeBackend>();
#ifdef SDFKIT_SKELETON_BENCH_OPENCL
  if (name == "opencl") return std::make_unique<sdfkit::cl::OpenClBackend>();
#endif
  throw sdfkit::InputError("unknown or unavailable SDF backend '" + name +
                           "' (this build has: embree"
#ifdef SDFKIT_SKELETON_BENCH_OPENCL
                           ", opencl"
#endif
                           ")");
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> paths;
  std::string backend_name;
  int runs = 1;
  SkeletonEvalArgs eval;
  bool eval_mode = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--eval" && i + 1 < argc) {
      eval_mode = true;
      eval.dir = argv[++i];
    } else if (arg == "--filter" && i + 1 < argc) {
      eval.filter = argv[++i];
    } else if (arg == "--dump" && i + 1 < argc) {
      eval.dump = argv[++i];
    } else if (arg == "--cgal-from" && i + 1 < argc) {
      eval.cgal_dir = argv[++i];
    } else if (arg == "--cgal-remesh" && i + 1 < argc) {
      char* end = nullptr;
      eval.cgal_remesh = std::strtod(argv[++i], &end) / 100.0;
      // Below 0.1 % of the diagonal the copy of a sphere would have over a million vertices.
      if (*end != '\0' || !(eval.cgal_remesh >= 0.001 && eval.cgal_remesh < 1.0)) {
        std::fprintf(stderr, "sdfkit_skeleton_bench: --cgal-remesh %s: expected a percentage of the diagonal in [0.1, 100)\n",
                     argv[i]);
        return 2;
      }
    } else if (arg == "--max-vertices" && i + 1 < argc) {
      eval.max_vertices = std::strtoul(argv[++i], nullptr, 10);
    } else if (arg == "--no-sdf-off") {
      eval.no_sdf_run = false;
    } else if (arg == "--no-models") {
      eval.procedural = false;
    } else if (arg == "--backend" && i + 1 < argc) {
      backend_name = argv[++i];
    } else if (arg == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (arg.rfind("--", 0) == 0) {
      std::fprintf(stderr, "usage: sdfkit_skeleton_bench [--backend opencl|embree] [--runs N] [MESH.off ...]\n"
                           "       sdfkit_skeleton_bench [--backend opencl|embree] --eval DIR [--filter TEXT] "
                           "[--dump DIR] [--cgal-from DIR | --cgal-remesh PCT] [--max-vertices N] [--no-sdf-off] [--no-models]\n");
      return 2;
    } else {
      paths.push_back(arg);
    }
  }
  if (!eval.cgal_dir.empty() && eval.cgal_remesh > 0.0) {
    std::fprintf(stderr, "sdfkit_skeleton_bench: --cgal-remesh has no effect with --cgal-from (CGAL's skeletons are read, not computed)\n");
    return 2;
  }
  // The dumps are written one file per mesh as the run goes: the directory must exist first, or
  // every write would fail silently after minutes of work.
  if (!eval.dump.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(eval.dump, ec);
    if (ec || !std::filesystem::is_directory(eval.dump)) {
      std::fprintf(stderr, "sdfkit_skeleton_bench: --dump %s: cannot create the directory (%s)\n", eval.dump.c_str(),
                   ec ? ec.message().c_str() : "not a directory");
      return 2;
    }
  }
  // A directory of CGAL skeletons that is not there would turn every mesh's row into an error.
  if (!eval.cgal_dir.empty() && !std::filesystem::is_directory(eval.cgal_dir)) {
    std::fprintf(stderr, "sdfkit_skeleton_bench: --cgal-from %s: no such directory (write one with --dump)\n",
                 eval.cgal_dir.c_str());
    return 2;
  }
  if (paths.empty())
    for (const char* m : {"elephant.off", "refined_elephant.off", "camel.off", "hand.off"})
      paths.push_back(std::string(SDFKIT_SKELETON_BENCH_DATA) + "/" + m);
  if (std::getenv("SDFKIT_DEBUG")) sdfkit::set_log_level(sdfkit::LogLevel::Debug);
  try {
    std::unique_ptr<sdfkit::SdfBackend> backend;
    if (backend_name.empty()) {
#ifdef SDFKIT_SKELETON_BENCH_OPENCL
      try {
        backend = make_backend("opencl");
      } catch (const sdfkit::DeviceError& e) {
        std::fprintf(stderr, "OpenCL is unavailable (%s); using the Embree reference\n", e.what());
      }
#endif
      if (!backend) backend = make_backend("embree");
    } else {
      backend = make_backend(backend_name);
    }
    if (eval_mode) return run_skeleton_eval(eval, *backend);
    const auto co = contraction_options();
    std::printf("SDF backend: %s (%s); %d rays for the input's SDF, %d per later contraction "
                "iteration; proxy above %zu vertices; best of %d run(s)\n\n",
                backend->name().c_str(), backend->device_name().c_str(), co.sdf.rays,
                co.iteration_rays > 0 ? co.iteration_rays : co.sdf.rays, co.proxy_vertices, runs);
    std::printf("| mesh | vertices | contracted vertices | sdfkit s | simplify / contraction (SDF + solve) / "
                "input SDF / build s | sdfkit iterations | nodes / edges / sheet tris | curve reliability | "
                "CGAL MCF s | CGAL iterations | CGAL nodes / edges | sdfkit / CGAL time |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const std::string& path : paths) {
      const sdfkit::io::Asset asset = sdfkit::io::load_asset(path);
      SdfkitRun a;
      CgalRun b;
      for (int r = 0; r < runs; ++r) {
        const SdfkitRun x = run_sdfkit(asset.mesh, *backend);
        if (r == 0 || x.seconds < a.seconds) a = x;
        const CgalRun y = run_cgal(asset.mesh);
        if (r == 0 || y.seconds < b.seconds) b = y;
      }
      const std::string name = path.substr(path.find_last_of('/') + 1);
      const auto& t = a.stages;
      std::printf("| %s | %zu | %zu | %.2f | %.2f / %.2f (%.2f + %.2f) / %.2f / %.2f | %d | %zu / %zu / %zu | "
                  "%.1f%% | %.2f | %d | %zu / %zu | %.2f |\n",
                  name.c_str(), asset.mesh.positions.size(), a.contracted_vertices, a.seconds,
                  t.simplify, t.contraction, t.contraction_sdf, t.contraction_solve, t.input_sdf, t.build,
                  a.iterations, a.nodes, a.edges, a.sheet_triangles, 100.0 * a.curve_reliability,
                  b.seconds, b.iterations, b.nodes, b.edges, a.seconds / b.seconds);
      std::fflush(stdout);
    }
  } catch (const sdfkit::Error& e) {
    std::fprintf(stderr, "sdfkit_skeleton_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
