#pragma once
// Skeleton texture mapping (STM, Madaras & Ďurikovič; the paper's section 4.1): a texture atlas
// of a closed mesh built from its skeleton, for diffusing per-vertex fields in texture space.
//
//   mesh + skeleton ──build_stm()──▶ AtlasMapping (charts packed in one square atlas, a chart and
//                                     atlas position per vertex, the triangles to rasterize)
//                                     + StmQuality (distortion per chart, atlas share used)
//
// Charts (the steps in order: the opening comment of engine/diffusion/stm.cpp):
//  - Bone: one per skeleton segment between joints (a chain of curve nodes of degree 2 between
//    nodes of degree != 2). A vertex is parameterized by the point of the segment's polyline
//    it projects to (between the planes bisecting the bends, so continuous there): y = arc length, x = angle around the polyline in a rotation-minimizing frame,
//    scaled by the median distance of the bone's vertices to the polyline. x wraps, except for a
//    piece of a bone's region that leaves over a quarter turn unused: its x spans the used
//    sector. A bone region cut in pieces (by the demotions below) is one chart per piece;
//    pieces under 12 vertices go to planar joint charts.
//  - Joint: at a leaf (end cap: stereographic projection of the directions around the bone's direction)
//    and, as planar projections, at junctions and wherever a bone chart would fold (closest point
//    at a segment's end, surface normal along the bone, vertex on the polyline, a stretched or
//    flipped triangle).
//  - Sheet: vertices of sheet nodes, parameterized by planar projection of their own triangles.
// Planar regions are split by normal direction (six directions of the region's principal axes)
// into connected charts, so that no triangle of a chart flips.
// Every chart's rectangle is sized from the surface it carries, at one scale (texels per model
// unit) for the whole atlas, and shelf-packed into the atlas with the gutter.
//
// Wrapping (the contract in atlas.hpp): in a chart with wraps_x, an AtlasTriangle whose corners
// straddle the angle seam has its corner x unwrapped by ±width so the triangle is contiguous; its
// x may then leave [x0, x0 + width) by less than width on one side, and a rasterizer draws it at
// x and at x ∓ width, clipped to the rectangle (write_atlas_png does). Every other corner, and
// every vertex_uv, lies inside its chart's rectangle.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/diffusion/atlas.hpp"
#include "sdfkit/skeleton/skeleton.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace sdfkit::diffusion {

struct StmOptions {
  std::uint32_t atlas_size = 2048;  // the atlas is atlas_size² texels (16 … 16384)
  std::uint32_t gutter = 2;         // texels between rectangles and around the atlas (0 … 64)
  // A vertex stays in a bone chart only while its normal is within this angle of perpendicular
  // to the bone (|n·t| ≤ cos(max_normal_angle_deg)): ends and crotches go to joint charts
  // where the cylinder map would fold.
  double max_normal_angle_deg = 50.0;
  // An atlas triangle whose longest edge is over this factor times its model length × the
  // atlas scale is stretched: its vertices in that chart move to a planar joint chart.
  double max_stretch = 3.0;
  // Overlap band, model units (0: only the triangles that touch a chart, one ring). Each chart
  // also carries the triangles within this distance along the surface (shortest edge paths)
  // of its own vertices, parameterized by the chart's map, as far as that map neither flips nor
  // stretches them, nor (in a non-wrapping chart) lays them over triangles the chart already holds
  // (a fold ends the band there), so a blur of σ sees the neighbouring charts'
  // surface up to the band, and (with `blend`) a vertex is read back from every chart whose band
  // covers it. smooth_texture_space sets it to kBandSigmas · σ from the blur's σ.
  double overlap = 0.0;
  // With an overlap band: read every vertex back from every chart that covers it (its own, and
  // the bands of its neighbours), blended by a partition of unity (AtlasMapping::samples). A
  // chart's weight at a vertex it covers is a smoothstep of the distance along the surface from
  // the vertex to where the chart's coverage ends (a vertex with a face around it the chart does
  // not draw), over [0, kBlendShare · overlap]: 1 deep inside the chart, falling to 0 at its
  // band's outer edge or where the band stopped at a fold; the weights are normalized over the
  // charts covering the vertex. They are continuous over the surface and the own chart's is never
  // 0 (its vertices have all their faces drawn), so the blend is continuous across chart borders:
  // no seams by construction, and each vertex's value comes mostly from the charts in which it
  // lies deepest (least touched by the coverage's end). Each weight is also multiplied by
  // exp(-kBlendDistortion · δ), δ the chart's mean of log² σ1 + log² σ2 over the vertex's faces
  // (σ1, σ2: the map's singular values, model units to chart units): where two charts overlap,
  // the one that keeps lengths better around the vertex (whose blur of fixed texels is closer to
  // σ in model units there) counts more.
  bool blend = true;
  // With an overlap band: each joint and sheet chart takes a least squares conformal map (LSCM)
  // over the faces it holds (its own and its band's) in place of its projection. Band faces the
  // map turns over, squashes (σ1/σ2 > max_stretch), stretches past max_stretch or shrinks past
  // it (σ2 < 1 / max_stretch) leave the band
  // (the map is solved again, up to 4 times); kept where the chart's own faces all pass and the
  // map does not fold over itself. False: the projections alone (orthographic, or stereographic
  // around the skeleton).
  bool conformal = true;
};

// The blend's reach as a share of the overlap band (StmOptions::blend): the whole band, so a
// chart's weight rises from 0 at its band's edge to 1 at the band's width inside its coverage.
// (camel, sigma 1..5 edges: share 1/3, 1/2, 2/3, 1 all hold the seam ratio at 0.97..1.17; RMS
// against heat falls with the share up to 1, and 1.5 or 2 change it by under 2 %.)
inline constexpr double kBlendShare = 1.0;
// The distortion's falloff in the blend weights (StmOptions::blend): a Gaussian of unit width in
// log-stretch, exp(-δ / 2), so a chart that stretches the surface by e in one direction counts
// 0.61 of one that keeps lengths. Chosen from 0, 1/4, 1/2, 1, 4, 16 on the camel, elephant and man
// (sdfkit-seam-bench, sigma 1/3/5 edges): 1/2 lowers the RMS against heat diffusion by 13-31 % at
// 3 and 5 edges (camel 0.0082 -> 0.0065 and 0.0117 -> 0.0081) for seam ratios within 0.1 of
// none's on the camel and elephant (man at 3 edges: 2.08 -> 2.43); 1 and more raise the seams.
inline constexpr double kBlendDistortion = 0.5;

// The overlap band a blur of standard deviation σ needs: a 2D Gaussian puts exp(-3²/2) = 1.1 %
// of its weight beyond 3σ, so a band of 3σ cuts off at most that much of a border vertex's kernel.
inline constexpr double kBandSigmas = 3.0;

// Statistics of a distribution over the triangles of a chart, weighted by surface area.
struct Stats {
  double mean = 0, p95 = 0, max = 0;
};

struct ChartQuality {
  Chart::Kind kind = Chart::Kind::Bone;
  std::uint32_t vertices = 0;    // vertices assigned to the chart
  std::uint32_t triangles = 0;   // atlas triangles in the chart (own and duplicated)
  double area = 0;               // model area of the faces whose corners are all in the chart
  std::uint64_t texels = 0;      // width × height of the rectangle
  std::uint64_t covered = 0, overlapped = 0;  // texels covered by its triangles; by more than one
  // Per triangle, from the singular values σ1 ≥ σ2 of the map model surface → atlas, in units of
  // the atlas scale (texels_per_unit of the whole atlas): area distortion σ1σ2 (1 = the same
  // texel density everywhere) and angle distortion σ1/σ2 (1 = conformal). Over the faces whose
  // corners are all in the chart. Angle distortion is capped at 1000 (a triangle mapped to a
  // segment).
  Stats area_distortion, angle_distortion;
};

struct StmQuality {
  std::vector<ChartQuality> charts;
  double atlas_used = 0;           // share of the atlas inside chart rectangles
  double atlas_covered = 0;        // share of the atlas whose texel centres atlas triangles cover
  double texels_per_unit = 0;      // the atlas scale: texels per model unit
  std::uint32_t bone_charts = 0, joint_charts = 0, sheet_charts = 0;
  double bone_vertex_share = 0;    // share of vertices in bone charts
  std::uint64_t duplicated_triangles = 0;  // atlas triangles beyond one per face
  // Share of the texels that atlas triangles cover (texel centres inside) covered by more than one
  // of them: a chart folding over itself (a planar projection of a non-convex piece, a bone
  // chart at a sharp bend) - there, two parts of the surface share texels and the blur mixes them.
  double overlap = 0;
  // The same statistics over every chart's faces together (area weighted).
  Stats area_distortion, angle_distortion;
  double band = 0;                 // the overlap band it was built with (StmOptions::overlap), model units
  // With the blended read-back (AtlasMapping::samples), the reads that do not see the vertex's
  // surroundings are dropped (a texel next to the read drawn by another part of the surface: a
  // tear in the chart, or a crumple of faces below a texel; stm.cpp 7b): how many vertices lost
  // the read of their own chart, and how many of them, left with no read, read where their
  // nearest vertices read.
  std::size_t dropped_own_reads = 0, borrowed_vertices = 0;
  double seconds = 0;              // wall-clock time of build_stm
};

struct Stm {
  AtlasMapping mapping;
  StmQuality quality;
};

// Builds the mapping of `mesh` (V positions, F triangles; closed or not) from `skeleton` (its
// nodes' `vertices` index mesh vertices: skeleton::extract on this mesh, or read_skeleton_json
// of what `sdfkit skeleton` wrote for it). A vertex no node holds takes a neighbour's node.
// With options.overlap > 0 the charts also carry their overlap bands (StmOptions::overlap).
// Deterministic. Throws InputError for an empty mesh, a skeleton without nodes, a node vertex
// out of range, or options out of range.
Stm build_stm(const Mesh& mesh, const skeleton::Skeleton& skeleton, const StmOptions& options = {});

// A read is bilinear over the texels next to its uv, and the blur brings each of them what
// surrounds it in the chart: a read is only as good as the chart around it. The faces the chart
// draws over the 4 × 4 texels around the read (those whose centres lie within 1.5 texels of it
// along each axis) should be one piece of surface around the vertex, joined through their shared
// corners among themselves. A texel of that block drawn by a face of another piece shows another
// part of the surface next to the vertex: a tear, where a band went round a fold and met itself,
// or a crumple of faces smaller than a texel that no texel centre lands in, with the surface
// beyond it drawn next to it. Such a read is dropped from `am.samples`; a vertex left with none
// reads what its nearest vertices with one read (the first ring of them, by edges, up to 8
// rings; each of them counts once; none within 8 rings: its reads stay). Samples stay sorted by
// vertex; an empty `samples` (no blended read-back) is left as it is. build_stm runs it on every
// mapping it makes with a band and blending (StmQuality::dropped_own_reads, borrowed_vertices).
// Throws InputError for a mapping that does not fit the mesh (a sample, triangle or chart index
// out of range, samples not sorted by vertex, a chart of no texels).
struct ReadCheck {
  std::size_t dropped_own = 0;  // vertices that lost the read of their own chart
  std::size_t borrowed = 0;     // of them, those left with none, reading their nearest vertices' reads
};
ReadCheck keep_reads_that_see_the_vertex(const Mesh& mesh, AtlasMapping& mapping);

// Reads a skeleton JSON as written by `sdfkit skeleton` / skeleton::to_json (nodes with position,
// radius, sheet, vertices; edges; sheet_triangles). Throws InputError "<path>: <problem>".
skeleton::Skeleton read_skeleton_json(const std::string& path);
skeleton::Skeleton parse_skeleton_json(const std::string& text, const std::string& what);

// Figure 10: the atlas as an RGB PNG of mapping.size² pixels (y up: row 0 of the image is the
// atlas's top row), every atlas triangle rasterized with the per-vertex values (V entries)
// interpolated and coloured by io::colormap over their [min, max]; gutters and unused texels
// dark. Written atomically. Throws InputError when vertex_values does not fit the mesh.
void write_atlas_png(const AtlasMapping& mapping, const Mesh& mesh, std::span<const float> vertex_values,
                     const std::string& path);

// The mapping as glTF's TEXCOORD_1 (io::WriteOptions::texcoord1): per mesh face, its corners'
// UVs in the chart that holds most of its vertices (a tie: its first vertex's chart), taken from
// that chart's atlas triangle, normalized to [0,1]² with v = 0 at the top, so that the PNG of
// write_atlas_png is the texture they address. Corners of one face are always in one chart, so
// no triangle interpolates across the atlas; the glTF writer splits vertices where the faces
// around them use different charts. A face across a wrapping chart's seam keeps its unwrapped
// corners: it reaches past the rectangle's edge by less than its own width, into the gutter.
std::vector<std::array<glm::vec2, 3>> gltf_corner_uv(const AtlasMapping& mapping, const Mesh& mesh);

}  // namespace sdfkit::diffusion
