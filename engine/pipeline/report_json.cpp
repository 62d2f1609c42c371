#include "sdfkit/pipeline.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>

namespace sdfkit {

std::string report_to_json(const ComputeReport& r, const std::string& error, const std::string& fingerprint) {
  nlohmann::json stages = nlohmann::json::object();
  for (const StageTiming& s : r.stages) stages[s.stage] = s.milliseconds;
  nlohmann::json memory = nlohmann::json::object();
  double peak = 0;
  for (const StageMemory& m : r.memory) {
    memory[m.stage] = {{"rss", m.memory.rss_mib}, {"peak_rss", m.memory.peak_rss_mib}};
    peak = std::max(peak, m.memory.peak_rss_mib);
  }
  nlohmann::json j = {
      {"input", r.input},
      {"output", r.output},
      {"ok", error.empty()},
      {"error", error.empty() ? nlohmann::json(nullptr) : nlohmann::json(error)},
      {"counts",
       {{"input_vertices", r.input_vertices}, {"input_faces", r.input_faces},
        {"welded_vertices", r.welded_vertices}, {"points", r.points}, {"filled_points", r.filled_points},
        {"solids", r.solids}, {"sdf_computations", r.sdf_computations}}},
      {"backend", r.backend},
      {"device", r.device},
      {"backend_choice", r.backend_choice},
      {"options", r.options.empty() ? nlohmann::json(nullptr) : nlohmann::json::parse(r.options)},
      {"time_ms", stages},
      {"total_ms", total_milliseconds(r.stages)},
      {"memory_mib", memory},
      {"peak_rss_mib", peak},
      {"summary",
       {{"min", r.summary.min}, {"median", r.summary.median}, {"mean", r.summary.mean}, {"max", r.summary.max}}},
      {"warnings", r.warnings},
      {"fingerprint", fingerprint}};
  return j.dump(2);
}

}  // namespace sdfkit
