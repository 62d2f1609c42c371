#include "commands.hpp"

#include "sdfkit/core/topology.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>

namespace sdfkit::cli {
namespace {

// What both forms of `info` report first: the file and its counts before and after welding.
nlohmann::json counts_json(const io::Asset& asset) {
  return {{"file", asset.path},
          {"vertices", asset.input_positions.size()},
          {"faces", asset.input_triangles.size()},
          {"welded_vertices", asset.mesh.positions.size()}};
}

void print_counts(const io::Asset& asset) {
  std::printf("file:               %s\n", asset.path.c_str());
  std::printf("vertices:           %zu\n", asset.input_positions.size());
  std::printf("faces:              %zu\n", asset.input_triangles.size());
  std::printf("welded vertices:    %zu\n", asset.mesh.positions.size());
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Print counts and topology of a mesh");
  auto path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto tolerance = std::make_shared<float>(io::LoadOptions::kDefaultWeld);
  cmd->add_option("MESH", *path, "Mesh file (.gltf .glb .obj .off .ply) or builtin:NAME")->required();
  cmd->add_option("--weld-tolerance", *tolerance, "Weld positions closer than this (model units; default 1e-6 of the bounding box, 0 = bitwise-equal only)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", *json, "Print JSON instead of text");
  auto load_only = std::make_shared<bool>(false);
  cmd->add_flag("--load-only", *load_only,
                "Only load and weld: print the counts and the load's stage times (read, weld; ms), no topology");
  auto limits = std::make_shared<io::LoadOptions>();
  add_asset_options(*cmd, *limits);
  cmd->callback([=] {
    io::LoadOptions load = *limits;
    load.weld_tolerance = *tolerance;
    const io::Asset asset = load_input(*path, load);
    if (*load_only) {
      nlohmann::json times = nlohmann::json::object();
      for (const StageTiming& s : asset.load_stages) times[s.stage] = s.milliseconds;
      nlohmann::json j = counts_json(asset);
      j["time_ms"] = times;
      if (*json) {
        std::printf("%s\n", j.dump(2).c_str());
        return;
      }
      print_counts(asset);
      for (const StageTiming& s : asset.load_stages) std::printf("%-20s%.1f ms\n", (s.stage + ":").c_str(), s.milliseconds);
      return;
    }
    const MeshReport r = analyze(asset.mesh);
    if (*json) {
      nlohmann::json j = counts_json(asset);
      j.update({
          {"bounds", {{"min", {r.bounds.min.x, r.bounds.min.y, r.bounds.min.z}},
                      {"max", {r.bounds.max.x, r.bounds.max.y, r.bounds.max.z}}}},
          {"diagonal", r.bounds.diagonal()},
          {"components", r.components},
          {"boundary_edges", r.boundary_edges},
          {"non_manifold_edges", r.non_manifold_edges},
          {"degenerate_faces", r.degenerate_faces},
          {"isolated_vertices", r.isolated_vertices},
          {"flipped_faces", asset.flipped_faces},
          {"closed", r.boundary_edges == 0 && r.non_manifold_edges == 0},
          {"warnings", asset.warnings}});
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    print_counts(asset);
    std::printf("bounding box:       [%g, %g, %g] .. [%g, %g, %g] (diagonal %g)\n", r.bounds.min.x,
                r.bounds.min.y, r.bounds.min.z, r.bounds.max.x, r.bounds.max.y, r.bounds.max.z,
                r.bounds.diagonal());
    std::printf("components:         %zu\n", r.components);
    std::printf("boundary edges:     %zu%s\n", r.boundary_edges, r.boundary_edges ? " (open mesh)" : "");
    std::printf("non-manifold edges: %zu\n", r.non_manifold_edges);
    std::printf("degenerate faces:   %zu\n", r.degenerate_faces);
    std::printf("isolated vertices:  %zu\n", r.isolated_vertices);
    std::printf("flipped faces:      %zu%s\n", asset.flipped_faces,
                asset.flipped_faces ? " (wound against the others or inside out; computed flipped)" : "");
    for (const std::string& w : asset.warnings) std::printf("warning:            %s\n", w.c_str());
  });
}

}  // namespace sdfkit::cli
