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
  // The overlap band (StmOptions::overlap) the blur needs: kBandSigmas · σ along the surface.
  // With σ in model units it is known before the mapping. With a radius in texels, σ in model
  // units is radius / texels_per_unit, and the atlas scale falls as the bands grow: build without
  // one, then with the band of the scale found (a quarter more, for the scale's fall), and again
  // while the band is short of kBandSigmas · σ at the new scale (at most three more builds).
  // A caller's own overlap (> 0) is kept.
  StmOptions so = o.stm;
  if (so.overlap == 0.0 && o.diffuse.sigma > 0.0f) so.overlap = kBandSigmas * o.diffuse.sigma;
  r.stm = build_stm(mesh, *skel, so);
  if (o.stm.overlap == 0.0 && o.diffuse.radius_px > 0.0f)
    for (int round = 0; round < 3; ++round) {
      const double need = kBandSigmas * o.diffuse.radius_px / r.stm.quality.texels_per_unit;
      if (!(need > so.overlap)) break;
      so.overlap = 1.25 * need;
      r.stm = build_stm(mesh, *skel, so);
    }
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
