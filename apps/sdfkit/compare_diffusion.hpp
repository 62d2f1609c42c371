#pragma once
// sdfkit compare --diffusion (issue 13): one per-vertex result smoothed three ways at each sigma,
// intrinsic heat diffusion (the reference), k-ring smoothing and texture-space diffusion, and
// how far the two are from heat diffusion (Pearson, median relative difference, RMS), as a table
// and JSON. cmd_compare.cpp parses the options; this file does the work.

#include "sdfkit/diffusion/heat.hpp"
#include "sdfkit/io/asset.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace sdfkit::cli {

struct DiffusionCompareArgs {
  std::string input;                // a result (.glb/.gltf _SDF, .ply quality) or .txt with `mesh`
  std::string mesh;                 // the mesh of a .txt result
  std::vector<double> sigmas;       // model units
  std::vector<double> sigma_edges;  // in mean edge lengths (one of the two lists, not both)
  std::uint32_t atlas_size = 2048;  // texture space
  std::string skeleton, device;     // texture space: skeleton JSON (default: extracted), Vulkan device
  int heat_steps = diffusion::kHeatSteps;  // implicit steps of the heat reference
  std::string json;                 // also write the rows as JSON here
  io::LoadOptions load;
};

void compare_diffusion(const DiffusionCompareArgs& args);

}  // namespace sdfkit::cli
