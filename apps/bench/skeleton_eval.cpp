// The skeleton evaluation (sdfkit_skeleton_bench --eval DIR): every closed mesh of a data set up
// to a vertex limit, plus the procedural models, skeletonized by sdfkit (library defaults, then
// with the SDF terms off) and by CGAL's Mean_curvature_flow_skeletonization in the same run.
//
// Per mesh it prints what a skeleton must get right, measured independently of the pipeline:
// - topology: independent cycles of the skeleton (sdfkit::skeleton::cycle_count) against the
//   solid's genus, from the Euler characteristic of each connected component of the surface;
// - containment: nodes inside the solid (winding number not 0, majority vote of three rays) and
//   curve edges whose whole segment is inside (both ends inside, the winding number never 0
//   between them: TriangleBvh::segment_leaves; where closed pieces overlap, the solid is their
//   union);
// - shape: leaves (nodes of degree 1, counting curve edges and sheet-triangle edges), branch
//   nodes (curve nodes of degree >= 3), share of sheet nodes, curve reliability before sheets;
// - agreement with CGAL's skeleton: the share of CGAL's leaves that have one of our leaves within
//   5 % of the bounding-box diagonal, and the mean distance from points along our curve edges
//   (every 0.5 % of the diagonal) to CGAL's skeleton edges, in % of the diagonal.
// CGAL gets the mesh through its polygon-soup repair (orient_polygon_soup duplicates the
// vertices of non-manifold edges), as a user of CGAL would do with such a mesh.
#include "skeleton_eval.hpp"

#include "bvh.hpp"  // engine/skeleton (private): the CPU BVH of the containment checks

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/topology.hpp"
#include "sdfkit/core/union_find.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/skeleton/models.hpp"
#include "sdfkit/skeleton/skeleton.hpp"

#include <CGAL/Mean_curvature_flow_skeletonization.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <boost/graph/graph_traits.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

namespace sk = sdfkit::skeleton;
using Kernel = CGAL::Simple_cartesian<double>;
using CgalMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Mcf = CGAL::Mean_curvature_flow_skeletonization<CgalMesh>;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A skeleton as a graph: points, edges, and which points are leaves.
struct Graph {
  std::vector<glm::vec3> points;
  std::vector<std::array<std::uint32_t, 2>> edges;
  std::vector<std::uint32_t> leaves;
};

struct CgalResult {
  bool ok = false;
  std::string error;
  double seconds = 0.0;
  int iterations = 0;
  int cycles = 0;
  Graph graph;
};

// CGAL's contract_until_convergence(), spelled out so the iterations can be counted.
// CGAL's skeleton graph's leaves (degree-1 points) and independent cycles (E - V + components).
void count_leaves_and_cycles(CgalResult& r) {
  std::vector<int> degree(r.graph.points.size(), 0);
  for (const auto& e : r.graph.edges) ++degree[e[0]], ++degree[e[1]];
  for (std::uint32_t v = 0; v < degree.size(); ++v)
    if (degree[v] == 1) r.graph.leaves.push_back(v);
  sdfkit::UnionFind uf(r.graph.points.size());
  std::size_t components = r.graph.points.size();
  for (const auto& e : r.graph.edges)
    if (uf.unite(e[0], e[1])) --components;
  r.cycles = static_cast<int>(r.graph.edges.size()) - static_cast<int>(r.graph.points.size()) +
             static_cast<int>(components);
}

CgalResult run_cgal(const sdfkit::Mesh& mesh, double remesh) {
  CgalResult r;
  try {
    std::vector<Kernel::Point_3> points;
    for (const auto& p : mesh.positions) points.emplace_back(p.x, p.y, p.z);
    std::vector<std::vector<std::size_t>> polygons;
    for (const auto& t : mesh.triangles) polygons.push_back({t[0], t[1], t[2]});
    namespace pmp = CGAL::Polygon_mesh_processing;
    pmp::repair_polygon_soup(points, polygons);
    pmp::orient_polygon_soup(points, polygons);
    CgalMesh tm;
    pmp::polygon_soup_to_polygon_mesh(points, polygons, tm);
    if (!CGAL::is_triangle_mesh(tm) || tm.number_of_faces() == 0) {
      r.error = "not a triangle mesh after soup repair";
      return r;
    }
    if (remesh > 0.0) {
      // Never coarser than the input: a fine mesh (armadillo's fingers) keeps its resolution and
      // only gets regular triangles.
      const double diag = sdfkit::bounding_box(mesh.positions).diagonal();
      double mean_edge = 0.0;
      for (auto e : CGAL::make_range(edges(tm))) mean_edge += pmp::edge_length(halfedge(e, tm), tm);
      mean_edge /= std::max<double>(1.0, static_cast<double>(tm.number_of_edges()));
      pmp::isotropic_remeshing(faces(tm), std::min(remesh * diag, mean_edge), tm,
                               CGAL::parameters::number_of_iterations(3));
      tm.collect_garbage();
    }
    const auto t0 = std::chrono::steady_clock::now();
    Mcf mcf(tm);
    const double original = pmp::area(tm);
    double last = 0.0;
    for (std::size_t it = 0; it < mcf.max_iterations(); ++it) {
      mcf.contract();
      ++r.iterations;
      const double area = pmp::area(mcf.meso_skeleton());
      if (std::abs(last - area) / original < mcf.area_variation_factor()) break;
      last = area;
    }
    Mcf::Skeleton skeleton;
    mcf.convert_to_skeleton(skeleton);
    r.seconds = seconds_since(t0);
    std::map<Mcf::Skeleton::vertex_descriptor, std::uint32_t> index;
    for (auto v : CGAL::make_range(vertices(skeleton))) {
      index[v] = static_cast<std::uint32_t>(r.graph.points.size());
      const auto& p = skeleton[v].point;
      r.graph.points.emplace_back(p.x(), p.y(), p.z());
    }
    for (auto e : CGAL::make_range(edges(skeleton)))
      r.graph.edges.push_back({index[source(e, skeleton)], index[target(e, skeleton)]});
    count_leaves_and_cycles(r);
    r.ok = true;
  } catch (const std::exception& e) {
    r.error = e.what();
  }
  return r;
}

// CGAL's skeleton as an earlier run dumped it (write_graph_obj): points and edges; seconds < 0.
CgalResult read_cgal(const std::string& path) {
  CgalResult r;
  std::ifstream in(path);
  if (!in) {
    r.error = "no " + path;
    return r;
  }
  std::string tag;
  while (in >> tag) {
    if (tag == "v") {
      glm::vec3 p;
      in >> p.x >> p.y >> p.z;
      r.graph.points.push_back(p);
    } else if (tag == "l") {
      std::uint32_t a = 0, b = 0;
      in >> a >> b;
      if (a < 1 || b < 1 || a > r.graph.points.size() || b > r.graph.points.size()) {
        r.error = path + ": bad edge";
        return r;
      }
      r.graph.edges.push_back({a - 1, b - 1});
    }
  }
  count_leaves_and_cycles(r);
  r.seconds = -1.0;
  r.ok = true;
  return r;
}

// Genus of a closed surface: per connected component (over shared vertices) (2 - chi) / 2.
int genus(const sdfkit::Mesh& mesh, std::size_t& components) {
  const std::size_t n = mesh.positions.size();
  sdfkit::UnionFind uf(n);
  std::vector<std::uint8_t> used(n, 0);
  for (const auto& t : mesh.triangles) {
    uf.unite(t[0], t[1]), uf.unite(t[1], t[2]);
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  }
  std::map<std::uint32_t, long> chi;
  for (std::uint32_t v = 0; v < n; ++v)
    if (used[v]) ++chi[uf.find(v)];
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const auto& t : mesh.triangles) {
    chi[uf.find(t[0])] += 1;  // the face
    for (int i = 0; i < 3; ++i)
      if (edges.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])}).second)
        chi[uf.find(t[0])] -= 1;
  }
  components = chi.size();
  long g = 0;
  for (const auto& [root, x] : chi) g += (2 - x) / 2;
  return static_cast<int>(g);
}

struct Eval {
  bool ok = false;
  std::string error;
  double seconds = 0.0;
  int iterations = 0;
  std::size_t nodes = 0, sheet_nodes = 0, edges = 0, leaves = 0, branches = 0;
  int cycles = 0;
  std::size_t nodes_inside = 0, edges_inside = 0;
  double curve_reliability = 0.0;
  double leaf_match = -1.0;  // share of CGAL's leaves matched (-1: no CGAL run)
  double curve_distance = -1.0;  // % of the diagonal (-1: no CGAL run or no curve edge)
  Graph graph;  // curve edges only (for the distance)
};

float point_segment(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float l2 = glm::dot(ab, ab);
  const float t = l2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / l2, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + t * ab));
}

Eval measure(const sk::Skeleton& s,
             const sdfkit::skeleton::detail::TriangleBvh& bvh) {
  Eval r;
  r.ok = true;
  r.iterations = s.iterations;
  r.nodes = s.nodes.size();
  r.edges = s.edges.size();
  r.curve_reliability = s.curve_reliability;
  r.cycles = sk::cycle_count(s);
  std::set<std::array<std::uint32_t, 2>> all_edges(s.edges.begin(), s.edges.end());
  for (const auto& t : s.sheet_triangles)
    for (int i = 0; i < 3; ++i)
      all_edges.insert({std::min(t[i], t[(i + 1) % 3]), std::max(t[i], t[(i + 1) % 3])});
  std::vector<int> degree(s.nodes.size(), 0);
  for (const auto& e : all_edges) ++degree[e[0]], ++degree[e[1]];
  for (std::uint32_t v = 0; v < s.nodes.size(); ++v) {
    const sk::Node& node = s.nodes[v];
    r.sheet_nodes += node.sheet;
    r.graph.points.push_back(node.position);
    if (degree[v] == 1) r.leaves++, r.graph.leaves.push_back(v);
    if (degree[v] >= 3 && !node.sheet) r.branches++;
  }
  std::vector<std::uint8_t> inside(s.nodes.size());
  for (std::uint32_t v = 0; v < s.nodes.size(); ++v) {
    inside[v] = bvh.inside(s.nodes[v].position);
    r.nodes_inside += inside[v];
  }
  for (const auto& e : s.edges) {
    r.graph.edges.push_back(e);
    if (!bvh.segment_leaves(s.nodes[e[0]].position, s.nodes[e[1]].position))
      ++r.edges_inside;
  }
  return r;
}

void compare(Eval& e, const CgalResult& c, float diag) {
  if (!c.ok) return;
  std::size_t matched = 0;
  for (std::uint32_t l : c.graph.leaves) {
    bool found = false;
    for (std::uint32_t m : e.graph.leaves)
      if (glm::length(e.graph.points[m] - c.graph.points[l]) <= 0.05f * diag) found = true;
    matched += found;
  }
  e.leaf_match = c.graph.leaves.empty() ? 1.0 : static_cast<double>(matched) / c.graph.leaves.size();
  double sum = 0.0;
  std::size_t count = 0;
  const float step = 0.005f * diag;
  for (const auto& edge : e.graph.edges) {
    const glm::vec3 a = e.graph.points[edge[0]], b = e.graph.points[edge[1]];
    const int samples = std::max(1, static_cast<int>(std::ceil(glm::length(b - a) / step)));
    for (int i = 0; i <= samples; ++i) {
      const glm::vec3 p = a + (b - a) * (static_cast<float>(i) / samples);
      float best = std::numeric_limits<float>::max();
      for (const auto& ce : c.graph.edges)
        best = std::min(best, point_segment(p, c.graph.points[ce[0]], c.graph.points[ce[1]]));
      if (c.graph.edges.empty())
        for (const auto& q : c.graph.points) best = std::min(best, glm::length(p - q));
      sum += best;
      ++count;
    }
  }
  e.curve_distance = count > 0 ? 100.0 * sum / count / diag : -1.0;
}

Eval run_sdfkit(const sdfkit::Mesh& mesh, sdfkit::SdfBackend& backend, bool sdf_terms,
                const sdfkit::skeleton::detail::TriangleBvh& bvh, const std::string& dump_path) {
  sk::ContractionOptions co;
  co.sdf_term = sdf_terms;
  if (const char* v = std::getenv("SDFKIT_EVAL_SL")) co.sl = std::atof(v);
  if (const char* v = std::getenv("SDFKIT_EVAL_SL_HANDLES")) co.sl_handles = std::atof(v);
  if (const char* v = std::getenv("SDFKIT_EVAL_PROXY")) co.proxy_vertices = static_cast<std::size_t>(std::atol(v));
  try {
    const auto t0 = std::chrono::steady_clock::now();
    sk::SkeletonOptions so;  // library defaults; SDFKIT_EVAL_EXTEND_LEAVES=0 / SDFKIT_EVAL_PRUNE_BRANCHES=0 for the comparisons
    if (const char* v = std::getenv("SDFKIT_EVAL_EXTEND_LEAVES")) so.extend_leaves = std::atoi(v) != 0;
    if (const char* v = std::getenv("SDFKIT_EVAL_PRUNE_BRANCHES")) so.prune_branches = std::atoi(v) != 0;
    if (const char* v = std::getenv("SDFKIT_EVAL_UNFOLD_BRANCHES")) so.unfold_branches = std::atoi(v) != 0;
    if (const char* v = std::getenv("SDFKIT_EVAL_SECTION_NODES")) so.section_nodes = std::atoi(v) != 0;
    if (const char* v = std::getenv("SDFKIT_EVAL_PROTRUSION_BRANCHES")) so.protrusion_branches = std::atoi(v) != 0;
    const sk::Skeleton s = sk::extract(mesh, &backend, co, so);
    const double seconds = seconds_since(t0);
    Eval e = measure(s, bvh);
    e.seconds = seconds;
    if (!dump_path.empty()) {
      std::ofstream out(dump_path);
      sk::write_obj(out, s);
    }
    return e;
  } catch (const std::exception& ex) {
    Eval e;
    e.error = ex.what();
    return e;
  }
}

void write_graph_obj(const std::string& path, const Graph& g) {
  std::ofstream out(path);
  for (const auto& p : g.points) out << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
  for (const auto& e : g.edges) out << "l " << e[0] + 1 << ' ' << e[1] + 1 << '\n';
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

std::string pct(double x) {
  if (x < 0.0) return "–";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f%%", 100.0 * x);
  return buf;
}

std::string num(double x, const char* fmt) {
  if (x < 0.0) return "–";
  char buf[32];
  std::snprintf(buf, sizeof buf, fmt, x);
  return buf;
}

struct Summary {
  std::size_t meshes = 0, cycles_ok = 0, nodes_ok = 0, edges_ok = 0, faster = 0, timed = 0, failed = 0;
  std::vector<double> sheet, reliability, match, distance;
  bool remeshed = false;  // CGAL ran on a remeshed copy: its time is not the one to compare with
  void add(const Eval& e, const CgalResult& c, int g) {
    ++meshes;
    if (!e.ok) {
      ++failed;
      return;
    }
    cycles_ok += e.cycles == g;
    nodes_ok += e.nodes_inside == e.nodes;
    edges_ok += e.edges_inside == e.edges;
    sheet.push_back(e.nodes ? static_cast<double>(e.sheet_nodes) / e.nodes : 0.0);
    reliability.push_back(e.curve_reliability);
    if (c.ok) {
      timed += c.seconds >= 0.0;
      faster += c.seconds >= 0.0 && e.seconds <= c.seconds;
      if (!c.graph.leaves.empty()) match.push_back(e.leaf_match);
      if (e.curve_distance >= 0.0) distance.push_back(e.curve_distance);
    }
  }
  void print(const char* what) const {
    std::printf("%s: %zu meshes, %zu failed; cycles = genus on %zu; all nodes inside on %zu; all "
                "curve edges inside on %zu; median sheet share %.1f%%; median curve reliability "
                "%.1f%%; CGAL leaves matched >= 80%% on %zu of the %zu meshes whose CGAL skeleton "
                "has leaves (median %.0f%%); median curve distance to CGAL %.2f%% of the diagonal; %s\n",
                what, meshes, failed, cycles_ok, nodes_ok, edges_ok, 100.0 * median(sheet),
                100.0 * median(reliability),
                static_cast<std::size_t>(std::count_if(match.begin(), match.end(), [](double m) { return m >= 0.8; })),
                match.size(), 100.0 * median(match), median(distance),
                !timed     ? "CGAL not timed (its skeletons read from a dump)"
                : remeshed ? ("no slower than CGAL's MCF on its remeshed copy on " + std::to_string(faster) + " of " +
                              std::to_string(timed) + " (not CGAL on the same mesh)").c_str()
                           : ("no slower than CGAL on " + std::to_string(faster) + " of " + std::to_string(timed)).c_str());
  }
};

// `filter`: comma-separated substrings, any of which selects a name (empty: all).
bool matches(const std::string& filter, const std::string& name) {
  if (filter.empty()) return true;
  std::size_t start = 0;
  while (start <= filter.size()) {
    const std::size_t end = std::min(filter.find(',', start), filter.size());
    const std::string part = filter.substr(start, end - start);
    if (!part.empty() && name.find(part) != std::string::npos) return true;
    start = end + 1;
  }
  return false;
}

struct Case {
  std::string name;
  sdfkit::Mesh mesh;
};

}  // namespace

int run_skeleton_eval(const SkeletonEvalArgs& args, sdfkit::SdfBackend& backend) {
  namespace fs = std::filesystem;
  std::vector<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(args.dir))
    if (entry.is_regular_file()) files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  std::vector<std::string> skipped;
  std::vector<Case> cases;
  for (const std::string& path : files) {
    const std::string name = fs::relative(path, args.dir).string();
    if (!matches(args.filter, name)) continue;
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
    if (ext != ".off" && ext != ".obj" && ext != ".ply") {
      if (ext == ".stl") skipped.push_back(name + ": STL (sdfkit's loader reads glTF, OBJ, OFF, PLY)");
      continue;  // images, point sets (.xyz, .pwn), volumes (.inr): not meshes
    }
    sdfkit::io::Asset asset;
    try {
      asset = sdfkit::io::load_asset(path);
    } catch (const std::exception& e) {
      skipped.push_back(name + ": not loadable (" + std::string(e.what()) + ")");
      continue;
    }
    const sdfkit::MeshReport rep = sdfkit::analyze(asset.mesh);
    if (rep.boundary_edges > 0) {
      skipped.push_back(name + ": open (" + std::to_string(rep.boundary_edges) + " boundary edges)");
      continue;
    }
    if (asset.mesh.positions.size() > args.max_vertices) {
      skipped.push_back(name + ": " + std::to_string(asset.mesh.positions.size()) + " vertices (over " +
                        std::to_string(args.max_vertices) + ")");
      continue;
    }
    cases.push_back({name, std::move(asset.mesh)});
  }
  if (args.procedural) {
    if (matches(args.filter, "model:c_shape")) cases.push_back({"model:c_shape", sk::models::c_shape().mesh});
    if (matches(args.filter, "model:s_shape")) cases.push_back({"model:s_shape", sk::models::s_shape().mesh});
    if (matches(args.filter, "model:star")) cases.push_back({"model:star", sk::models::five_armed_star().mesh});
    if (matches(args.filter, "model:genus2")) cases.push_back({"model:genus2", sk::models::genus2().mesh});
  }

  // Warm-up (OpenCL compiles its kernels on first use): not timed.
  sk::extract(sk::models::five_armed_star().mesh, &backend, {}, {});
  std::printf("SDF backend: %s (%s); library defaults; %zu meshes (%zu skipped, listed below)\n",
              backend.name().c_str(), backend.device_name().c_str(), cases.size(), skipped.size());
  if (args.cgal_remesh > 0.0)
    std::printf("CGAL's input: each mesh isotropically remeshed to edges of %.2f%% of its diagonal or its "
                "mean edge length, whichever is shorter (CGAL's isotropic_remeshing, 3 iterations, not "
                "timed; CGAL's time is its MCF on that denser mesh, so the speed comparison is not the "
                "product's: run without --cgal-remesh for that)\n",
                100.0 * args.cgal_remesh);
  std::printf("\n");
  std::printf("| mesh | vertices | comp. | genus | non-manif. edges | s | it | nodes | sheet | leaves | "
              "branch | cycles | nodes in | edges in | curve rel. | CGAL s | CGAL leaves | CGAL cycles | "
              "CGAL leaves matched | curve dist. %% | no-SDF s | sheet | leaves | cycles | edges in | "
              "matched | dist. %% |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
              "---|---|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);
  Summary with, without;
  with.remeshed = without.remeshed = args.cgal_remesh > 0.0;
  for (const Case& c : cases) {
    std::size_t components = 0;
    const int g = genus(c.mesh, components);
    const sdfkit::MeshReport rep = sdfkit::analyze(c.mesh);
    const sdfkit::skeleton::detail::TriangleBvh bvh(c.mesh);
    const float diag = sdfkit::bounding_box(c.mesh.positions).diagonal();
    std::string stem = c.name;
    std::replace(stem.begin(), stem.end(), '/', '_');
    std::replace(stem.begin(), stem.end(), ':', '_');
    const std::string dump = args.dump.empty() ? "" : args.dump + "/" + stem;
    Eval a = run_sdfkit(c.mesh, backend, true, bvh, dump.empty() ? "" : dump + ".sdfkit.obj");
    Eval b;
    if (args.no_sdf_run) b = run_sdfkit(c.mesh, backend, false, bvh, dump.empty() ? "" : dump + ".nosdf.obj");
    const CgalResult cg = args.cgal_dir.empty() ? run_cgal(c.mesh, args.cgal_remesh) : read_cgal(args.cgal_dir + "/" + stem + ".cgal.obj");
    if (!dump.empty() && cg.ok) write_graph_obj(dump + ".cgal.obj", cg.graph);
    compare(a, cg, diag);
    compare(b, cg, diag);
    with.add(a, cg, g);
    if (args.no_sdf_run) without.add(b, cg, g);
    auto frac = [](std::size_t x, std::size_t n) { return std::to_string(x) + "/" + std::to_string(n); };
    std::string ours, theirs, nosdf;
    if (a.ok) {
      char buf[512];
      std::snprintf(buf, sizeof buf, "%.3f | %d | %zu | %s | %zu | %zu | %d | %s | %s | %.1f%%", a.seconds,
                    a.iterations, a.nodes, pct(a.nodes ? double(a.sheet_nodes) / a.nodes : 0.0).c_str(),
                    a.leaves, a.branches, a.cycles, frac(a.nodes_inside, a.nodes).c_str(),
                    frac(a.edges_inside, a.edges).c_str(), 100.0 * a.curve_reliability);
      ours = buf;
    } else {
      ours = "error: " + a.error + " | | | | | | | | |";
    }
    if (cg.ok) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "%s | %zu | %d | %s | %s", num(cg.seconds, "%.3f").c_str(), cg.graph.leaves.size(), cg.cycles,
                    pct(a.leaf_match).c_str(), num(a.curve_distance, "%.2f").c_str());
      theirs = buf;
    } else {
      theirs = "error: " + cg.error + " | | | |";
    }
    if (!args.no_sdf_run) {
      nosdf = "| | | | | |";
    } else if (b.ok) {
      char buf[256];
      std::snprintf(buf, sizeof buf, "%.3f | %s | %zu | %d | %s | %s | %s", b.seconds,
                    pct(b.nodes ? double(b.sheet_nodes) / b.nodes : 0.0).c_str(), b.leaves, b.cycles,
                    frac(b.edges_inside, b.edges).c_str(), pct(b.leaf_match).c_str(),
                    num(b.curve_distance, "%.2f").c_str());
      nosdf = buf;
    } else {
      nosdf = "error: " + b.error + " | | | | | |";
    }
    std::printf("| %s | %zu | %zu | %d | %zu | %s | %s | %s |\n", c.name.c_str(), c.mesh.positions.size(),
                components, g, rep.non_manifold_edges, ours.c_str(), theirs.c_str(), nosdf.c_str());
    std::fflush(stdout);
  }
  std::printf("\nSkipped (%zu):\n", skipped.size());
  for (const std::string& s : skipped) std::printf("- %s\n", s.c_str());
  std::printf("\n");
  with.print("SDF terms on (defaults)");
  if (args.no_sdf_run) without.print("SDF terms off");
  return 0;
}
