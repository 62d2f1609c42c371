#pragma once
// `sdfkit bench --diffusion`: the paper's Table 2 on this machine. On each mesh: the skeleton
// texture mapping (build_stm, timed), then texture-space diffusion at radius 2, 4, 8, 16, 32, 64
// texels on the atlas (rasterization, blur, read-back and total: wall and CPU time of the graph
// with and without the blur passes, alternated; lavapipe's timestamps do not time a dispatch),
// next to k-ring smoothing with k = 1..6 on the same mesh.

#include "bench_runner.hpp"

#include "sdfkit/diffusion/atlas.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace sdfkit::bench {

struct DiffusionMesh {
  std::string name;
  Mesh mesh;
  std::optional<Mesh> base;  // the mesh `mesh` was midpoint-subdivided from: its skeleton is used
  std::optional<diffusion::AtlasMapping> mapping;  // given (analytic): no skeleton, no STM
};

// An open cylinder of `segments` × (stacks + 1) vertices whose height is its circumference,
// mapped isometrically onto one wrapping chart filling a size² atlas (less the gutter): the
// blur's cost on a full atlas, independent of any mapping algorithm.
DiffusionMesh cylinder_mesh(int segments, int stacks, std::uint32_t size);

struct DiffusionBenchOptions {
  std::uint32_t atlas_size = 2048;
  std::vector<float> radii = {2, 4, 8, 16, 32, 64};
  std::vector<int> rings = {1, 2, 3, 4, 5, 6};
  int repeats = 5;          // warm runs per radius; the median and quartiles are reported
  std::string device;       // Vulkan device selector
};

// Runs every mesh; returns {"meshes": [...]} and fills `markdown`.
nlohmann::json run_diffusion_bench(const std::vector<DiffusionMesh>& meshes, const DiffusionBenchOptions& options,
                                   std::string& markdown);

}  // namespace sdfkit::bench
