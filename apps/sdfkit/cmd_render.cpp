// sdfkit render: a PNG of the SDF-coloured mesh from several views with a histogram and a colour
// bar (the paper's Figure 5), a skeleton drawn over it, or a point cloud (a frame, a frame set, a
// skinned animation played back) with its skeleton, alone or as a strip of frames (Figure 15).
#include "commands.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/io/field.hpp"
#include "sdfkit/pointcloud/pointcloud.hpp"
#include "sdfkit/pointcloud/skinning.hpp"
#include "sdfkit/render/figure.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

namespace sdfkit::cli {
namespace {

namespace fs = std::filesystem;

enum class InputKind { Mesh, Points, Animation };

std::string lower_extension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

// A PLY whose header declares no faces (or zero of them) is a point cloud.
bool ply_has_faces(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return true;  // let the mesh loader say what is wrong
  std::string line;
  for (int n = 0; n < 200 && std::getline(in, line); ++n) {
    if (line.rfind("end_header", 0) == 0) return false;
    if (line.rfind("element face ", 0) == 0) return std::strtoll(line.c_str() + 13, nullptr, 10) > 0;
  }
  return true;
}

// The glTF's JSON (a .gltf file, or a .glb's JSON chunk); null when it cannot be read.
nlohmann::json gltf_json(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return nullptr;
  if (lower_extension(path) == ".glb") {
    std::uint32_t header[5] = {};
    if (!in.read(reinterpret_cast<char*>(header), sizeof header) || header[0] != 0x46546C67u ||
        header[4] != 0x4E4F534Au || header[3] > (64u << 20))
      return nullptr;
    std::string text(header[3], '\0');
    if (!in.read(text.data(), static_cast<std::streamsize>(text.size()))) return nullptr;
    return nlohmann::json::parse(text, nullptr, false);
  }
  return nlohmann::json::parse(in, nullptr, false);
}

// A skinned animation of points (what compress-animation writes): skins, animations and only
// POINTS primitives.
bool is_point_animation(const std::string& path) {
  const nlohmann::json j = gltf_json(path);
  if (!j.is_object() || !j.contains("skins") || !j.contains("animations") || !j.contains("meshes")) return false;
  bool any = false;
  for (const auto& m : j["meshes"])
    for (const auto& p : m.value("primitives", nlohmann::json::array())) {
      if (p.value("mode", 4) != 0) return false;
      any = true;
    }
  return any;
}

InputKind classify(const std::string& input, bool force_points) {
  if (input.starts_with("builtin:")) {
    if (force_points) throw UsageError("--points: " + input + " is a mesh");
    return InputKind::Mesh;
  }
  const bool wildcard = input.find_first_of("*?") != std::string::npos;
  if (!wildcard && !fs::exists(input)) throw InputError(input + ": no such file or directory");
  const std::string ext = lower_extension(input);
  if ((ext == ".glb" || ext == ".gltf") && fs::is_regular_file(input) && is_point_animation(input))
    return InputKind::Animation;
  if (force_points && (ext == ".off" || ext == ".obj" || ext == ".stl" || ext == ".glb" || ext == ".gltf"))
    throw UsageError("--points: " + input + " is a mesh file (point clouds: .ply, .xyz, .csv, .txt, frame sets)");
  if (force_points) return InputKind::Points;
  if (fs::is_directory(input) || wildcard) return InputKind::Points;
  if (ext == ".xyz" || ext == ".csv" || ext == ".txt") return InputKind::Points;
  if (ext == ".ply" && fs::is_regular_file(input) && !ply_has_faces(input)) return InputKind::Points;
  return InputKind::Mesh;
}

render::Orientation orientation_for(const std::string& up, const std::string& input,
                                    std::span<const glm::vec3> points) {
  if (up == "auto") return render::orient(points, render::up_rule_for(input));
  return render::orientation_with_up(points, up);
}

}  // namespace

void add_figure_options(CLI::App& cmd, render::RenderOptions& o) {
  cmd.add_option("--views", o.views, "Views of the mesh in the figure (default 4; 1 for point clouds)")
      ->check(CLI::Range(1, 64));
  cmd.add_option("--width", o.width, "Figure width in pixels")->check(CLI::Range(64, 8192));
  cmd.add_option("--height", o.height, "Figure height in pixels")->check(CLI::Range(64, 8192));
}

void add_render_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "render",
      "Draw the SDF-coloured mesh from several views with a histogram and colour bar, a skeleton over it, "
      "or a point-cloud frame / strip of frames with its skeleton (PNG)");
  struct Args {
    std::string input, output, skeleton, up = "auto";
    bool no_histogram = false, no_colorbar = false, points = false;
    int strip = 0, frame = -1;
    std::vector<float> range;
    render::RenderOptions figure;
    SdfCliOptions sdf;
    std::vector<CLI::Option*> sdf_options;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("INPUT", a->input,
                  "A result (.glb/.gltf with _SDF, .ply with quality), a mesh / builtin:NAME to compute, or a point "
                  "cloud: .ply without faces, .xyz/.csv/.txt, a directory or glob of frames, a Sibernetic frame set, "
                  "a skinned point animation (.glb from compress-animation, played back)")
      ->required();
  cmd->add_option("-o,--output", a->output, "PNG file to write")->required();
  cmd->add_option("--skeleton", a->skeleton,
                  "Skeleton JSON drawn over the mesh or points: `sdfkit skeleton`'s (nodes, edges, sheet_triangles) "
                  "or `sdfkit pointcloud-skeleton`'s (an ordered polyline, or one per frame)");
  cmd->add_option("--up", a->up,
                  "Axis drawn up: auto (glTF: +y; other files: the bounding box's longest axis) | x | y | z | -x ...")
      ->capture_default_str();
  cmd->add_flag("--points", a->points, "Read INPUT as a point cloud (automatic for the kinds listed above)");
  cmd->add_option("--frame", a->frame, "The frame of a frame set (or of the skeleton's frames) to draw (default 0)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--strip", a->strip,
                  "Point clouds: N frames evenly spaced over the set, side by side (the paper's Figure 15)")
      ->check(CLI::Range(1, 64));
  cmd->add_option("--range", a->range, "Colour map range LO HI (default: the values' min and max)")
      ->expected(2);
  cmd->add_flag("--no-histogram", a->no_histogram, "Leave out the histogram");
  cmd->add_flag("--no-colorbar", a->no_colorbar, "Leave out the colour bar");
  // --views names the figure's views here; the depth peeling's camera count is --sdf-views.
  const std::size_t before = cmd->get_options().size();
  add_sdf_options(*cmd, a->sdf, "--sdf-views");
  const std::vector<CLI::Option*> options = cmd->get_options();
  a->sdf_options.assign(options.begin() + static_cast<std::ptrdiff_t>(before), options.end());
  add_figure_options(*cmd, a->figure);
  cmd->callback([a, cmd] {
    finish_sdf_options(a->sdf);
    check_png_name(a->output);
    render::RenderOptions& o = a->figure;
    if (a->up != "auto") {
      try {
        render::orientation_with_up({}, a->up);
      } catch (const InputError& e) {
        throw UsageError(std::string("--up: ") + e.what());
      }
    }
    if (a->strip > 0 && a->frame >= 0) throw UsageError("--strip draws several frames: leave out --frame");
    const InputKind kind = classify(a->input, a->points);
    const bool views_given = cmd->get_option("--views")->count() > 0;
    std::vector<render::SkeletonOverlay> skeletons;
    if (!a->skeleton.empty()) skeletons = render::read_skeleton_json(a->skeleton);

    if (kind == InputKind::Mesh) {
      if (a->strip > 0 || a->frame >= 0) throw UsageError("--strip and --frame need a point cloud or frame set");
      o.histogram = !a->no_histogram;
      o.colorbar = !a->no_colorbar;
      if (a->range.size() == 2) {
        o.lo = a->range[0];
        o.hi = a->range[1];
        if (!(o.lo < o.hi)) throw UsageError("--range needs LO < HI");
      }
      if (skeletons.size() > 1)
        throw InputError(a->skeleton + ": " + std::to_string(skeletons.size()) + " frames of skeletons for one mesh");
      const ResultValues r = load_or_compute(a->input, &a->sdf, a->sdf.load);
      if (!skeletons.empty()) {
        o.skeleton = skeletons.front();
        o.fade = 0.55f;  // the SDF colours stay readable, the skeleton stands out
      }
      o.setup.orientation = orientation_for(a->up, a->input, r.asset.mesh.positions);
      vk::ContextConfig config;
      config.validation = a->sdf.backend_config.validation;
      vk::Context ctx(config);
      const render::Image img = render::render_figure(ctx, r.asset.mesh, r.values, r.domain, o);
      render::write_png(a->output, img);
      if (r.computed) std::printf("%s\n", backend_line(r.report).c_str());
      std::printf("%s: %zu %s values%s -> %s (%d x %d, %d views, %s)\n", a->input.c_str(), r.values.size(),
                  r.domain == SdfDomain::Vertex ? "vertex" : "face", r.computed ? " (computed)" : "",
                  a->output.c_str(), img.width, img.height, o.views, ctx.info().name.c_str());
      return;
    }

    // Point clouds: no SDF is computed, so its options and the value legend do not apply.
    for (const CLI::Option* opt : a->sdf_options)
      if (opt->count() > 0)
        throw UsageError(opt->get_name() + " does not apply to a point cloud (render computes no SDF for it)");
    if (!a->range.empty() || a->no_histogram || a->no_colorbar)
      throw UsageError("--range, --no-histogram and --no-colorbar do not apply to a point cloud (it has no values)");
    if (a->strip > 0 && views_given) throw UsageError("--strip draws one view per frame: leave out --views");
    o.histogram = o.colorbar = false;
    if (!views_given) o.views = 1;
    o.setup.elevation_degrees = 0.0f;  // looking straight along the front axis
    o.setup.azimuth_degrees = 0.0f;

    pointcloud::FrameSet set;
    if (kind == InputKind::Animation) {
      set.frames = pointcloud::play_skinned_glb(a->input);
      for (std::size_t f = 0; f < set.frames.size(); ++f) set.names.push_back("frame " + std::to_string(f));
    } else {
      set = pointcloud::read_frames(a->input);
    }
    if (set.frames.empty()) throw InputError(a->input + ": no frames");
    const std::size_t count = set.frames.size();
    if (!skeletons.empty() && skeletons.size() != count && !(skeletons.size() == 1 && a->strip == 0))
      throw InputError(a->skeleton + " has " + std::to_string(skeletons.size()) + " frames of skeletons, " + a->input +
                       " " + std::to_string(count) + " frames");

    std::vector<std::size_t> chosen;
    if (a->strip > 0) {
      if (static_cast<std::size_t>(a->strip) > count)
        throw InputError(a->input + " has " + std::to_string(count) + " frames, fewer than --strip " +
                         std::to_string(a->strip));
      for (int i = 0; i < a->strip; ++i)
        chosen.push_back(a->strip == 1 ? 0
                                       : static_cast<std::size_t>(std::lround(static_cast<double>(i) * (count - 1) /
                                                                              (a->strip - 1))));
    } else {
      const std::size_t f = a->frame < 0 ? 0 : static_cast<std::size_t>(a->frame);
      if (f >= count)
        throw InputError(a->input + " has " + std::to_string(count) + " frames: --frame " + std::to_string(f) +
                         " does not exist");
      chosen.push_back(f);
    }
    std::vector<render::PointFrame> frames;
    std::vector<glm::vec3> all;
    for (const std::size_t f : chosen) {
      render::PointFrame pf;
      pf.points = std::move(set.frames[f]);
      if (!skeletons.empty()) pf.skeleton = skeletons[skeletons.size() == 1 ? 0 : f];
      if (a->strip > 0) pf.label = std::to_string(f);
      all.insert(all.end(), pf.points.begin(), pf.points.end());
      frames.push_back(std::move(pf));
    }
    // Point clouds follow the longest-axis rule whatever the container: a simulation's frames
    // (and the glb compress-animation writes from them) keep the simulator's own axes.
    o.setup.orientation = orientation_for(a->up, "", all);
    vk::ContextConfig config;
    config.validation = a->sdf.backend_config.validation;
    vk::Context ctx(config);
    const render::Image img =
        a->strip > 0 ? render::render_strip(ctx, frames, o) : render::render_points_figure(ctx, frames.front(), o);
    render::write_png(a->output, img);
    std::printf("%s: %zu of %zu frames, %zu points%s -> %s (%d x %d, %s)\n", a->input.c_str(), frames.size(), count,
                frames.front().points.size(), skeletons.empty() ? "" : " with skeleton", a->output.c_str(), img.width,
                img.height, ctx.info().name.c_str());
  });
}

}  // namespace sdfkit::cli
