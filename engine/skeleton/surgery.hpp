#pragma once
// Connectivity surgery (Au et al. 2008, section 4): half-edge collapses on the contracted mesh
// until no triangle is left, then SDF grouping of nodes closer than their grouping distance.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/union_find.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <vector>

namespace sdfkit::skeleton::detail {

struct SurgeryOptions {
  double shape_weight = 1.0;     // w_a
  double sampling_weight = 0.1;  // w_b
  double grouping_global = 0.0;  // ggt * bbox diagonal, model units
  double grouping_local = 0.0;   // gmt
  // When set, grouping never joins two nodes unless this holds for their embedded positions
  // (the skeleton: the segment between them stays inside the solid).
  std::function<bool(const glm::vec3&, const glm::vec3&)> segment_inside;
  // In a mesh component of genus > 0, refuse a collapse that closes a hollow triangle whose
  // embedded sides leave the solid (a loop round a hole; see collapse_to_curves). Needs
  // segment_inside.
  bool keep_handles = false;
};

struct CurveGraph {
  std::vector<glm::vec3> positions;                  // per node: the contracted position
  std::vector<std::vector<std::uint32_t>> members;   // per node: mesh vertices it represents
  std::vector<std::array<std::uint32_t, 2>> edges;   // i < j
  std::size_t collapses = 0;
  std::size_t groupings = 0;
  std::size_t pruned_cycles = 0;  // spurious cycles removed (see collapse_to_curves)
};

// `contracted`: the contracted mesh (closed input connectivity). `radius`: per mesh vertex, the
// local radius in model units (SDF/2); a node's radius is the mean over its members and its
// grouping distance dt = grouping_global + grouping_local * radius.
// Shape cost: F_a(i->j) = p_j^T (Q_i + Q_j) p_j with Q_i the sum over i's edges of K^T K
// (K: the 3x4 matrix giving the squared distance to the edge's line), accumulated on collapse.
// Sampling cost: F_b(i->j) = |p_i - p_j| * sum over i's edges (i,k) of |p_i - p_k|.
// Cost = w_a F_a + w_b F_b; the cheapest half-edge lying on a triangle is collapsed first.
// Grouping then collapses face-less edges shorter than the removed node's dt, shortest first,
// never one whose end points share a neighbour (that would close a cycle of the skeleton).
// Lengths for grouping are measured between the nodes' embedded positions, the mean of their
// vertices' `centres` (per mesh vertex: a centre point inside the solid, model units), not
// between contracted positions: mean-curvature contraction also shrinks a ring's radius, and
// grouping on the shrunk ring left a torus with three nodes.
// Half-edge collapses without a link condition can leave short cycles where a flat part
// collapsed (measured: 3 on CGAL's elephant, 27 on refined_elephant, both genus 0). A solid
// bounded by a closed surface of genus g has a curve skeleton with g independent cycles, so
// per component only the g longest fundamental cycles of the minimum spanning tree (edge
// lengths between embedded positions) are kept; the closing edges of the others are removed.
CurveGraph collapse_to_curves(const Mesh& contracted, std::span<const float> radius,
                              std::span<const glm::vec3> centres, const SurgeryOptions& options);

// Genus of each connected component of a closed mesh, (2 - (V - E + F)) / 2, keyed by the
// component's root in `uf` (a union-find over the mesh's vertices, united here).
std::map<std::uint32_t, int> component_genus(const Mesh& mesh, UnionFind& uf);

}  // namespace sdfkit::skeleton::detail
