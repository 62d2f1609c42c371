// Skeletons of frame sequences and their JSON form.

#include "sdfkit/pointcloud/pointcloud.hpp"

#include <nlohmann/json.hpp>

namespace sdfkit::pointcloud {
namespace {

nlohmann::json nodes_json(const Polyline& line) {
  nlohmann::json nodes = nlohmann::json::array();
  for (const Node& n : line.nodes)
    nodes.push_back({{"position", {n.position.x, n.position.y, n.position.z}}, {"radius", n.radius}});
  return nodes;
}

}  // namespace

SequenceSkeleton skeleton_sequence(const std::vector<std::vector<glm::vec3>>& frames, SdfBackend& backend,
                                   const SkeletonOptions& options, int subdivided_nodes) {
  SequenceSkeleton seq;
  std::vector<Polyline> lines;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    seq.frames.push_back(point_cloud_skeleton(frames[f], backend, options));
    if (!seq.frames.back().exact) seq.inexact.push_back(f);
    seq.ambiguous.push_back(seq.frames.back().ambiguous.size());
    lines.push_back(seq.frames.back().polyline);
  }
  seq.reversed = orient_sequence(lines);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    seq.frames[f].polyline = std::move(lines[f]);
    if (subdivided_nodes > 0) seq.subdivided.push_back(resample(seq.frames[f].polyline, subdivided_nodes));
  }
  return seq;
}

std::string skeleton_json(const SequenceSkeleton& seq, const std::vector<std::string>& names,
                          const SkeletonOptions& options) {
  auto frame_json = [&](std::size_t f) {
    const SkeletonResult& r = seq.frames[f];
    nlohmann::json j;
    if (f < names.size()) j["name"] = names[f];
    j["nodes"] = nodes_json(r.polyline);
    j["segments"] = r.polyline.segments();
    j["threshold"] = r.threshold;
    if (options.segments > 0) j["exact_segments"] = r.exact;
    j["length"] = r.polyline.length();
    j["points"] = r.sdf.size();
    j["surface_triangles"] = r.surface_triangles;
    j["ambiguous_normals"] = r.ambiguous;
    if (f < seq.subdivided.size()) j["subdivided"] = {{"nodes", nodes_json(seq.subdivided[f])}};
    nlohmann::json times = nlohmann::json::object();
    for (const StepTime& t : r.times) times[t.step] = t.milliseconds;
    j["milliseconds"] = times;
    return j;
  };
  nlohmann::json doc;
  if (seq.frames.size() == 1) {
    doc = frame_json(0);
  } else {
    doc["frames"] = nlohmann::json::array();
    for (std::size_t f = 0; f < seq.frames.size(); ++f) doc["frames"].push_back(frame_json(f));
    doc["reversed_frames"] = seq.reversed;
    if (options.segments > 0) doc["frames_without_exact_segments"] = seq.inexact;
  }
  doc["method"] = {{"neighbours", options.neighbours},
                   {"cluster_neighbours", options.cluster_neighbours},
                   {"linkage", options.linkage == Linkage::Single ? "single" : "average"},
                   {"rays", options.sdf.rays},
                   {"cone_degrees", options.sdf.cone_degrees},
                   {"up_axis", options.up_axis}};
  if (options.segments > 0) doc["method"]["segments"] = options.segments;
  return doc.dump(1);
}

}  // namespace sdfkit::pointcloud
