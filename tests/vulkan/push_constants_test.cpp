// The C++ push-constant structs the passes record (passes/depth_peel_passes.hpp,
// passes/figure_passes.hpp) against the GLSL blocks they feed, read back from the embedded
// SPIR-V: same member offsets, same size. No device needed.
#include "depth_peel_passes.hpp"
#include "atlas_passes.hpp"
#include "figure_passes.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/vulkan/pipeline.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

namespace sdfkit::vk {
namespace {

struct Expected {
  std::vector<std::uint32_t> offsets;
  std::uint32_t size;
};

#define SDFKIT_OFF(T, m) static_cast<std::uint32_t>(offsetof(T, m))

void expect_block(const std::string& shader, const Expected& want) {
  const PushConstantLayout got = push_constant_layout(embedded_spirv(shader));
  EXPECT_EQ(got.offsets, want.offsets) << shader;
  EXPECT_EQ(got.size, want.size) << shader;
}

TEST(PushConstants, DepthPeelStructsMatchTheirGlslBlocks) {
  using namespace passes;
  const Expected peel{{SDFKIT_OFF(PeelPush, center_scale), SDFKIT_OFF(PeelPush, camera_base),
                       SDFKIT_OFF(PeelPush, first_layer), SDFKIT_OFF(PeelPush, epsilon), SDFKIT_OFF(PeelPush, back)},
                      sizeof(PeelPush)};
  expect_block("depth_peel.vert", peel);
  expect_block("depth_peel.frag", peel);
  expect_block("diameter.comp",
               {{SDFKIT_OFF(DiameterPush, center_scale), SDFKIT_OFF(DiameterPush, camera_base),
                 SDFKIT_OFF(DiameterPush, camera_count), SDFKIT_OFF(DiameterPush, first_layer),
                 SDFKIT_OFF(DiameterPush, point_count), SDFKIT_OFF(DiameterPush, max_samples),
                 SDFKIT_OFF(DiameterPush, cos_half_cone), SDFKIT_OFF(DiameterPush, rule),
                 SDFKIT_OFF(DiameterPush, resolution), SDFKIT_OFF(DiameterPush, front_tolerance),
                 SDFKIT_OFF(DiameterPush, pending_slot)},
                sizeof(DiameterPush)});
  const Expected list{{SDFKIT_OFF(ListPush, center_scale), SDFKIT_OFF(ListPush, camera_base),
                       SDFKIT_OFF(ListPush, resolution), SDFKIT_OFF(ListPush, capacity)},
                      sizeof(ListPush)};
  expect_block("fragment_list.vert", list);
  expect_block("fragment_list.frag", list);
  expect_block("fragment_list.comp",
               {{SDFKIT_OFF(ResolvePush, center_scale), SDFKIT_OFF(ResolvePush, camera_base),
                 SDFKIT_OFF(ResolvePush, camera_count), SDFKIT_OFF(ResolvePush, point_count),
                 SDFKIT_OFF(ResolvePush, max_samples), SDFKIT_OFF(ResolvePush, cos_half_cone),
                 SDFKIT_OFF(ResolvePush, rule), SDFKIT_OFF(ResolvePush, resolution),
                 SDFKIT_OFF(ResolvePush, front_tolerance), SDFKIT_OFF(ResolvePush, capacity)},
                sizeof(ResolvePush)});
  expect_block("gather.comp",
               {{SDFKIT_OFF(GatherPush, point_count), SDFKIT_OFF(GatherPush, max_samples)}, sizeof(GatherPush)});
}

TEST(PushConstants, FigureStructsMatchTheirGlslBlocks) {
  using namespace render::passes;
  const Expected mesh{{SDFKIT_OFF(MeshPush, view_projection), SDFKIT_OFF(MeshPush, eye), SDFKIT_OFF(MeshPush, scale)},
                      sizeof(MeshPush)};
  expect_block("render_mesh.vert", mesh);
  expect_block("render_mesh.frag", mesh);
  const Expected overlay{{SDFKIT_OFF(OverlayPush, view_projection), SDFKIT_OFF(OverlayPush, viewport)},
                         sizeof(OverlayPush)};
  expect_block("render_overlay.vert", overlay);
  const Expected sheet{{SDFKIT_OFF(SheetPush, view_projection), SDFKIT_OFF(SheetPush, color)}, sizeof(SheetPush)};
  expect_block("figure_sheet.vert", sheet);
  expect_block("figure_sheet.frag", sheet);
}

TEST(PushConstants, AtlasStructsMatchTheirGlslBlocks) {
  using namespace diffusion::passes;
  expect_block("atlas_raster.vert", {{SDFKIT_OFF(RasterPush, scale)}, sizeof(RasterPush)});
  expect_block("atlas_raster.frag", {{SDFKIT_OFF(RasterPush, scale)}, sizeof(RasterPush)});
  expect_block("atlas_raster_value.frag", {{SDFKIT_OFF(RasterPush, scale)}, sizeof(RasterPush)});
  for (const char* blur : {"atlas_blur.comp", "atlas_blur_box.comp"})
    expect_block(blur, {{SDFKIT_OFF(BlurPush, job_offset), SDFKIT_OFF(BlurPush, job_count), SDFKIT_OFF(BlurPush, size),
                         SDFKIT_OFF(BlurPush, axis), SDFKIT_OFF(BlurPush, box), SDFKIT_OFF(BlurPush, src_tiled)},
                        sizeof(BlurPush)});
  expect_block("atlas_blur_stretch.comp",
               {{SDFKIT_OFF(StretchBlurPush, job_offset), SDFKIT_OFF(StretchBlurPush, job_count),
                 SDFKIT_OFF(StretchBlurPush, size), SDFKIT_OFF(StretchBlurPush, axis), SDFKIT_OFF(StretchBlurPush, box),
                 SDFKIT_OFF(StretchBlurPush, src_tiled), SDFKIT_OFF(StretchBlurPush, variance)},
                sizeof(StretchBlurPush)});
  expect_block("atlas_sample.comp",
               {{SDFKIT_OFF(SamplePush, vertex_count), SDFKIT_OFF(SamplePush, size)}, sizeof(SamplePush)});
  expect_block("atlas_dilate.comp",
               {{SDFKIT_OFF(DilatePush, chart), SDFKIT_OFF(DilatePush, size), SDFKIT_OFF(DilatePush, reach),
                 SDFKIT_OFF(DilatePush, margin)},
                sizeof(DilatePush)});
}

TEST(PushConstants, ShadersWithoutABlockHaveNoneAndJunkIsRefused) {
  // render_overlay.frag declares no push constants; the reader refuses what is not SPIR-V.
  EXPECT_TRUE(push_constant_layout(embedded_spirv("render_overlay.frag")).offsets.empty());
  const std::uint32_t junk[] = {1, 2, 3, 4, 5, 6};
  EXPECT_THROW(push_constant_layout(junk), Error);
}

}  // namespace
}  // namespace sdfkit::vk
