#include "bench_runner.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/sdf.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/post/smooth.hpp"
#include "sdfkit/reference/embree_backend.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

namespace sdfkit::bench {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

double cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) / 1e6;
}

double children_cpu_s() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e6;
}

// Peak resident set size of this process so far, MiB (Linux reports ru_maxrss in KiB).
double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void write_off(const Mesh& m, const std::string& path) {
  io::write_file_atomically(path, [&](std::ostream& os) {
    os << "OFF\n" << m.positions.size() << ' ' << m.triangles.size() << " 0\n";
    char line[128];
    for (const auto& p : m.positions) {
      std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", p.x, p.y, p.z);
      os << line;
    }
    for (const auto& t : m.triangles) os << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  });
}

// Runs a command, returns its standard output; throws Error on a non-zero exit.
std::string run_process(const std::string& command) {
  FILE* pipe = popen((command + " 2>/dev/null").c_str(), "r");
  if (!pipe) throw Error("could not start: " + command);
  std::string out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
  const int status = pclose(pipe);
  if (status != 0) throw Error("command failed (status " + std::to_string(status) + "): " + command);
  return out;
}

double stage_ms(const std::vector<StageTiming>& stages, const std::string& prefix) {
  double t = 0;
  for (const auto& s : stages)
    if (s.stage.rfind(prefix, 0) == 0) t += s.milliseconds;
  return t;
}

std::unique_ptr<SdfBackend> make(const std::string& name, const BenchOptions& o, int views, int resolution) {
  if (name == "embree") return std::make_unique<reference::EmbreeBackend>();
  BackendConfig c;
  c.kind = parse_backend_kind(name == "opencl-octree" ? "opencl" : name);
  if (name == "opencl-octree") c.accel = "octree";
  c.device = o.device;
  c.views = views;
  c.resolution = resolution;
  c.vulkan_mode = o.vulkan_mode;
  c.profile = o.profile;
  return make_backend(c);
}

// Times one backend on one mesh: a cold call, then `repeats` warm calls on moved (here:
// identical) positions through update_positions, as the skeleton loop does (the OpenCL BVH is
// refit then), or with `full_calls` through set_mesh and a new query each time: everything a
// one-off call on a warm session does (the CGAL comparison).
BackendRun time_backend(const std::string& name, const Mesh& mesh, const SdfOptions& sdf,
                        const BenchOptions& o, int views, int resolution, const std::string& mode,
                        const std::vector<float>* reference_values, std::vector<float>* values_out,
                        bool full_calls = false) {
  BackendRun run;
  run.backend = name;
  run.mode = mode;
  try {
    auto t0 = Clock::now();
    auto backend = make(name, o, views, resolution);
    run.session_ms = ms_since(t0);
    run.device = backend->device_name();
    const SdfQuery query = make_query(mesh, sdf.domain);
    t0 = Clock::now();
    backend->set_mesh(mesh);
    RawSdf raw = backend->compute(query, sdf);
    run.first_ms = ms_since(t0);
    std::vector<double> warm, warm_cpu;
    for (int r = 0; r < o.repeats; ++r) {
      t0 = Clock::now();
      const double c0 = cpu_ms();
      if (full_calls) {
        backend->set_mesh(mesh);
        raw = backend->compute(make_query(mesh, sdf.domain), sdf);
      } else {
        backend->update_positions(mesh.positions);
        raw = backend->compute(query, sdf);
      }
      warm.push_back(ms_since(t0));
      warm_cpu.push_back(cpu_ms() - c0);
    }
    run.repeat_ms = warm.empty() ? run.first_ms : median(warm);
    run.repeat_cpu_ms = warm_cpu.empty() ? 0.0 : median(warm_cpu);
    run.stages = backend->last_timings();
    run.device_bytes = backend->device_memory_bytes();
    run.peak_rss_mib = peak_rss_mib();
    std::size_t valid = 0;
    for (auto v : query.valid) valid += v;
    double trace = stage_ms(run.stages, "trace");
    if (trace <= 0) trace = run.repeat_ms;
    if (name != "vulkan") run.rays_per_second = static_cast<double>(valid) * sdf.rays / (trace / 1000.0);
    const SdfField field = finish_field(mesh, sdf.domain, std::move(raw));
    if (reference_values) run.vs_reference = compare_fields(field.values, *reference_values);
    if (values_out) *values_out = field.values;
  } catch (const std::exception& e) {
    run.error = e.what();
  }
  return run;
}

// MeshLab's GPU "Shape Diameter Function" filter under xvfb-run; the filter's time is the run
// with the filter minus a run that only loads and saves.
double meshlab_seconds(const std::string& off, int views, int resolution, const std::string& work) {
  const std::string sdf_script = work + "/meshlab_sdf.mlx", noop_script = work + "/meshlab_noop.mlx";
  std::ofstream(sdf_script) << "<!DOCTYPE FilterScript>\n<FilterScript>\n"
    " <filter name=\"Shape Diameter Function\">\n"
    "  <Param type=\"RichEnum\" value=\"0\" name=\"onPrimitive\" enum_val0=\"On vertices\" enum_val1=\"On Faces\" enum_cardinality=\"2\"/>\n"
    "  <Param type=\"RichInt\" value=\"" << views << "\" name=\"numberRays\"/>\n"
    "  <Param type=\"RichInt\" value=\"" << resolution << "\" name=\"DepthTextureSize\"/>\n"
    "  <Param type=\"RichInt\" value=\"10\" name=\"peelingIteration\"/>\n"
    "  <Param type=\"RichFloat\" value=\"1e-07\" name=\"peelingTolerance\"/>\n"
    "  <Param type=\"RichFloat\" value=\"120\" name=\"coneAngle\"/>\n"
    "  <Param type=\"RichBool\" value=\"true\" name=\"removeFalse\"/>\n"
    "  <Param type=\"RichBool\" value=\"true\" name=\"removeOutliers\"/>\n"
    " </filter>\n</FilterScript>\n";
  std::ofstream(noop_script) << "<!DOCTYPE FilterScript>\n<FilterScript>\n</FilterScript>\n";
  auto timed = [&](const std::string& script) {
    const std::string cmd = "xvfb-run -a -s '-screen 0 1024x768x24' meshlabserver -i '" + off + "' -o '" + work +
                            "/meshlab_out.ply' -m vq -s '" + script + "' >/dev/null";
    const auto t0 = Clock::now();
    run_process(cmd);
    return ms_since(t0) / 1000.0;
  };
  const double with_filter = timed(sdf_script);
  const double without = timed(noop_script);
  return std::max(0.0, with_filter - without);
}

}  // namespace

BenchMesh load_mesh(const std::string& path, const std::string& work_dir) {
  BenchMesh m;
  m.name = fs::path(path).stem().string();
  m.mesh = io::load_asset(path).mesh;
  if (fs::path(path).extension() == ".off") {
    m.off_path = path;
  } else {
    m.off_path = work_dir + "/" + m.name + ".off";
    write_off(m.mesh, m.off_path);
  }
  return m;
}

std::vector<BenchMesh> default_meshes(const std::string& work_dir, bool large) {
  fs::create_directories(work_dir);
  const std::vector<std::string> names = {"elephant", "armadillo", "bunny00", "refined_elephant"};
  std::string members;
  for (const auto& n : names) members += " data/meshes/" + n + ".off";
  run_process("tar -xzf " SDFKIT_CGAL_DATA_TARBALL " -C '" + work_dir + "' --strip-components=2" + members);
  std::vector<BenchMesh> out;
  for (const auto& n : names) out.push_back(load_mesh(work_dir + "/" + n + ".off", work_dir));
  if (large) {
    BenchMesh buddha;  // ~150k vertices, the paper's Buddha size
    buddha.name = "bunny00-subdiv1";
    buddha.mesh = subdivide_midpoint(out[2].mesh);
    buddha.off_path = work_dir + "/" + buddha.name + ".off";
    write_off(buddha.mesh, buddha.off_path);
    out.push_back(std::move(buddha));
    BenchMesh gargoyle;  // ~416k vertices, near the paper's Gargoyle size
    gargoyle.name = "armadillo-subdiv2";
    gargoyle.mesh = subdivide_midpoint(subdivide_midpoint(out[1].mesh));
    gargoyle.off_path = work_dir + "/" + gargoyle.name + ".off";
    write_off(gargoyle.mesh, gargoyle.off_path);
    out.push_back(std::move(gargoyle));
  }
  return out;
}

MeshResult run_mesh(const BenchMesh& bm, const BenchOptions& o) {
  MeshResult r;
  r.name = bm.name;
  r.vertices = bm.mesh.positions.size();
  r.faces = bm.mesh.triangles.size();
  const std::string work = fs::path(bm.off_path).parent_path().string();

  // The default table: per vertex, o.rays rays; the reference first, the others against it.
  SdfOptions sdf;
  sdf.rays = o.rays;
  std::vector<float> reference_values;
  const bool have_embree = std::find(o.backends.begin(), o.backends.end(), "embree") != o.backends.end();
  if (have_embree) {
    r.runs.push_back(time_backend("embree", bm.mesh, sdf, o, 0, 0,
                                  "vertex, " + std::to_string(o.rays) + " rays", nullptr, &reference_values));
  }
  const std::vector<float>* ref = reference_values.empty() ? nullptr : &reference_values;
  for (const std::string& b : o.backends) {
    if (b == "embree") continue;
    const bool vk = b == "vulkan";
    const std::string mode = vk ? "vertex, default views" : "vertex, " + std::to_string(o.rays) + " rays";
    r.runs.push_back(time_backend(b, bm.mesh, sdf, o, o.views, o.resolution, mode, ref, nullptr));
  }

  // The CGAL comparison: per face, 25 rays (sdf_values computes per face).
  if (o.cgal) {
    try {
      const double c0 = children_cpu_s();
      const std::string out = run_process("'" + o.cgal_helper + "' '" + bm.off_path + "' " + std::to_string(o.cgal_rays));
      r.cgal_seconds = nlohmann::json::parse(out).at("seconds").get<double>();
      r.cgal_cpu_seconds = children_cpu_s() - c0;
    } catch (const std::exception& e) {
      r.cgal_error = e.what();
    }
    SdfOptions face = sdf;
    face.domain = SdfDomain::Face;
    face.rays = o.cgal_rays;
    for (const std::string& b : o.backends)
      if (b != "vulkan")
        r.runs.push_back(time_backend(b, bm.mesh, face, o, 0, 0, "face, " + std::to_string(o.cgal_rays) + " rays, set_mesh every call",
                                      nullptr, nullptr, /*full_calls=*/true));
  }

  // The MeshLab comparison: per vertex, 128 views at 512 x 512.
  if (o.meshlab) {
    try {
      r.meshlab_seconds = meshlab_seconds(bm.off_path, o.meshlab_views, o.meshlab_resolution, work);
    } catch (const std::exception& e) {
      r.meshlab_error = e.what();
    }
    if (std::find(o.backends.begin(), o.backends.end(), "vulkan") != o.backends.end())
      r.runs.push_back(time_backend("vulkan", bm.mesh, sdf, o, o.meshlab_views, o.meshlab_resolution,
                                    "vertex, " + std::to_string(o.meshlab_views) + " views " +
                                        std::to_string(o.meshlab_resolution) + "px",
                                    ref, nullptr));
  }

  if (o.smooth_rings > 0) {
    std::vector<float> values(bm.mesh.positions.size(), 1.0f);
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(i % 17);
    SmoothOptions s;
    s.rings = o.smooth_rings;
    smooth_field(bm.mesh, SdfDomain::Vertex, values, s);  // warm-up (page faults, threads)
    std::vector<double> t;
    for (int k = 0; k < 3; ++k) {
      const auto t0 = Clock::now();
      smooth_field(bm.mesh, SdfDomain::Vertex, values, s);
      t.push_back(ms_since(t0));
    }
    r.smooth_ms = median(t);
  }
  return r;
}

nlohmann::json to_json(const std::vector<MeshResult>& results, const BenchOptions& o) {
  nlohmann::json j;
  j["options"] = {{"rays", o.rays}, {"cgal_rays", o.cgal_rays}, {"views", o.views}, {"resolution", o.resolution},
                  {"repeats", o.repeats}, {"smooth_rings", o.smooth_rings}};
  for (const MeshResult& m : results) {
    nlohmann::json jm = {{"mesh", m.name}, {"vertices", m.vertices}, {"faces", m.faces}};
    for (const BackendRun& b : m.runs) {
      nlohmann::json jb = {{"backend", b.backend}, {"device", b.device}, {"mode", b.mode},
                           {"session_ms", b.session_ms}, {"first_ms", b.first_ms}, {"repeat_ms", b.repeat_ms}, {"repeat_cpu_ms", b.repeat_cpu_ms},
                           {"rays_per_second", b.rays_per_second}, {"device_bytes", b.device_bytes},
                           {"peak_rss_mib_after", b.peak_rss_mib}};
      nlohmann::json st = nlohmann::json::object();
      for (const auto& s : b.stages) st[s.stage] = s.milliseconds;
      jb["stages_ms"] = st;
      if (b.vs_reference)
        jb["vs_reference"] = {{"pearson", b.vs_reference->pearson},
                              {"median_relative", b.vs_reference->median_relative},
                              {"p95_relative", b.vs_reference->p95_relative}};
      if (!b.error.empty()) jb["error"] = b.error;
      jm["runs"].push_back(jb);
    }
    if (m.cgal_seconds) jm["cgal_sdf_values_s"] = *m.cgal_seconds;
    if (m.cgal_cpu_seconds) jm["cgal_process_cpu_s"] = *m.cgal_cpu_seconds;
    if (!m.cgal_error.empty()) jm["cgal_error"] = m.cgal_error;
    if (m.meshlab_seconds) jm["meshlab_sdf_s"] = *m.meshlab_seconds;
    if (!m.meshlab_error.empty()) jm["meshlab_error"] = m.meshlab_error;
    if (m.smooth_ms) jm["smooth_ms"] = *m.smooth_ms;
    j["meshes"].push_back(jm);
  }
  j["peak_rss_mib"] = peak_rss_mib();
  return j;
}

namespace {
const BackendRun* find_run(const MeshResult& m, const std::string& backend, const std::string& mode_prefix) {
  for (const auto& r : m.runs)
    if (r.backend == backend && r.mode.rfind(mode_prefix, 0) == 0 && r.error.empty()) return &r;
  return nullptr;
}
// "wall (CPU)" seconds of the median warm call.
std::string fmt_s(const BackendRun* r) {
  if (!r) return "–";
  char b[64];
  std::snprintf(b, sizeof b, "%.3f (%.3f)", r->repeat_ms / 1000.0, r->repeat_cpu_ms / 1000.0);
  return b;
}
std::string fmt(double v, const char* f) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
}  // namespace

std::string to_markdown(const std::vector<MeshResult>& results, const BenchOptions& o) {
  std::ostringstream md;
  md << "SDF per vertex; Vulkan at its default views/resolution, ray backends at " << o.rays
     << " rays. Times are seconds of a warm call (update_positions + compute, median of " << o.repeats
     << ") as wall clock (process CPU time, all threads, in brackets).\n\n";
  md << "| mesh | vertices | faces | Vulkan s | OpenCL BVH s | OpenCL octree s | Embree s | OpenCL Mrays/s | Embree Mrays/s | "
        "OpenCL vs Embree (median rel. / Pearson) | Vulkan vs Embree | smooth k=" << o.smooth_rings << " ms |\n";
  md << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---:|\n";
  for (const MeshResult& m : results) {
    const auto* vk = find_run(m, "vulkan", "vertex, default");
    const auto* cl = find_run(m, "opencl", "vertex");
    const auto* oct = find_run(m, "opencl-octree", "vertex");
    const auto* em = find_run(m, "embree", "vertex");
    auto cmp = [](const BackendRun* r) {
      if (!r || !r->vs_reference) return std::string("–");
      return fmt(100 * r->vs_reference->median_relative, "%.2f%%") + " / " + fmt(r->vs_reference->pearson, "%.4f");
    };
    md << "| " << m.name << " | " << m.vertices << " | " << m.faces << " | " << fmt_s(vk) << " | " << fmt_s(cl)
       << " | " << fmt_s(oct) << " | " << fmt_s(em) << " | " << (cl ? fmt(cl->rays_per_second / 1e6, "%.2f") : "–") << " | "
       << (em ? fmt(em->rays_per_second / 1e6, "%.2f") : "–") << " | " << cmp(cl) << " | " << cmp(vk) << " | "
       << (m.smooth_ms ? fmt(*m.smooth_ms, "%.1f") : "–") << " |\n";
  }
  if (o.cgal) {
    md << "\nAgainst CGAL `sdf_values` (per face, " << o.cgal_rays << " rays, one process each; "
          "sdfkit's time is a whole call on a warm session: query, set_mesh with a new BVH, "
          "compute):\n\n";
    md << "| mesh | faces | CGAL s | OpenCL s | Embree s | CGAL / OpenCL (wall) | CGAL / OpenCL (CPU) |\n"
          "|---|---:|---:|---:|---:|---:|---:|\n";
    for (const MeshResult& m : results) {
      const auto* cl = find_run(m, "opencl", "face");
      const auto* em = find_run(m, "embree", "face");
      md << "| " << m.name << " | " << m.faces << " | "
         << (m.cgal_seconds ? fmt(*m.cgal_seconds, "%.2f") + " (" + fmt(m.cgal_cpu_seconds.value_or(0), "%.2f") + ")"
                            : "– " + m.cgal_error)
         << " | " << fmt_s(cl) << " | " << fmt_s(em) << " | "
         << (m.cgal_seconds && cl ? fmt(*m.cgal_seconds / (cl->repeat_ms / 1000.0), "%.1f×") : "–") << " | "
         << (m.cgal_cpu_seconds && cl && cl->repeat_cpu_ms > 0 ? fmt(*m.cgal_cpu_seconds / (cl->repeat_cpu_ms / 1000.0), "%.1f×") : "–")
         << " |\n";
    }
  }
  if (o.meshlab) {
    md << "\nAgainst MeshLab's GPU Shape Diameter Function filter (per vertex, " << o.meshlab_views << " views, "
       << o.meshlab_resolution << "², meshlabserver under xvfb-run on Mesa llvmpipe):\n\n";
    md << "| mesh | MeshLab s | Vulkan s | MeshLab / Vulkan |\n|---|---:|---:|---:|\n";
    for (const MeshResult& m : results) {
      const auto* vk = find_run(m, "vulkan", "vertex, " + std::to_string(o.meshlab_views) + " views");
      md << "| " << m.name << " | " << (m.meshlab_seconds ? fmt(*m.meshlab_seconds, "%.2f") : "– " + m.meshlab_error)
         << " | " << fmt_s(vk) << " | "
         << (m.meshlab_seconds && vk ? fmt(*m.meshlab_seconds / (vk->repeat_ms / 1000.0), "%.1f×") : "–") << " |\n";
    }
  }
  md << "\nRepeated calls (the skeleton loop's pattern): creating a session, the first call on it (set_mesh + "
        "compute), and a warm call (update_positions + compute, or set_mesh + compute where the mode "
        "says so), wall seconds:\n\n"
        "| mesh | backend | mode | session s | first call s | warm call s |\n|---|---|---|---:|---:|---:|\n";
  for (const MeshResult& m : results)
    for (const BackendRun& b : m.runs)
      if (b.error.empty())
        md << "| " << m.name << " | " << b.backend << " | " << b.mode << " | " << fmt(b.session_ms / 1000.0, "%.3f")
           << " | " << fmt(b.first_ms / 1000.0, "%.3f")
           << " | " << fmt(b.repeat_ms / 1000.0, "%.3f") << " |\n";
  md << "\nPer-stage times of the last call (ms) and the memory the backend reports for its session "
        "(device buffers: geometry and per-batch; Embree: the peak its scene allocated, on the "
        "host):\n\n"
        "| mesh | backend | mode | stages | backend MiB |\n|---|---|---|---|---:|\n";
  for (const MeshResult& m : results)
    for (const BackendRun& b : m.runs) {
      std::string st;
      for (const auto& s : b.stages) st += s.stage + " " + fmt(s.milliseconds, "%.1f") + ", ";
      if (!b.error.empty()) st = "error: " + b.error;
      md << "| " << m.name << " | " << b.backend << " | " << b.mode << " | " << st << " | "
         << (b.device_bytes > 0 ? fmt(static_cast<double>(b.device_bytes) / (1 << 20), "%.1f") : "–") << " |\n";
    }
  md << "\nPeak resident memory of the benchmark process (all backends, all meshes): "
     << fmt(peak_rss_mib(), "%.0f") << " MiB.\n";
  return md.str();
}

}  // namespace sdfkit::bench
