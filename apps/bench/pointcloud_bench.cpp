// Point-cloud skeleton benchmark (issue 14): the linear skeleton of every frame of the shared
// Sibernetic worm (the outer-surface particles as an unoriented cloud) and of synthetic worms,
// with each step's time, the polyline's mean distance to the true midline and head/tail swaps.
//
// usage: sdfkit_pointcloud_bench [--data DIR] [--segments N] [--backend opencl|embree]
//                                [--synthetic N,N,...] [--runs R] [--linkage average|single]
//                                [--neighbours K] [--bones 4,8,...] [--rotation procrustes|polyline]
//   --data       a Sibernetic frame set (default: ../shared/worm beside the source tree)
//   --synthetic  point counts of synthetic worms to time (default 2000,30000)
//   --runs       repetitions of the whole frame set; the per-step medians are over all runs
#include "sdfkit/core/error.hpp"
#include "sdfkit/pointcloud/pointcloud.hpp"
#include "sdfkit/pointcloud/skinning.hpp"
#include "sdfkit/reference/embree_backend.hpp"
#ifdef SDFKIT_POINTCLOUD_BENCH_OPENCL
#include "sdfkit/opencl/opencl_backend.hpp"
#endif

#include <glm/geometric.hpp>

#ifdef SDFKIT_POINTCLOUD_BENCH_CGAL
#include <CGAL/Mean_curvature_flow_skeletonization.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <boost/graph/graph_traits.hpp>
#endif

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace pc = sdfkit::pointcloud;

namespace {

std::unique_ptr<sdfkit::SdfBackend> make(const std::string& name) {
  if (name == "embree") return std::make_unique<sdfkit::reference::EmbreeBackend>();
#ifdef SDFKIT_POINTCLOUD_BENCH_OPENCL
  if (name == "opencl") return std::make_unique<sdfkit::cl::OpenClBackend>();
#endif
  throw sdfkit::InputError("unknown or unavailable backend " + name);
}

std::vector<pc::Polyline> read_midlines(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw sdfkit::InputError("cannot open " + path);
  std::vector<pc::Polyline> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::size_t f;
    int slice;
    float x, y, z;
    if (!(ls >> f >> slice >> x >> y >> z)) continue;
    if (lines.size() <= f) lines.resize(f + 1);
    lines[f].nodes.push_back({glm::vec3(x, y, z), 0.0f});  // slice 50 (tail) first
  }
  return lines;
}

#ifdef SDFKIT_POINTCLOUD_BENCH_CGAL
// CGAL's mean curvature flow skeleton (contract_until_convergence spelled out) of a frame's
// surface as the simulator's own membrane triangles (a closed mesh of the shell particles: the
// best reconstruction a robust mesh method could hope for). Returns seconds; fills the mean
// distance of the skeleton's vertices to the midline.
double run_mcf(const std::vector<glm::vec3>& all, const std::vector<std::array<std::size_t, 3>>& tris,
               const pc::Polyline& midline, double& mean_distance, std::size_t& nodes) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  using Mcf = CGAL::Mean_curvature_flow_skeletonization<Mesh>;
  std::vector<Kernel::Point_3> points;
  for (const auto& p : all) points.emplace_back(p.x, p.y, p.z);
  std::vector<std::vector<std::size_t>> polygons;
  for (const auto& t : tris) polygons.push_back({t[0], t[1], t[2]});
  CGAL::Polygon_mesh_processing::orient_polygon_soup(points, polygons);
  Mesh tm;
  CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(points, polygons, tm);
  tm.collect_garbage();
  const auto t0 = std::chrono::steady_clock::now();
  Mcf mcf(tm);
  const double original = CGAL::Polygon_mesh_processing::area(tm);
  double last = 0.0;
  for (std::size_t it = 0; it < mcf.max_iterations(); ++it) {
    mcf.contract();
    const double area = CGAL::Polygon_mesh_processing::area(mcf.meso_skeleton());
    if (std::abs(last - area) / original < mcf.area_variation_factor()) break;
    last = area;
  }
  Mcf::Skeleton skeleton;
  mcf.convert_to_skeleton(skeleton);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double sum = 0.0;
  nodes = 0;
  for (auto v : CGAL::make_range(vertices(skeleton))) {
    const auto& p = skeleton[v].point;
    sum += pc::distance_to_polyline(glm::vec3(p.x(), p.y(), p.z()), midline);
    ++nodes;
  }
  mean_distance = nodes ? sum / static_cast<double>(nodes) : 0.0;
  return seconds;
}
#endif

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Summary {
  std::map<std::string, std::vector<double>> steps, cpu;
  std::vector<double> totals, cpu_totals;
  void add(const pc::SkeletonResult& r) {
    double t = 0.0, c = 0.0;
    for (const auto& s : r.times) {
      steps[s.step].push_back(s.milliseconds);
      cpu[s.step].push_back(s.cpu_milliseconds);
      t += s.milliseconds;
      c += s.cpu_milliseconds;
    }
    totals.push_back(t);
    cpu_totals.push_back(c);
  }
  // Each cell: the median wall-clock ms (the median CPU ms of the process, both cores and
  // PoCL's threads counted, in brackets).
  void print(const char* label, std::size_t points) const {
    std::printf("| %s | %zu |", label, points);
    for (const char* s : {"subsample", "neighbours", "normals", "orientation", "surface", "sdf", "shift", "clustering", "polyline"})
      std::printf(" %.2f (%.2f) |", steps.count(s) ? median(steps.at(s)) : 0.0, cpu.count(s) ? median(cpu.at(s)) : 0.0);
    std::printf(" **%.1f** (%.1f) | %.1f |\n", median(totals), median(cpu_totals), *std::max_element(totals.begin(), totals.end()));
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string data = std::string(SDFKIT_SOURCE_DIR) + "/../shared/worm";
  std::string backend_name =
#ifdef SDFKIT_POINTCLOUD_BENCH_OPENCL
      "opencl";
#else
      "embree";
#endif
  int segments = 16, runs = 1;
  bool procrustes = true, worm_frames = true, cgal = true;
  std::vector<std::size_t> synthetic{2000, 30000};
  std::vector<int> bone_counts{4, 6, 8, 12, 16, 20, 24, 32};
  pc::SkeletonOptions opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw sdfkit::InputError(a + " needs a value");
      return argv[++i];
    };
    if (a == "--data") data = next();
    else if (a == "--segments") segments = std::stoi(next());
    else if (a == "--backend") backend_name = next();
    else if (a == "--rotation") procrustes = next() != "polyline";
    else if (a == "--runs") runs = std::stoi(next());
    else if (a == "--neighbours") opt.neighbours = std::stoi(next());
    else if (a == "--cluster-neighbours") opt.cluster_neighbours = std::stoi(next());
    else if (a == "--no-median") opt.median = false;
    else if (a == "--no-worm") worm_frames = false;
    else if (a == "--no-cgal") cgal = false;
    else if (a == "--max-points") opt.max_points = std::stoul(next());
    else if (a == "--rays") opt.sdf.rays = std::stoi(next());
    else if (a == "--linkage") opt.linkage = next() == "single" ? pc::Linkage::Single : pc::Linkage::Average;
    else if (a == "--synthetic") {
      synthetic.clear();
      std::stringstream ss(next());
      std::string tok;
      while (std::getline(ss, tok, ','))
        if (!tok.empty()) synthetic.push_back(std::stoul(tok));
    } else if (a == "--bones") {
      bone_counts.clear();
      std::stringstream ss(next());
      std::string tok;
      while (std::getline(ss, tok, ','))
        if (!tok.empty()) bone_counts.push_back(std::stoi(tok));
    } else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  opt.segments = segments;
  try {
    auto backend = make(backend_name);
    std::printf("backend: %s (%s), k = %d, rays = %d, segments = %d, linkage = %s\n\n", backend->name().c_str(),
                backend->device_name().c_str(), opt.neighbours, opt.sdf.rays, segments,
                opt.linkage == pc::Linkage::Single ? "single" : "average");
    const pc::FrameSet set = pc::read_frames(data, true);
    const auto mid = read_midlines(data + "/midline.txt");
    std::printf("Each cell: median wall-clock ms (median process CPU ms, all threads)\n\n");
    std::printf("| cloud | points | subsample | neighbours | normals | orientation | surface | sdf | shift | clustering | polyline | total median ms | max ms |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    std::string accuracy;
    if (worm_frames) {
      Summary worm;
      std::vector<pc::Polyline> lines;
      std::vector<double> err, err_sym;
      std::size_t inexact = 0, ambiguous = 0;
      for (int run = 0; run < runs; ++run) {
        lines.clear();
        for (std::size_t f = 0; f < set.frames.size(); ++f) {
          pc::SkeletonResult r = pc::point_cloud_skeleton(set.frames[f], *backend, opt);
          if (run == 0) {
            inexact += !r.exact;
            ambiguous += r.ambiguous.size();
          }
          worm.add(r);
          lines.push_back(std::move(r.polyline));
        }
      }
      pc::orient_sequence(lines);
      std::size_t swaps = 0;
      int first_end = 0;
      double worst = 0.0, worst_sym = 0.0;
      for (std::size_t f = 0; f < lines.size(); ++f) {
        const float body = mid[f].length();
        const double e = pc::mean_distance(lines[f], mid[f], 0.25f) / body;
        const double es = 0.5 * (e + pc::mean_distance(mid[f], lines[f], 0.25f) / body);
        err.push_back(e);
        err_sym.push_back(es);
        worst = std::max(worst, e);
        worst_sym = std::max(worst_sym, es);
        // Which end is first: +1 = the tail (slice 50), -1 = the head (slice 148).
        const glm::vec3 p0 = lines[f].nodes.front().position;
        const int end = glm::distance(p0, mid[f].nodes.front().position) < glm::distance(p0, mid[f].nodes.back().position) ? 1 : -1;
        if (f == 0) first_end = end;
        else if (end != first_end) ++swaps;
      }
      double mean = 0.0;
      for (double e : err) mean += e;
      mean /= static_cast<double>(err.size());
      char line[1024];
      std::snprintf(line, sizeof line, "worm: %zu frames x %zu points: polyline -> midline mean distance %.3f %% of the body length "
                  "(worst frame %.3f %%), symmetric worst %.3f %%; frames whose first node is not the same end as frame 0: %zu; "
                  "frames without exactly %d segments: %zu; ambiguous normals: %zu\n\n",
                  set.frames.size(), set.frames[0].size(), 100.0 * mean, 100.0 * worst, 100.0 * worst_sym, swaps,
                  segments, inexact, ambiguous);
      accuracy = line;
      worm.print("Sibernetic worm (shell)", set.frames[0].size());
    }
    for (std::size_t count : synthetic) {
      pc::WormShape shape;
      shape.points = count;
      Summary syn;
      double e = 0.0;
      for (int s = 0; s < 5; ++s) {
        shape.seed = static_cast<std::uint32_t>(s + 1);
        shape.phase = 0.7f * static_cast<float>(s);
        const pc::SyntheticWorm w = pc::synthetic_worm(shape);
        pc::SkeletonResult r = pc::point_cloud_skeleton(w.points, *backend, opt);
        syn.add(r);
        e = std::max<double>(e, pc::mean_distance(r.polyline, w.midline, 0.25f) / w.length);
      }
      const std::string label = "synthetic worm (worst error " + std::to_string(100.0 * e).substr(0, 5) + " %)";
      syn.print(label.c_str(), count);
      if (opt.max_points == 0 && count > 4000) {  // the same clouds, subsampled to 4000 points
        pc::SkeletonOptions sub = opt;
        sub.max_points = 4000;
        Summary ss;
        double es = 0.0;
        for (int s = 0; s < 5; ++s) {
          shape.seed = static_cast<std::uint32_t>(s + 1);
          shape.phase = 0.7f * static_cast<float>(s);
          const pc::SyntheticWorm w = pc::synthetic_worm(shape);
          pc::SkeletonResult r = pc::point_cloud_skeleton(w.points, *backend, sub);
          ss.add(r);
          es = std::max<double>(es, pc::mean_distance(r.polyline, w.midline, 0.25f) / w.length);
        }
        const std::string sl = "same, --max-points 4000 (worst error " + std::to_string(100.0 * es).substr(0, 5) + " %)";
        ss.print(sl.c_str(), count);
      }
    }
    if (!accuracy.empty()) std::printf("\n%s", accuracy.c_str());
#ifdef SDFKIT_POINTCLOUD_BENCH_CGAL
    if (cgal) {
      // CGAL's MCF on four frames' membrane meshes, beside the point-cloud method.
      const pc::FrameSet all = pc::read_frames(data, false);
      std::ifstream in(data + "/membranes.txt");
      std::vector<std::array<std::size_t, 3>> tris;
      std::string line;
      while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ls(line);
        std::array<std::size_t, 3> t;
        if (ls >> t[0] >> t[1] >> t[2]) tris.push_back(t);
      }
      std::printf("\n| CGAL MCF on the membrane mesh (%zu triangles) | frame | seconds | skeleton vertices | mean distance to the midline %% |\n|---|---|---|---|---|\n",
                  tris.size());
      for (std::size_t f : {0, 25, 50, 75}) {
        if (f >= all.frames.size()) break;
        double md = 0.0;
        std::size_t nodes = 0;
        const double sec = run_mcf(all.frames[f], tris, mid[f], md, nodes);
        std::printf("| | %zu | %.3f | %zu | %.3f |\n", f, sec, nodes, 100.0 * md / mid[f].length());
      }
    }
#endif
    // The ratio-error curve of compress-animation over the bone count, measured on the glb.
    if (!bone_counts.empty()) {
      const pc::FrameSet all = pc::read_frames(data, false);
      const std::string glb = "/tmp/sdfkit_pointcloud_bench_" + std::to_string(::getpid()) + ".glb";
      std::printf("\n| bones | glb bytes | ratio | RMSE | RMSE %% of length | max error | KG error %% | worst particle (frame) | skeletons s | fit s |\n");
      std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
      for (int bones : bone_counts) {
        pc::CompressionOptions co;
        co.bones = bones;
        co.frame_time = set.frame_time > 0.0 ? set.frame_time : 1.0;
        co.skeleton.sdf = opt.sdf;
        co.rotation = procrustes ? pc::CompressionOptions::Rotation::Procrustes : pc::CompressionOptions::Rotation::Polyline;
        const pc::Compression c = pc::compress_animation(all.frames, set.frames, *backend, co);
        const std::size_t bytes = pc::write_skinned_glb(c.animation, glb);
        const auto played = pc::play_skinned_glb(glb);
        double length = 0.0;
        for (const auto& l : c.bones_per_frame) length += l.length();
        length /= static_cast<double>(c.bones_per_frame.size());
        const pc::CompressionReport r = pc::measure_compression(all.frames, played, bytes, c.animation.bone_count(), length);
        std::size_t wf = 0, wi = 0;
        float we = 0.0f;
        for (std::size_t f = 0; f < played.size(); ++f)
          for (std::size_t i = 0; i < played[f].size(); ++i)
            if (glm::distance(played[f][i], all.frames[f][i]) > we) {
              we = glm::distance(played[f][i], all.frames[f][i]);
              wf = f;
              wi = i;
            }
        std::printf("| %d | %zu | %.1f | %.3f | %.2f | %.2f | %.3f | %zu (%zu) | %.2f | %.2f |\n", bones, bytes, r.ratio, r.rmse,
                    r.rmse_percent, r.max_error, r.kg_error, wi, wf, c.skeleton_ms / 1000.0, c.fit_ms / 1000.0);
      }
      std::remove(glb.c_str());
    }
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "error: %s\n", ex.what());
    return 1;
  }
  return 0;
}
