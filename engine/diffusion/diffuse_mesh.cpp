// smooth_texture_space (diffuse_mesh.hpp): skeleton -> build_stm -> Diffuser, on one context.
#include "sdfkit/diffusion/diffuse_mesh.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/vulkan/context.hpp"

#include <chrono>
#include <cmath>
#include <utility>

namespace sdfkit::diffusion {

TextureSmoothResult smooth_texture_space(const Mesh& mesh, std::span<const float> values,
                                         const TextureSmoothOptions& o) {
  using Clock = std::chrono::steady_clock;
  if (values.size() != mesh.vertex_count())
    throw InputError("texture-space smoothing needs one value per vertex (" + std::to_string(mesh.vertex_count()) +
                     "), got " + std::to_string(values.size()));
  for (float v : values)
    if (!std::isfinite(v)) throw InputError("texture-space smoothing needs finite values (fill the field first)");
  (void)plan_blur(AtlasMapping{}, o.diffuse);  // option errors before any long work
  TextureSmoothResult r;
  auto t = Clock::now();
  skeleton::Skeleton extracted;
  const skeleton::Skeleton* skel = o.skeleton;
  if (!skel) {
    extracted = skeleton::extract(mesh, nullptr, {}, {});
    skel = &extracted;
  }
  r.skeleton_seconds = std::chrono::duration<double>(Clock::now() - t).count();
  t = Clock::now();
  r.stm = build_stm(mesh, *skel, o.stm);
  r.mapping_seconds = std::chrono::duration<double>(Clock::now() - t).count();
  vk::ContextConfig config;
  config.device = o.device;
  vk::Context ctx(config);
  Diffuser diffuser(ctx);
  r.diffusion = diffuser.run(mesh, r.stm.mapping, values, o.diffuse);
  r.values = std::move(r.diffusion.values);
  r.diffusion.values.clear();
  return r;
}

}  // namespace sdfkit::diffusion
