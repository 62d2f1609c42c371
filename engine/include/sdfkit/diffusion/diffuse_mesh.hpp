#pragma once
// Texture-space smoothing of a per-vertex field on a mesh, the whole road: the skeleton (given,
// or extracted from the mesh's geometry), the skeleton texture mapping (build_stm), and the
// diffusion on a Vulkan device (Diffuser). What `sdfkit smooth --texture-space`, `compute` /
// `batch --smooth-texture` and Python's sdfkit.diffuse call.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/diffusion/diffuse.hpp"
#include "sdfkit/diffusion/stm.hpp"
#include "sdfkit/skeleton/skeleton.hpp"

#include <span>
#include <string>
#include <vector>

namespace sdfkit::diffusion {

struct TextureSmoothOptions {
  DiffuseOptions diffuse;                       // radius_px or sigma (exactly one), keep_atlas, profile
  StmOptions stm;                               // atlas size, gutter; overlap 0: set from the blur (diffuse_mesh.cpp)
  const skeleton::Skeleton* skeleton = nullptr; // nullptr: skeleton::extract on the mesh, no SDF backend
  std::string device;                           // Vulkan device selector (empty: SDFKIT_VK_DEVICE or the best)
};

struct TextureSmoothResult {
  std::vector<float> values;  // per vertex
  Stm stm;                    // the mapping and its quality
  DiffuseResult diffusion;    // timings, plan, atlas (with keep_atlas); values moved out
  double skeleton_seconds = 0.0, mapping_seconds = 0.0;
};

// Throws InputError (bad values, options, skeleton), DeviceError (no Vulkan device).
TextureSmoothResult smooth_texture_space(const Mesh& mesh, std::span<const float> values,
                                         const TextureSmoothOptions& options);

}  // namespace sdfkit::diffusion
