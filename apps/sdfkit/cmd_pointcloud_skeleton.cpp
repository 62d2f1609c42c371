// sdfkit pointcloud-skeleton: the linear skeleton (an ordered polyline) of an unoriented point
// cloud or of every frame of a sequence (issue 14, the paper's section 5.3).
#include "commands.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/pointcloud/pointcloud.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

namespace sdfkit::cli {

// Writes `text` to `path` through a temporary file beside it: never a half-written output.
void write_text_atomically(const std::string& path, const std::string& text) {
  const std::string temp = path + ".tmp";
  {
    std::ofstream out(temp, std::ios::binary);
    if (!out) throw InputError("cannot write " + path);
    out << text;
    if (!out.flush()) throw InputError("cannot write " + path);
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    throw InputError("cannot write " + path);
  }
}

void add_pointcloud_skeleton_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("pointcloud-skeleton",
                                 "Linear skeleton (ordered polyline) of an unoriented point cloud or of each frame of a sequence");
  struct Args {
    std::string input, output, up = "y", linkage = "average";
    int segments = 0, nodes = 0;
    float threshold = 0.0f;
    pointcloud::SkeletonOptions options;
    bool quiet = false;
    SdfCliOptions sdf;
  };
  auto a = std::make_shared<Args>();
  a->sdf.sdf.rays = a->options.sdf.rays;
  cmd->add_option("CLOUD", a->input,
                  "Point cloud (.ply with x y z, .xyz/.csv/.txt text), a directory or glob of frames, or a "
                  "Sibernetic frame set (a directory with positions_f32le.bin: its surface particles)")
      ->required();
  cmd->add_option("-o,--output", a->output, "OUT.json: {\"nodes\": [...]} or {\"frames\": [...]} for a sequence")->required();
  cmd->add_option("--segments", a->segments,
                  "Exactly N segments (N + 1 nodes) per frame: the clustering threshold is searched per frame")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--threshold", a->threshold, "Clustering distance threshold in model units (default: the mean SDF)")
      ->check(CLI::PositiveNumber)
      ->excludes("--segments");
  cmd->add_option("--nodes", a->nodes, "Also write each polyline resampled at this many nodes (\"subdivided\")")
      ->check(CLI::Range(2, 100000));
  cmd->add_option("--neighbours", a->options.neighbours, "k nearest neighbours for normals, orientation and the surface")
      ->check(CLI::Range(4, 64))
      ->capture_default_str();
  cmd->add_option("--max-points", a->options.max_points,
                  "Run on this many points drawn at random when the cloud has more (0 = all; 4000 keeps a 30k-point worm's "
                  "polyline, bench/RESULTS.md)")
      ->check(CLI::Range(std::size_t{0}, std::size_t{1} << 40))
      ->capture_default_str();
  cmd->add_option("--up-axis", a->up, "x | y | z: the topmost point along it seeds the normal orientation")
      ->check(CLI::IsMember({"x", "y", "z"}))
      ->capture_default_str();
  cmd->add_option("--linkage", a->linkage, "average | single (clustering)")
      ->check(CLI::IsMember({"average", "single"}))
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", a->quiet, "Print nothing on success");
  add_sdf_options(*cmd, a->sdf);
  cmd->get_option("--backend")->description("auto | vulkan | opencl (auto: OpenCL first)");
  cmd->callback([a] {
    finish_sdf_options(a->sdf);
    if (a->sdf.sdf.domain != SdfDomain::Vertex) throw UsageError("point clouds use the per-point SDF (--per vertex)");
    const std::string ext = std::filesystem::path(a->output).extension().string();
    if (ext != ".json" && ext != ".JSON") throw UsageError(a->output + ": the output must be a .json file");
    pointcloud::SkeletonOptions options = a->options;
    options.segments = a->segments;
    options.threshold = a->threshold;
    options.up_axis = a->up == "x" ? 0 : a->up == "y" ? 1 : 2;
    options.linkage = a->linkage == "single" ? pointcloud::Linkage::Single : pointcloud::Linkage::Average;
    options.sdf = a->sdf.sdf;
    pointcloud::validate_options(options);
    const pointcloud::FrameSet set = pointcloud::read_frames(a->input, true);
    std::unique_ptr<SdfBackend> backend = make_backend(a->sdf.backend_config);
    const pointcloud::SequenceSkeleton seq = pointcloud::skeleton_sequence(set.frames, *backend, options, a->nodes);
    write_text_atomically(a->output, pointcloud::skeleton_json(seq, set.names, options));
    if (!seq.inexact.empty())
      std::fprintf(stderr, "sdfkit: warning: %zu of %zu frames have no threshold giving exactly %d segments (listed in %s)\n",
                   seq.inexact.size(), set.frames.size(), a->segments, a->output.c_str());
    if (!a->quiet) {
      double ms = 0.0;
      for (const auto& f : seq.frames)
        for (const auto& t : f.times) ms += t.milliseconds;
      std::printf("%s: %zu frame(s), %zu points each, %zu nodes in frame 0, %.1f ms per frame on %s -> %s\n",
                  a->input.c_str(), set.frames.size(), set.frames[0].size(), seq.frames[0].polyline.nodes.size(),
                  ms / static_cast<double>(set.frames.size()), backend->name().c_str(), a->output.c_str());
    }
  });
}

}  // namespace sdfkit::cli
