#include "batch_bench.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/mesh.hpp"
#include "sdfkit/io/asset.hpp"

#include <glm/gtc/quaternion.hpp>

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

extern char** environ;

namespace fs = std::filesystem;

namespace sdfkit::bench {
namespace {

std::string fmt(double v, const char* f = "%.2f") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// The 1-minute load average (/proc/loadavg), -1 where the system does not say.
double load_average() {
  std::ifstream f("/proc/loadavg");
  double l = -1;
  f >> l;
  return l;
}

void write_off(const Mesh& m, const std::string& path) {
  io::write_file_atomically(path, [&](std::ostream& os) {
    os << "OFF\n" << m.positions.size() << ' ' << m.triangles.size() << " 0\n";
    char buf[96];
    for (const glm::vec3& p : m.positions) os.write(buf, std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g\n", p.x, p.y, p.z));
    for (const Triangle& t : m.triangles) os << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  });
}

void write_obj(const Mesh& m, const std::string& path) {
  io::write_file_atomically(path, [&](std::ostream& os) {
    char buf[96];
    for (const glm::vec3& p : m.positions) os.write(buf, std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", p.x, p.y, p.z));
    for (const Triangle& t : m.triangles) os << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  });
}

void write_ply(const Mesh& m, const std::string& path) {
  io::write_file_atomically(path, [&](std::ostream& os) {
    os << "ply\nformat binary_little_endian 1.0\nelement vertex " << m.positions.size()
       << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << m.triangles.size()
       << "\nproperty list uchar int vertex_indices\nend_header\n";
    os.write(reinterpret_cast<const char*>(m.positions.data()),
             static_cast<std::streamsize>(m.positions.size() * sizeof(glm::vec3)));
    for (const Triangle& t : m.triangles) {
      os.put(3);
      os.write(reinterpret_cast<const char*>(t.data()), 12);
    }
  });
}

// Asset `i`: the cow rotated, scaled (0.5..2), moved and jittered (1e-4 of its size), from a
// seed of its own, so the set is the same on every machine.
Mesh variant(const Mesh& cow, int i) {
  std::mt19937 rng(static_cast<std::uint32_t>(0x5dfc0000u + static_cast<std::uint32_t>(i)));
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const glm::quat q = glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)) + glm::quat(1e-3f, 0, 0, 0));
  const float scale = std::exp2(u(rng));
  const glm::vec3 move(10 * u(rng), 10 * u(rng), 10 * u(rng));
  Mesh m = cow;
  for (glm::vec3& p : m.positions) p = scale * (q * (p + 1e-4f * glm::vec3(u(rng), u(rng), u(rng)))) + move;
  return m;
}

struct Child {
  int status = 0;
  double wall_s = 0, cpu_s = 0, peak_rss_mib = 0;
};

Child run(const std::vector<std::string>& args, const std::string& log) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw Error("could not start " + args[0]);
  Child c;
  rusage ru{};
  if (wait4(pid, &c.status, 0, &ru) < 0) throw Error("wait4 failed for " + args[0]);
  c.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  c.cpu_s = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
            1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  c.peak_rss_mib = static_cast<double>(ru.ru_maxrss) / 1024.0;
  return c;
}

}  // namespace

nlohmann::json run_batch_bench(const BatchBenchOptions& o, std::string& markdown) {
  if (o.assets < 1) throw InputError("--batch needs at least one asset");
  fs::create_directories(o.work_dir);
  const std::string cow_path = o.work_dir + "/cow.off";
  if (!fs::exists(cow_path)) {
    const std::string cmd = "tar -xzf " SDFKIT_CGAL_DATA_TARBALL " -C '" + o.work_dir +
                            "' --strip-components=2 data/meshes/cow.off";
    if (std::system(cmd.c_str()) != 0) throw Error("could not extract cow.off from CGAL's data set");
  }
  const Mesh cow = io::load_asset(cow_path).mesh;
  const std::string in = o.work_dir + "/batch-assets-" + std::to_string(o.assets);
  const std::string out = o.work_dir + "/batch-out";
  fs::create_directories(in);
  static const char* kFormats[] = {"off", "ply", "obj"};
  for (int i = 0; i < o.assets; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/cow%05d.%s", i, kFormats[i % 3]);
    const std::string path = in + name;
    if (fs::exists(path)) continue;
    const Mesh m = variant(cow, i);
    if (i % 3 == 0) write_off(m, path);
    else if (i % 3 == 1) write_ply(m, path);
    else write_obj(m, path);
  }
  fs::remove_all(out);
  const std::vector<std::string> args = {o.sdfkit, "batch", in, "--out", out, "--format", o.format, "-j",
                                         std::to_string(o.jobs), "--backend", o.backend, "--rays",
                                         std::to_string(o.rays)};
  std::fprintf(stderr, "sdfkit-bench: sdfkit batch of %d cow-sized assets, -j %d, --backend %s\n", o.assets, o.jobs,
               o.backend.c_str());
  const double load_before = load_average();
  const Child first = run(args, o.work_dir + "/batch-log-1.txt");
  const double load_after = load_average();
  nlohmann::json report;
  if (std::ifstream f(out + "/batch-report.json"); f) report = nlohmann::json::parse(f, nullptr, false);
  const Child again = run(args, o.work_dir + "/batch-log-2.txt");
  nlohmann::json report2;
  if (std::ifstream f(out + "/batch-report.json"); f) report2 = nlohmann::json::parse(f, nullptr, false);

  const auto count = [](const nlohmann::json& r, const char* k) {
    return r.is_object() ? r.value(k, std::size_t{0}) : std::size_t{0};
  };
  const nlohmann::json timing = report.is_object() ? report.value("timing", nlohmann::json::object()) : nlohmann::json::object();
  const nlohmann::json per = timing.value("per_asset_mean_ms", nlohmann::json::object());
  std::ostringstream md;
  md << "| assets | -j | backend | wall s | CPU s (user+sys) | peak RSS MiB | done / failed | sessions (opened in ms) "
        "| rerun, all complete: wall s / skipped | load average before / after |\n"
     << "| ---: | ---: | --- | ---: | ---: | ---: | --- | --- | --- | --- |\n"
     << "| " << o.assets << " | " << o.jobs << " | " << o.backend << " | " << fmt(first.wall_s, "%.1f") << " | "
     << fmt(first.cpu_s, "%.1f") << " | " << fmt(first.peak_rss_mib, "%.0f") << " | " << count(report, "done") << " / "
     << count(report, "failed") << " | " << timing.value("sessions", 0) << " ("
     << fmt(timing.value("sessions_ms", 0.0), "%.0f") << ") | " << fmt(again.wall_s, "%.1f") << " / "
     << count(report2, "skipped") << " | " << fmt(load_before) << " / " << fmt(load_after) << " |";
  if (first.status != 0) md << " (exit status " << first.status << ")";
  md << "\n\nPer asset, mean ms over the assets computed (stages of the two workers overlap):\n\n| ";
  std::ostringstream rule;
  rule << "| ";
  std::ostringstream row;
  row << "| ";
  for (const auto& [stage, ms] : per.items()) {
    md << stage << " | ";
    rule << "---: | ";
    row << fmt(ms.get<double>()) << " | ";
  }
  md << "\n" << rule.str() << "\n" << row.str() << "\n";
  markdown = md.str();
  return {{"assets", o.assets}, {"jobs", o.jobs}, {"backend", o.backend}, {"rays", o.rays},
          {"wall_s", first.wall_s}, {"cpu_s", first.cpu_s}, {"peak_rss_mib", first.peak_rss_mib},
          {"exit_status", first.status}, {"load_average_before", load_before}, {"load_average_after", load_after},
          {"report", report}, {"rerun_wall_s", again.wall_s}, {"rerun_skipped", count(report2, "skipped")}};
}

}  // namespace sdfkit::bench
