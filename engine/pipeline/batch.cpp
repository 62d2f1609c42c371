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
void expand_one(const std::string& input, std::set<std::string>& out, std::set<std::string>& manifests,
                int depth) {
  if (depth > 8) throw InputError(input + ": manifests nest too deeply");
  std::string path = input;
  bool manifest = is_manifest(path);
  if (!path.empty() && path[0] == '@') {
    path = path.substr(1);
    manifest = true;
  }
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
      fs::path p = line.substr(b, e - b + 1);
      if (p.is_relative()) p = base / p;
      expand_one(p.lexically_normal().string(), out, manifests, depth + 1);
    }
    return;
  }
  out.insert(fs::path(path).lexically_normal().string());
}

// A result is complete when its record says ok with the same fingerprint and the output exists.
bool complete(const std::string& output, const std::string& record, const std::string& print) {
  std::error_code ec;
  if (!fs::exists(output, ec) || !fs::exists(record, ec)) return false;
  try {
    std::ifstream f(record);
    const auto j = nlohmann::json::parse(f);
    return j.value("ok", false) && j.value("fingerprint", std::string()) == print;
  } catch (const std::exception&) {
    return false;
  }
}

std::string record_path(const std::string& output) {
  return (fs::path(output).parent_path() / fs::path(output).stem()).string() + ".json";
}

}  // namespace

std::string batch_fingerprint(const std::string& input, const BatchOptions& o) {
  std::error_code ec;
  const auto size = fs::file_size(input, ec);
  const auto mtime = fs::last_write_time(input, ec).time_since_epoch().count();
  return "v2 size=" + std::to_string(size) + " mtime=" + std::to_string(mtime) + " options=" + options_to_json(o.base);
}

std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs) {
  std::set<std::string> out, manifests;
  for (const auto& in : inputs) expand_one(in, out, manifests, 0);
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
  const auto outputs = plan_outputs(inputs, o.out_dir, o.format);
  summary.assets.resize(inputs.size());
  std::vector<std::size_t> todo;
  std::vector<std::string> prints(inputs.size());  // input file and options, for the records
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    AssetOutcome& a = summary.assets[i];
    a.input = inputs[i];
    a.output = outputs[i];
    a.record = record_path(outputs[i]);
    prints[i] = batch_fingerprint(a.input, o);
    if (!o.force && complete(a.output, a.record, prints[i])) {
      a.status = AssetStatus::Skipped;
    } else {
      todo.push_back(i);
    }
  }

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
    // The first session is made here so that a missing device stops the batch before any work.
    std::vector<std::unique_ptr<Session>> sessions;
    sessions.push_back(std::make_unique<Session>(o.base.backend, o.base.sdf));
    const int workers = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(o.jobs), todo.size()));
    for (int w = 1; w < workers; ++w) sessions.push_back(std::make_unique<Session>(o.base.backend, o.base.sdf));
    std::atomic<std::size_t> next{0};
    auto worker = [&](Session& session) {
      for (std::size_t k; (k = next.fetch_add(1)) < todo.size();) {
        AssetOutcome& a = summary.assets[todo[k]];
        const std::string& print = prints[todo[k]];
        const auto t0 = std::chrono::steady_clock::now();
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
        a.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        try {
          const std::string text = report_to_json(report, a.error, a.error.empty() ? print : std::string());
          io::write_file_atomically(a.record, [&](std::ostream& os) { os << text << '\n'; });
        } catch (const std::exception& e) {
          if (a.error.empty()) {
            a.status = AssetStatus::Failed;
            a.error = e.what();
          }
        }
        report_done(a);
      }
    };
    std::vector<std::thread> threads;
    for (int w = 1; w < workers; ++w) threads.emplace_back(worker, std::ref(*sessions[static_cast<std::size_t>(w)]));
    worker(*sessions[0]);
    for (auto& t : threads) t.join();
  }

  nlohmann::json j = nlohmann::json::array();
  for (const AssetOutcome& a : summary.assets) {
    const char* status = a.status == AssetStatus::Done ? "done" : a.status == AssetStatus::Skipped ? "skipped" : "failed";
    if (a.status == AssetStatus::Done) ++summary.done;
    if (a.status == AssetStatus::Skipped) ++summary.skipped;
    if (a.status == AssetStatus::Failed) ++summary.failed;
    j.push_back({{"input", a.input}, {"output", a.output}, {"record", a.record}, {"status", status},
                 {"seconds", a.seconds}, {"error", a.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.error)}});
  }
  summary.report = (fs::path(o.out_dir) / o.report_name).string();
  const nlohmann::json report = {{"assets", j},
                                 {"done", summary.done},
                                 {"skipped", summary.skipped},
                                 {"failed", summary.failed}};
  io::write_file_atomically(summary.report, [&](std::ostream& os) { os << report.dump(2) << '\n'; });
  return summary;
}

}  // namespace sdfkit
