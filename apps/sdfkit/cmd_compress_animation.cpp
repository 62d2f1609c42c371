// sdfkit compress-animation: a particle animation (the same points in every frame) as a skinned,
// animated glTF, with a report of its size and of its error measured by playing the file back.
#include "commands.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/pointcloud/skinning.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

namespace sdfkit::cli {
namespace {

std::vector<std::uint32_t> read_indices(const std::string& path, std::size_t count) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open " + path);
  std::vector<std::uint32_t> out;
  long long v;
  while (in >> v) {
    if (v < 0 || static_cast<std::size_t>(v) >= count)
      throw InputError(path + ": index " + std::to_string(v) + " is outside the frames' " + std::to_string(count) + " points");
    out.push_back(static_cast<std::uint32_t>(v));
  }
  if (!in.eof()) throw InputError(path + ": expected point indices (integers)");
  if (out.size() < 8) throw InputError(path + ": at least 8 skeleton point indices are needed");
  return out;
}

}  // namespace

void add_compress_animation_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("compress-animation",
                                 "Compress a point-cloud animation as a skinned, animated glTF (bones from the frames' linear skeletons)");
  struct Args {
    std::string input, output, json, skeleton_points, rotation = "procrustes";
    int bones = 16;
    double frame_time = 0.0;
    bool quiet = false;
    SdfCliOptions sdf;
  };
  auto a = std::make_shared<Args>();
  a->sdf.sdf.rays = pointcloud::SkeletonOptions{}.sdf.rays;
  cmd->add_option("FRAMES", a->input,
                  "A directory or glob of point-cloud frames (.ply/.xyz/.csv/.txt, file-name order, same points in the same "
                  "order), or a Sibernetic frame set (all its particles; the skeleton from its surface particles)")
      ->required();
  cmd->add_option("-o,--output", a->output, "OUT.glb")->required();
  cmd->add_option("--bones", a->bones, "Bones (the skeleton's segments)")->check(CLI::Range(4, 255))->capture_default_str();
  cmd->add_option("--frame-time", a->frame_time, "Seconds between frames (default: the frame set's own, when it says)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--json", a->json, "REPORT.json: sizes, ratio, RMSE / max / KG error of the played-back glb");
  cmd->add_option("--skeleton-points", a->skeleton_points,
                  "A file of point indices (one per line) on the outer surface: the skeleton uses only those (default: all "
                  "points; Sibernetic sets: their shell particles)");
  cmd->add_option("--rotation", a->rotation,
                  "procrustes: each bone's least-squares rotation of its particles | polyline: the skeleton segment's "
                  "direction and a fitted twist")
      ->check(CLI::IsMember({"procrustes", "polyline"}))
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", a->quiet, "Print nothing on success");
  add_sdf_options(*cmd, a->sdf);
  cmd->get_option("--backend")->description("auto | vulkan | opencl (auto: OpenCL first)");
  cmd->callback([a] {
    finish_sdf_options(a->sdf);
    if (a->sdf.sdf.domain != SdfDomain::Vertex) throw UsageError("point clouds use the per-point SDF (--per vertex)");
    const std::string ext = std::filesystem::path(a->output).extension().string();
    if (ext != ".glb" && ext != ".GLB") throw UsageError(a->output + ": the output must be a .glb file");
    if (!a->json.empty() && std::filesystem::path(a->json).extension() != ".json")
      throw UsageError(a->json + ": the report must be a .json file");
    const pointcloud::FrameSet all = pointcloud::read_frames(a->input, false);
    const bool sibernetic = std::filesystem::exists(std::filesystem::path(a->input) / "positions_f32le.bin");
    double frame_time = a->frame_time > 0.0 ? a->frame_time : all.frame_time;
    if (!(frame_time > 0.0)) throw UsageError("--frame-time is required: " + a->input + " does not say the time between frames");
    if (all.frames.size() < 2) throw InputError(a->input + ": an animation needs at least 2 frames");
    for (std::size_t f = 1; f < all.frames.size(); ++f)
      if (all.frames[f].size() != all.frames[0].size())
        throw InputError(all.names[f] + " has " + std::to_string(all.frames[f].size()) + " points, " + all.names[0] + " " +
                         std::to_string(all.frames[0].size()) + ": every frame needs the same points");
    std::vector<std::vector<glm::vec3>> skeleton_points;
    if (sibernetic && a->skeleton_points.empty()) {
      skeleton_points = pointcloud::read_frames(a->input, true).frames;
    } else if (!a->skeleton_points.empty()) {
      const auto idx = read_indices(a->skeleton_points, all.frames[0].size());
      for (const auto& f : all.frames) {
        std::vector<glm::vec3> pts;
        for (std::uint32_t i : idx) pts.push_back(f[i]);
        skeleton_points.push_back(std::move(pts));
      }
    } else {
      skeleton_points = all.frames;
    }
    std::unique_ptr<SdfBackend> backend = make_backend(a->sdf.backend_config);
    pointcloud::CompressionOptions options;
    options.bones = a->bones;
    options.frame_time = frame_time;
    options.rotation = a->rotation == "polyline" ? pointcloud::CompressionOptions::Rotation::Polyline
                                                 : pointcloud::CompressionOptions::Rotation::Procrustes;
    options.skeleton.sdf = a->sdf.sdf;
    const pointcloud::Compression c = pointcloud::compress_animation(all.frames, skeleton_points, *backend, options);
    const std::size_t bytes = pointcloud::write_skinned_glb(c.animation, a->output);
    double length = 0.0;
    for (const auto& line : c.bones_per_frame) length += line.length();
    length /= static_cast<double>(c.bones_per_frame.size());
    const auto played = pointcloud::play_skinned_glb(a->output);
    const pointcloud::CompressionReport r =
        pointcloud::measure_compression(all.frames, played, bytes, c.animation.bone_count(), length);
    if (!a->json.empty()) write_text_atomically(a->json, pointcloud::report_json(r));
    if (!a->quiet)
      std::printf("%s: %zu frames x %zu points, %zu bones -> %s: %zu bytes (raw %zu, %.1f:1), RMSE %.3f (%.2f %% of the "
                  "length %.1f), max %.3f, KG %.3f %% (skeletons %.0f ms, fit %.0f ms)\n",
                  a->input.c_str(), r.frames, r.points, r.bones, a->output.c_str(), r.compressed_bytes, r.raw_bytes, r.ratio,
                  r.rmse, r.rmse_percent, r.body_length, r.max_error, r.kg_error, c.skeleton_ms, c.fit_ms);
  });
}

}  // namespace sdfkit::cli
