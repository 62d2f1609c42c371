#include "sdfkit/batch.hpp"

#include "sdfkit/core/error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

namespace sdfkit {
namespace fs = std::filesystem;
namespace {

bool is_mesh_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".gltf" || ext == ".glb" || ext == ".obj" || ext == ".off" || ext == ".ply";
}

bool is_manifest(const std::string& s) {
  const std::string ext = fs::path(s).extension().string();
  return ext == ".list" || ext == ".manifest" || ext == ".txt";  // .txt is no mesh input format
}

// `manifests`: those already expanded; one listed again (by itself, or twice) adds nothing new,
// so it is read once: a manifest naming itself N times stays linear, not N^depth.
// `path` is a file, directory or (`manifest`) a manifest; no '@' prefix is parsed here, so a
// file named "@x.off" reached through a manifest stays a file.
void expand_path(const std::string& path, bool manifest, std::set<std::string>& out,
                 std::set<std::string>& manifests, int depth) {
  if (depth > 8) throw InputError(path + ": manifests nest too deeply");
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path + ": no such file or directory");
  if (fs::is_directory(path, ec)) {
    for (auto it = fs::recursive_directory_iterator(path, fs::directory_options::skip_permission_denied, ec);
         it != fs::recursive_directory_iterator(); it.increment(ec)) {
      if (ec) break;
      if (it->is_regular_file(ec) && is_mesh_file(it->path())) out.insert(it->path().lexically_normal().string());
    }
    return;
  }
  if (manifest) {
    if (!manifests.insert(fs::weakly_canonical(path, ec).string()).second) return;
    std::ifstream f(path);
    if (!f) throw InputError(path + ": cannot read the manifest");
    const fs::path base = fs::path(path).parent_path();
    std::string line;
    while (std::getline(f, line)) {
      const auto b = line.find_first_not_of(" \t\r");
      if (b == std::string::npos || line[b] == '#') continue;
      const auto e = line.find_last_not_of(" \t\r");
      std::string entry = line.substr(b, e - b + 1);
      // "@FILE" names a manifest as on the command line, FILE relative to this manifest.
      const bool nested = entry[0] == '@';
      if (nested) entry.erase(0, 1);
      if (entry.empty()) throw InputError(path + ": a line '@' names no manifest");
      fs::path p = entry;
      if (p.is_relative()) p = base / p;
      const std::string resolved = p.lexically_normal().string();
      expand_path(resolved, nested || is_manifest(resolved), out, manifests, depth + 1);
    }
    return;
  }
  out.insert(fs::path(path).lexically_normal().string());
}

// A command-line input: "@FILE" is the manifest FILE.
void expand_one(const std::string& input, std::set<std::string>& out, std::set<std::string>& manifests) {
  if (!input.empty() && input[0] == '@') return expand_path(input.substr(1), true, out, manifests, 0);
  expand_path(input, is_manifest(input), out, manifests, 0);
}

// The output file as it is now (size and modification time); empty when there is none. The record
// keeps the stamp of the output it was written for, so an output replaced after its record (a run
// with other options killed between its output's rename and its record's) is not taken for that
// record's result.
std::string output_stamp(const std::string& output) {
  std::error_code ec;
  const auto size = fs::file_size(output, ec);
  if (ec) return {};
  const auto mtime = fs::last_write_time(output, ec).time_since_epoch().count();
  if (ec) return {};
  return " output=" + std::to_string(size) + "/" + std::to_string(mtime);
}

// A result is complete when its record says ok with the same fingerprint, written for the output
// that exists now.
bool complete(const std::string& output, const std::string& record, const std::string& print) {
  std::error_code ec;
  const std::string stamp = output_stamp(output);
  if (stamp.empty() || !fs::exists(record, ec)) return false;
  try {
    std::ifstream f(record);
    const auto j = nlohmann::json::parse(f);
    return j.value("ok", false) && j.value("fingerprint", std::string()) == print + stamp;
  } catch (const std::exception&) {
    return false;
  }
}

std::string record_path(const std::string& output) {
  return (fs::path(output).parent_path() / fs::path(output).stem()).string() + ".json";
}

double ms_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// Whether `name` is `target` + ".tmp-" + 8 of [a-z0-9]: a temporary of io::write_file_atomically.
bool is_temporary_of(const std::string& name, const std::set<std::string>& targets) {
  static constexpr std::size_t kSuffix = 5 + 8;  // ".tmp-" and the random part
  if (name.size() <= kSuffix || name.compare(name.size() - kSuffix, 5, ".tmp-") != 0) return false;
  for (std::size_t i = name.size() - 8; i < name.size(); ++i)
    if (!std::islower(static_cast<unsigned char>(name[i])) && !std::isdigit(static_cast<unsigned char>(name[i])))
      return false;
  return targets.count(name.substr(0, name.size() - kSuffix)) > 0;
}

// Removes the temporaries a killed run left beside `files` (all in `dir`); returns how many.
std::size_t remove_stale_temporaries(const std::string& dir, const std::vector<std::string>& files) {
  std::set<std::string> targets;
  for (const auto& f : files) targets.insert(fs::path(f).filename().string());
  std::size_t removed = 0;
  std::error_code ec;
  for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::error_code rm;
    if (is_temporary_of(name, targets) && it->is_regular_file(rm) && fs::remove(it->path(), rm)) ++removed;
  }
  return removed;
}


}  // namespace

namespace {

std::string fingerprint_with(const std::string& input, const std::string& options_json) {
  std::error_code ec;
  const auto size = fs::file_size(input, ec);
  const auto mtime = fs::last_write_time(input, ec).time_since_epoch().count();
  return "v2 size=" + std::to_string(size) + " mtime=" + std::to_string(mtime) + " options=" + options_json;
}

}  // namespace

std::string batch_fingerprint(const std::string& input, const BatchOptions& o) {
  return fingerprint_with(input, options_to_json(o.base));
}

std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs) {
  std::set<std::string> out, manifests;
  for (const auto& in : inputs) expand_one(in, out, manifests);
  return {out.begin(), out.end()};
}

std::pair<int, int> parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("no slash");
    std::size_t a = 0, b = 0;
    const int i = std::stoi(text.substr(0, slash), &a);
    const int n = std::stoi(text.substr(slash + 1), &b);
    if (a != slash || b != text.size() - slash - 1 || n < 1 || i < 0 || i >= n) throw std::invalid_argument("range");
    return {i, n};
  } catch (const std::exception&) {
    throw UsageError("--shard expects I/N with 0 <= I < N, got '" + text + "'");
  }
}

std::vector<std::string> select_shard(const std::vector<std::string>& inputs, int index, int count) {
  std::vector<std::string> out;
  for (std::size_t k = static_cast<std::size_t>(index); k < inputs.size(); k += static_cast<std::size_t>(count))
    out.push_back(inputs[k]);
  return out;
}

std::vector<std::string> plan_outputs(const std::vector<std::string>& inputs, const std::string& out_dir,
                                      const std::string& format) {
  std::map<std::string, int> stems;
  for (const auto& in : inputs) ++stems[fs::path(in).stem().string()];
  std::vector<std::string> out;
  for (const auto& in : inputs) {
    std::string stem = fs::path(in).stem().string();
    if (stems[stem] > 1) {
      // FNV-1a of the full path: stable across runs and machines.
      std::uint64_t h = 1469598103934665603ull;
      for (unsigned char c : in) h = (h ^ c) * 1099511628211ull;
      char buf[17];
      std::snprintf(buf, sizeof buf, "%08llx", static_cast<unsigned long long>(h & 0xffffffffull));
      stem += std::string("-") + buf;
    }
    out.push_back((fs::path(out_dir) / (stem + "." + format)).string());
  }
  return out;
}

BatchSummary run_batch(const std::vector<std::string>& inputs, const BatchOptions& o, const BatchProgress& progress) {
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  static const std::set<std::string> formats = {"glb", "gltf", "ply", "txt"};
  if (!formats.count(o.format)) throw UsageError("--format must be glb, gltf, ply or txt, got '" + o.format + "'");
  if (o.jobs < 1 || o.jobs > 64) throw UsageError("--jobs must be between 1 and 64");
  {
    ComputeRequest probe = o.base;
    probe.output = "x." + o.format;
    validate(probe);
    if (o.format == "glb" || o.format == "gltf") io::check_output(probe.output, probe.sdf.domain);
  }
  std::error_code ec;
  fs::create_directories(o.out_dir, ec);
  if (ec || !fs::is_directory(o.out_dir)) throw InputError(o.out_dir + ": cannot create the output directory");

  BatchSummary summary;
  BatchTiming& timing = summary.timing;
  summary.report = (fs::path(o.out_dir) / o.report_name).string();
  const auto outputs = plan_outputs(inputs, o.out_dir, o.format);
  {
    const auto t0 = clock::now();
    std::vector<std::string> ours = outputs;
    for (const auto& out : outputs) ours.push_back(record_path(out));
    ours.push_back(summary.report);
    summary.stale_temporaries = remove_stale_temporaries(o.out_dir, ours);
    timing.cleanup_ms = ms_between(t0, clock::now());
  }
  const auto t_plan = clock::now();
  summary.assets.resize(inputs.size());
  std::vector<std::size_t> todo;
  std::vector<std::string> prints(inputs.size());  // input file and options, for the records
  const std::string options_json = options_to_json(o.base);
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    AssetOutcome& a = summary.assets[i];
    a.input = inputs[i];
    a.output = outputs[i];
    a.record = record_path(outputs[i]);
    prints[i] = fingerprint_with(a.input, options_json);
    if (!o.force && complete(a.output, a.record, prints[i])) {
      a.status = AssetStatus::Skipped;
    } else {
      todo.push_back(i);
    }
  }
  timing.plan_ms = ms_between(t_plan, clock::now());

  std::mutex mutex;
  std::size_t finished = 0;
  auto report_done = [&](const AssetOutcome& a) {
    std::lock_guard lock(mutex);
    ++finished;
    if (progress) progress(finished, inputs.size(), a);
  };
  for (const AssetOutcome& a : summary.assets)
    if (a.status == AssetStatus::Skipped) report_done(a);

  if (!todo.empty()) {
    // One session per worker for the whole batch: the device, the compiled kernels or pipelines
    // and the buffers are made here, once, and each asset only replaces the session's mesh.
    // The first is made before any work so that a missing device stops the batch; the others
    // open the backend the first one chose (with --backend auto the devices are listed once).
    const auto t_sessions = clock::now();
    std::vector<std::unique_ptr<Session>> sessions;
    sessions.push_back(std::make_unique<Session>(o.base.backend, o.base.sdf));
    BackendConfig chosen = o.base.backend;
    if (sessions[0]->choice().kind != BackendKind::Auto) chosen.kind = sessions[0]->choice().kind;
    const int workers = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(o.jobs), todo.size()));
    for (int w = 1; w < workers; ++w) sessions.push_back(std::make_unique<Session>(chosen, o.base.sdf));
    timing.sessions = workers;
    timing.sessions_ms = ms_between(t_sessions, clock::now());
    std::atomic<std::size_t> next{0};
    auto worker = [&](Session& session) {
      for (std::size_t k; (k = next.fetch_add(1)) < todo.size();) {
        AssetOutcome& a = summary.assets[todo[k]];
        const std::string& print = prints[todo[k]];
        const auto t0 = clock::now();
        ComputeRequest req = o.base;
        req.input = a.input;
        req.output = a.output;
        ComputeReport report;
        report.input = a.input;
        report.output = a.output;
        try {
          report = run_compute(req, session);
          a.status = AssetStatus::Done;
        } catch (const std::bad_alloc&) {
          a.error = a.input + ": out of memory";
        } catch (const std::exception& e) {
          a.error = e.what();
        }
        if (!a.error.empty()) a.status = AssetStatus::Failed;
        const auto t1 = clock::now();
        try {
          const std::string text = report_to_json(report, a.error, a.error.empty() ? print + output_stamp(a.output) : std::string());
          io::write_file_atomically(a.record, [&](std::ostream& os) { os << text << '\n'; });
        } catch (const std::exception& e) {
          if (a.error.empty()) {
            a.status = AssetStatus::Failed;
            a.error = e.what();
          }
        }
        const auto t2 = clock::now();
        a.seconds = ms_between(t0, t2) / 1000.0;
        a.stages = report.stages;
        const double run_ms = ms_between(t0, t1);
        a.stages.push_back({"record", ms_between(t1, t2)});
        a.stages.push_back({"other", std::max(0.0, run_ms - total_milliseconds(report.stages))});
        report_done(a);
      }
    };
    std::vector<std::thread> threads;
    for (int w = 1; w < workers; ++w) threads.emplace_back(worker, std::ref(*sessions[static_cast<std::size_t>(w)]));
    worker(*sessions[0]);
    for (auto& t : threads) t.join();
  }

  nlohmann::json j = nlohmann::json::array();
  std::vector<StageTiming> sums;
  for (const AssetOutcome& a : summary.assets) {
    const char* status = a.status == AssetStatus::Done ? "done" : a.status == AssetStatus::Skipped ? "skipped" : "failed";
    if (a.status == AssetStatus::Done) {
      ++summary.done;
      accumulate_stages(sums, a.stages);
    }
    if (a.status == AssetStatus::Skipped) ++summary.skipped;
    if (a.status == AssetStatus::Failed) ++summary.failed;
    j.push_back({{"input", a.input}, {"output", a.output}, {"record", a.record}, {"status", status},
                 {"seconds", a.seconds}, {"error", a.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.error)}});
  }
  nlohmann::json per_asset = nlohmann::json::object();
  for (StageTiming& s : sums) {
    s.milliseconds /= static_cast<double>(std::max<std::size_t>(summary.done, 1));
    per_asset[s.stage] = s.milliseconds;
  }
  timing.mean_stages = std::move(sums);
  timing.wall_ms = ms_between(t_start, clock::now());
  nlohmann::json report = {{"assets", j},
                           {"done", summary.done},
                           {"skipped", summary.skipped},
                           {"failed", summary.failed},
                           {"stale_temporaries_removed", summary.stale_temporaries},
                           {"timing",
                            {{"wall_ms", timing.wall_ms},
                             {"plan_ms", timing.plan_ms},
                             {"cleanup_ms", timing.cleanup_ms},
                             {"sessions", timing.sessions},
                             {"sessions_ms", timing.sessions_ms},
                             {"per_asset_mean_ms", per_asset},
                             {"note", "per_asset_mean_ms: mean over the assets computed; nested stages (read, "
                                      "weld) are parts of load; with several workers the stages of different "
                                      "assets overlap, so their sum exceeds wall_ms / done"}}}};
  io::write_file_atomically(summary.report, [&](std::ostream& os) { os << report.dump(2) << '\n'; });
  return summary;
}

}  // namespace sdfkit
