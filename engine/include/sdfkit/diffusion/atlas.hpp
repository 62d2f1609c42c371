#pragma once
// The texture atlas of a skeleton texture mapping (STM, Madaras & Ďurikovič; the paper's section
// 4.1): the contract between the code that builds the mapping (engine/diffusion/stm.*) and the
// code that diffuses a per-vertex field through it (the render-graph passes in passes/ and
// engine/diffusion/diffuse.*). Neither side depends on how the other is implemented.
//
// Conventions:
//  - The atlas is `size` × `size` texels; texel (x, y) covers [x, x+1) × [y, y+1), its centre is
//    (x + 0.5, y + 0.5). Atlas coordinates below are in texels, not normalized.
//  - Every chart owns an axis-aligned rectangle of the atlas; rectangles never overlap, and a
//    gutter of `gutter` texels separates each rectangle from its neighbours and the atlas border.
//  - A chart with `wraps_x` is cylindrical: its rectangle's x direction is the angle around a bone
//    and its left and right columns are neighbours (blurs wrap there). y never wraps.
//  - The blur must not carry values from one chart into another: texels outside every chart's
//    coverage are only filled by gutter dilation (from their own chart).

#include <glm/vec2.hpp>

#include <cstdint>
#include <vector>

namespace sdfkit::diffusion {

struct Chart {
  enum class Kind : std::uint8_t { Bone, Joint, Sheet };
  Kind kind = Kind::Bone;
  std::uint32_t x0 = 0, y0 = 0;           // rectangle's lower corner, texels
  std::uint32_t width = 0, height = 0;    // rectangle's size, texels
  bool wraps_x = false;                   // cylindrical in x (see above)
  float texels_per_unit = 0.0f;           // mean scale: atlas texels per model unit in this chart
};

// A triangle to rasterize: a mesh triangle, or a copy of one in each chart it touches (a triangle
// whose vertices fall in different charts is duplicated into each, its corners expressed in that
// chart's parameterization, so no rasterized triangle stretches across the atlas).
struct AtlasTriangle {
  std::uint32_t chart = 0;
  std::uint32_t face = 0;                 // the mesh face it comes from
  glm::vec2 uv[3];                        // atlas texel coordinates of the corners, inside the chart's rectangle
};

// One read-back of a vertex's value: the blurred atlas at `uv` (atlas texels, inside `chart`'s
// rectangle), weighted by `weight` (> 0) among the vertex's samples.
struct VertexSample {
  std::uint32_t vertex = 0;
  std::uint32_t chart = 0;
  glm::vec2 uv{0.0f};
  float weight = 1.0f;
};

struct AtlasMapping {
  std::uint32_t size = 2048;              // atlas is size × size texels
  std::uint32_t gutter = 2;               // texels between rectangles
  std::vector<Chart> charts;
  std::vector<AtlasTriangle> triangles;   // corner c of triangle t carries mesh vertex mesh.triangles[t.face][c]
  std::vector<std::uint32_t> vertex_chart;  // V entries: the chart a vertex belongs to (and is read back from)
  std::vector<glm::vec2> vertex_uv;         // V entries: where, in atlas texels (inside that chart)
  // Optional blended read-back: when not empty, a vertex's value is the weight-normalized mean of
  // the reads of its samples (sorted by vertex, every vertex at least one), each from a chart that
  // covers it (its own, or a neighbour's overlap band), so the result is continuous across chart
  // borders. A read whose texels show another part of the surface next to the vertex (a tear in
  // the chart, or faces below a texel) is left out; a vertex left with none has the reads of its
  // nearest vertices instead (build_stm, StmQuality::dropped_own_reads). Empty: every vertex
  // reads vertex_chart at vertex_uv alone.
  std::vector<VertexSample> samples;
  // Optional, V entries where present: how far around each vertex (model units, along the surface)
  // the chart that covers it deepest reaches before its coverage ends (where its overlap band
  // stops at a fold, or at the band's width). A blur whose kernel reaches further than this sees
  // only part of its kernel; DiffuseOptions::steps = 0 sizes its steps from it. Empty: unknown.
  std::vector<float> vertex_reach;
};

}  // namespace sdfkit::diffusion
