// sdfkit render: a PNG of the SDF-coloured mesh from several views with a histogram and a colour
// bar (the paper's Figure 5). Reads a result file, or computes the SDF when the file has none.
#include "commands.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/io/field.hpp"
#include "sdfkit/post/smooth.hpp"
#include "sdfkit/render/figure.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <memory>

namespace sdfkit::cli {
namespace {

glm::vec3 json_point(const nlohmann::json& j, const std::string& path, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
    throw InputError(path + ": " + what + " is not an array of three numbers");
  return {j[0].get<float>(), j[1].get<float>(), j[2].get<float>()};
}

}  // namespace

void read_skeleton_overlay(const std::string& path, render::RenderOptions& o) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the skeleton file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  if (!j.is_object()) throw InputError(path + ": a skeleton is a JSON object with \"nodes\"");
  std::vector<glm::vec3> nodes;
  if (j.contains("nodes")) {
    if (!j["nodes"].is_array()) throw InputError(path + ": \"nodes\" is not an array");
    for (std::size_t i = 0; i < j["nodes"].size(); ++i) {
      const nlohmann::json& n = j["nodes"][i];
      if (!n.is_object() || !n.contains("position"))
        throw InputError(path + ": node " + std::to_string(i) + " has no \"position\"");
      nodes.push_back(json_point(n["position"], path, "the position of node " + std::to_string(i)));
    }
  }
  const auto node = [&](const nlohmann::json& index, const std::string& what) {
    if (!index.is_number_integer() || index.get<long long>() < 0 ||
        static_cast<std::size_t>(index.get<long long>()) >= nodes.size())
      throw InputError(path + ": " + what + " refers to a node that does not exist");
    return nodes[static_cast<std::size_t>(index.get<long long>())];
  };
  const auto items = [&](const char* key, std::size_t arity) {
    std::vector<std::vector<glm::vec3>> out;
    if (!j.contains(key)) return out;
    if (!j[key].is_array()) throw InputError(path + ": \"" + key + "\" is not an array");
    for (std::size_t i = 0; i < j[key].size(); ++i) {
      const nlohmann::json& e = j[key][i];
      const std::string what = std::string(key) + " entry " + std::to_string(i);
      if (!e.is_array() || e.size() != arity)
        throw InputError(path + ": " + what + " is not " + std::to_string(arity) + " node indices");
      std::vector<glm::vec3> corners;
      for (const nlohmann::json& k : e) corners.push_back(node(k, what));
      out.push_back(std::move(corners));
    }
    return out;
  };
  o.points.insert(o.points.end(), nodes.begin(), nodes.end());
  for (const auto& e : items("edges", 2)) o.lines.push_back({e[0], e[1]});
  for (const auto& t : items("sheet_triangles", 3))
    for (int k = 0; k < 3; ++k) o.lines.push_back({t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]});
}

void add_figure_options(CLI::App& cmd, render::RenderOptions& o) {
  cmd.add_option("--views", o.views, "Views of the mesh in the figure")->check(CLI::Range(1, 64));
  cmd.add_option("--width", o.width, "Figure width in pixels")->check(CLI::Range(64, 8192));
  cmd.add_option("--height", o.height, "Figure height in pixels")->check(CLI::Range(64, 8192));
}

void add_render_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "render", "Draw the SDF-coloured mesh from several views with a histogram and colour bar (PNG)");
  struct Args {
    std::string input, output, skeleton;
    bool no_histogram = false, no_colorbar = false;
    std::vector<float> range;
    render::RenderOptions figure;
    SdfCliOptions sdf;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("INPUT", a->input,
                  "A result (.glb/.gltf with _SDF, .ply with quality), or a mesh / builtin:NAME to compute")
      ->required();
  cmd->add_option("-o,--output", a->output, "PNG file to write")->required();
  cmd->add_option("--skeleton", a->skeleton, "Skeleton JSON (nodes, edges, sheet_triangles) drawn over the mesh");
  cmd->add_option("--range", a->range, "Colour map range LO HI (default: the values' min and max)")
      ->expected(2);
  cmd->add_flag("--no-histogram", a->no_histogram, "Leave out the histogram");
  cmd->add_flag("--no-colorbar", a->no_colorbar, "Leave out the colour bar");
  // --views names the figure's views here; the depth peeling's camera count is --sdf-views.
  add_sdf_options(*cmd, a->sdf, "--sdf-views");
  add_figure_options(*cmd, a->figure);
  cmd->callback([a] {
    finish_sdf_options(a->sdf);
    check_png_name(a->output);
    render::RenderOptions& o = a->figure;
    o.histogram = !a->no_histogram;
    o.colorbar = !a->no_colorbar;
    if (a->range.size() == 2) {
      o.lo = a->range[0];
      o.hi = a->range[1];
      if (!(o.lo < o.hi)) throw UsageError("--range needs LO < HI");
    }
    if (!a->skeleton.empty()) read_skeleton_overlay(a->skeleton, o);

    const ResultValues r = load_or_compute(a->input, &a->sdf, a->sdf.load);
    vk::ContextConfig config;
    config.validation = a->sdf.backend_config.validation;
    vk::Context ctx(config);
    const render::Image img = render::render_figure(ctx, r.asset.mesh, r.values, r.domain, o);
    render::write_png(a->output, img);
    if (r.computed) std::printf("%s\n", backend_line(r.report).c_str());
    std::printf("%s: %zu %s values%s -> %s (%d x %d, %d views, %s)\n", a->input.c_str(), r.values.size(),
                r.domain == SdfDomain::Vertex ? "vertex" : "face", r.computed ? " (computed)" : "",
                a->output.c_str(), img.width, img.height, o.views, ctx.info().name.c_str());
  });
}

}  // namespace sdfkit::cli
