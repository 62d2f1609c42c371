#include "commands.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/skeleton/skeleton.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

namespace sdfkit::cli {
namespace {

// Node vertex lists name welded vertices; outputs name the input file's vertices.
skeleton::Skeleton to_input_vertices(skeleton::Skeleton s, const io::Asset& asset) {
  std::vector<std::vector<std::uint32_t>> inputs_of(asset.mesh.positions.size());
  for (std::uint32_t i = 0; i < asset.input_to_welded.size(); ++i) inputs_of[asset.input_to_welded[i]].push_back(i);
  for (skeleton::Node& n : s.nodes) {
    std::vector<std::uint32_t> mapped;
    for (std::uint32_t w : n.vertices) mapped.insert(mapped.end(), inputs_of[w].begin(), inputs_of[w].end());
    n.vertices = std::move(mapped);
  }
  return s;
}

std::string extension_of(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

}  // namespace

void add_skeleton_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("skeleton", "Extract an SDF-driven curve skeleton (with sheets) of a closed mesh");
  struct Args {
    std::string input, output;
    bool no_sdf_term = false, no_sheets = false, quiet = false;
    int iterations = 20;
    std::size_t proxy_vertices = skeleton::ContractionOptions{}.proxy_vertices;
    SdfCliOptions sdf;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("MESH", a->input, "Closed mesh (.gltf .glb .obj .off .ply) or builtin:NAME")->required();
  cmd->add_option("-o,--output", a->output,
                  "SKEL.json (nodes, edges, sheet triangles), SKEL.obj (lines + faces), or .glb/.gltf (the mesh "
                  "with its SDF and the skeleton as a node of its own)")
      ->required();
  cmd->add_flag("--no-sdf-term", a->no_sdf_term, "Plain Au et al. contraction (no SDF centering or holding weights)");
  cmd->add_flag("--no-sheets", a->no_sheets, "Curves only, even where a curve is not reliable");
  cmd->add_option("--iterations", a->iterations, "Contraction iteration cap")->check(CLI::Range(1, 200));
  cmd->add_option("--proxy-vertices", a->proxy_vertices,
                  "Contract a simplified proxy of at most this many vertices when the mesh has more (0 = contract the mesh itself)")
      ->check(CLI::Range(0, 1000000000))
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", a->quiet, "Print nothing on success");
  add_sdf_options(*cmd, a->sdf);
  add_output_options(*cmd, a->sdf, false);
  cmd->get_option("--backend")
      ->description("auto | vulkan | opencl (auto: OpenCL when a device exists, else Vulkan: the SDF is "
                    "recomputed at every contraction iteration, where the ray caster's calls are cheapest)");
  cmd->callback([a] {
    finish_sdf_options(a->sdf);
    const std::string ext = extension_of(a->output);
    if (ext != ".json" && ext != ".obj" && ext != ".glb" && ext != ".gltf")
      throw UsageError(a->output + ": unknown skeleton output extension (expected .json, .obj, .glb or .gltf)");
    if (a->sdf.sdf.domain != SdfDomain::Vertex) throw UsageError("skeletons use the per-vertex SDF (--per vertex)");
    const auto t0 = std::chrono::steady_clock::now();
    const io::Asset asset = load_input(a->input, a->sdf.load);
    // The pipeline's session: the same contract and automatic choice as `sdfkit compute` (between
    // two GPU backends OpenCL first, the cheapest for the SDF recomputed at every contraction
    // iteration).
    Session session(a->sdf.backend_config, a->sdf.sdf);
    SdfBackend* backend = &session.backend();

    skeleton::ContractionOptions contraction;
    contraction.sdf_term = !a->no_sdf_term;
    contraction.max_iterations = a->iterations;
    contraction.proxy_vertices = a->proxy_vertices;
    contraction.sdf = a->sdf.sdf;
    skeleton::SkeletonOptions options;
    options.sheets = !a->no_sheets;
    const skeleton::Skeleton skel = to_input_vertices(skeleton::extract(asset.mesh, backend, contraction, options), asset);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    if (ext == ".json") {
      const std::string text = skeleton::to_json(skel);
      io::write_file_atomically(a->output, [&](std::ostream& os) { os << text << '\n'; });
    } else if (ext == ".obj") {
      io::write_file_atomically(a->output, [&](std::ostream& os) { skeleton::write_obj(os, skel); });
    } else {
      SdfField field;  // the input's SDF, measured by extract()
      field.domain = SdfDomain::Vertex;
      field.values = skel.sdf;
      io::WriteOptions write = a->sdf.write;
      io::Overlay overlay;
      overlay.name = "skeleton";
      for (const auto& n : skel.nodes) overlay.points.push_back(n.position);
      overlay.lines = skel.edges;
      overlay.triangles = skel.sheet_triangles;
      write.overlays.push_back(std::move(overlay));
      io::write_field(a->output, asset, field, write);
    }
    if (a->quiet) return;
    std::size_t sheet_nodes = 0;
    for (const auto& n : skel.nodes) sheet_nodes += n.sheet;
    std::printf("%s: %zu nodes (%zu in sheets), %zu curve edges, %zu sheet triangles, %d cycles -> %s\n",
                a->input.c_str(), skel.nodes.size(), sheet_nodes, skel.edges.size(), skel.sheet_triangles.size(),
                skeleton::cycle_count(skel), a->output.c_str());
    std::printf("%d contraction iterations with the %s SDF on %s (%s); reliability %.1f%% (curves alone %.1f%%); %.2f s\n",
                skel.iterations, backend->name().c_str(), backend->device_name().c_str(), session.choice().reason.c_str(),
                100.0 * skel.reliability, 100.0 * skel.curve_reliability, seconds);
    if (session.choice().kind == BackendKind::Vulkan)
      std::printf("every iteration's SDF used all the depth peeling's cameras (--views): the vulkan backend casts "
                  "no rays, so the %d rays per later iteration of ray casting do not apply\n",
                  contraction.iteration_rays);
    else
      std::printf("SDF with %d rays per point, then %d per later iteration\n", contraction.sdf.rays,
                  contraction.iteration_rays > 0 ? contraction.iteration_rays : contraction.sdf.rays);
    for (const std::string& w : skel.warnings) std::fprintf(stderr, "sdfkit: warning: %s\n", w.c_str());
  });
}

}  // namespace sdfkit::cli
