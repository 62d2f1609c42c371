#include "huge_bench.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/mesh.hpp"
#include "sdfkit/io/asset.hpp"

#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

extern char** environ;

namespace fs = std::filesystem;

namespace sdfkit::bench {
namespace {

// Binary little-endian PLY: float x y z, uchar 3 + int indices.
void write_binary_ply(const Mesh& m, const std::string& path) {
  io::write_file_atomically(path, [&](std::ostream& os) {
    os << "ply\nformat binary_little_endian 1.0\ncomment CGAL armadillo, midpoint-subdivided\nelement vertex "
       << m.positions.size() << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
       << m.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
    os.write(reinterpret_cast<const char*>(m.positions.data()),
             static_cast<std::streamsize>(m.positions.size() * sizeof(glm::vec3)));
    std::string block;
    block.reserve(13 * 65536);
    for (std::size_t f = 0; f < m.triangles.size(); ++f) {
      block.push_back(3);
      block.append(reinterpret_cast<const char*>(m.triangles[f].data()), 12);
      if (block.size() >= 13 * 65535) os.write(block.data(), static_cast<std::streamsize>(block.size())), block.clear();
    }
    os.write(block.data(), static_cast<std::streamsize>(block.size()));
  });
}

void write_obj(const Mesh& m, const std::string& path) {
  io::write_file_atomically(path, [&](std::ostream& os) {
    std::string block;
    char buf[64];
    const auto flush = [&](bool force) {
      if (force || block.size() > (1u << 20)) os.write(block.data(), static_cast<std::streamsize>(block.size())), block.clear();
    };
    block += "# CGAL armadillo, midpoint-subdivided\n";
    for (const glm::vec3& p : m.positions) {
      block += 'v';
      for (int k = 0; k < 3; ++k) {
        block += ' ';
        block.append(buf, std::to_chars(buf, buf + sizeof buf, p[k]).ptr);  // shortest round-trip
      }
      block += '\n';
      flush(false);
    }
    for (const Triangle& t : m.triangles) {
      block += 'f';
      for (int k = 0; k < 3; ++k) {
        block += ' ';
        block.append(buf, std::to_chars(buf, buf + sizeof buf, t[k] + 1).ptr);
      }
      block += '\n';
      flush(false);
    }
    flush(true);
  });
}

struct ChildRun {
  int status = 0;
  double wall_s = 0, peak_rss_mib = 0, cpu_s = 0;
};

// Runs argv[0] with argv, stdout/stderr inherited; the child's peak RSS from wait4.
ChildRun run_child(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0)
    throw Error("could not start " + args[0]);
  ChildRun r;
  rusage ru{};
  if (wait4(pid, &r.status, 0, &ru) < 0) throw Error("wait4 failed for " + args[0]);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.peak_rss_mib = static_cast<double>(ru.ru_maxrss) / 1024.0;
  r.cpu_s = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
            1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  return r;
}

std::string fmt(double v, const char* f = "%.2f") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

std::string huge_mesh_path(const HugeOptions& o, int level, const std::string& format) {
  return o.work_dir + "/armadillo-subdiv" + std::to_string(level) + "." + format;
}

void generate_huge_meshes(const HugeOptions& o) {
  fs::create_directories(o.work_dir);
  bool all = true;
  for (int level : o.levels)
    for (const auto& f : o.formats) all = all && fs::exists(huge_mesh_path(o, level, f));
  if (all) return;
  const std::string armadillo = o.work_dir + "/armadillo.off";
  if (!fs::exists(armadillo)) {
    const std::string cmd = "tar -xzf " SDFKIT_CGAL_DATA_TARBALL " -C '" + o.work_dir +
                            "' --strip-components=2 data/meshes/armadillo.off";
    if (std::system(cmd.c_str()) != 0) throw Error("could not extract armadillo.off from CGAL's data set");
  }
  Mesh m = io::load_asset(armadillo).mesh;
  int level = 0;
  for (int want : o.levels) {
    while (level < want) m = subdivide_midpoint(m), ++level;
    std::fprintf(stderr, "sdfkit-bench: armadillo level %d: %zu vertices, %zu triangles\n", level,
                 m.positions.size(), m.triangles.size());
    for (const auto& f : o.formats) {
      const std::string path = huge_mesh_path(o, level, f);
      if (fs::exists(path)) continue;
      if (f == "ply") write_binary_ply(m, path);
      else if (f == "obj") write_obj(m, path);
      else throw InputError("--huge formats: ply or obj, got '" + f + "'");
    }
  }
}

nlohmann::json run_huge(const HugeOptions& o, std::string& markdown) {
  generate_huge_meshes(o);
  nlohmann::json runs = nlohmann::json::array();
  std::ostringstream md;
  md << "| mesh | format | file MB | triangles | read s | weld s | orient s | BVH build s | upload s | trace s | write s | "
        "wall s | peak RSS MiB | peak after load / build+upload / trace / write MiB |\n"
     << "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |\n";
  for (int level : o.levels)
    for (const auto& f : o.formats) {
      const std::string input = huge_mesh_path(o, level, f);
      const std::string stem = o.work_dir + "/out-subdiv" + std::to_string(level) + "-" + f;
      std::fprintf(stderr, "sdfkit-bench: sdfkit compute %s --backend %s\n", input.c_str(), o.backend.c_str());
      fs::remove(stem + ".json");
      const ChildRun c = run_child({o.sdfkit, "compute", input, "-o", stem + ".ply", "--backend", o.backend,
                                    "--rays", std::to_string(o.rays), "--json", stem + ".json"});
      nlohmann::json j = {{"mesh", "armadillo-subdiv" + std::to_string(level)}, {"format", f},
                          {"file_bytes", fs::file_size(input)}, {"wall_s", c.wall_s},
                          {"cpu_s", c.cpu_s}, {"peak_rss_mib", c.peak_rss_mib}, {"exit_status", c.status}};
      nlohmann::json report;
      if (std::ifstream in(stem + ".json"); in) report = nlohmann::json::parse(in, nullptr, false);
      if (report.is_object()) j["report"] = report;
      const auto t = [&](const char* stage) {
        const auto& tm = report.is_object() ? report.value("time_ms", nlohmann::json::object()) : nlohmann::json::object();
        return tm.contains(stage) ? fmt(tm[stage].get<double>() / 1000.0) : std::string("–");
      };
      const auto mem = [&](const char* stage) {
        if (!report.is_object() || !report.contains("memory_mib") || !report["memory_mib"].contains(stage))
          return std::string("–");
        return fmt(report["memory_mib"][stage]["peak_rss"].get<double>(), "%.0f");
      };
      const std::size_t faces = report.is_object() ? report["counts"].value("input_faces", std::size_t{0}) : 0;
      md << "| armadillo-subdiv" << level << " | " << f << " | " << fmt(static_cast<double>(fs::file_size(input)) / 1e6, "%.0f")
         << " | " << faces << " | " << t("read") << " | " << t("weld") << " | " << t("orient") << " | " << t("bvh_build") << " | "
         << t("upload") << " | " << t("trace_gather") << " | " << t("write") << " | " << fmt(c.wall_s, "%.1f") << " | "
         << fmt(c.peak_rss_mib, "%.0f") << " | " << mem("weld") << " / " << mem("set_mesh")
         << " / " << mem("sdf") << " / " << mem("write") << " |";
      if (c.status != 0) md << " (exit status " << c.status << ")";
      md << "\n";
      runs.push_back(j);
      fs::remove(stem + ".ply");
    }
  markdown = md.str();
  return {{"runs", runs}};
}

}  // namespace sdfkit::bench
