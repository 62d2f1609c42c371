// Skeleton pictures: the role of each node (leaf, branch, curve node, sheet node, an ordered
// polyline's first node) and the flat colour each part of a skeleton is drawn in.

#include "sdfkit/render/figure.hpp"

#include "sdfkit/core/error.hpp"

#include <cmath>

namespace sdfkit::render {

std::array<std::uint8_t, 3> skeleton_color(SkeletonPart part) {
  switch (part) {
    case SkeletonPart::Curve: return {20, 20, 20};          // near black
    case SkeletonPart::Sheet: return {255, 160, 40};        // orange fill
    case SkeletonPart::SheetOutline: return {150, 80, 0};   // brown
    case SkeletonPart::Node: return {40, 60, 160};          // dark blue
    case SkeletonPart::Branch: return {220, 30, 30};        // red
    case SkeletonPart::Leaf: return {0, 170, 0};            // green
    case SkeletonPart::First: return {200, 0, 200};         // magenta
  }
  return {0, 0, 0};
}

void validate(const SkeletonOverlay& s) {
  for (std::size_t i = 0; i < s.nodes.size(); ++i)
    if (!std::isfinite(s.nodes[i].x) || !std::isfinite(s.nodes[i].y) || !std::isfinite(s.nodes[i].z))
      throw InputError("skeleton node " + std::to_string(i) + " has a non-finite position");
  const auto check = [&](std::uint32_t k, const std::string& what) {
    if (k >= s.nodes.size()) throw InputError(what + " refers to node " + std::to_string(k) + ", which does not exist");
  };
  for (std::size_t e = 0; e < s.edges.size(); ++e)
    for (const std::uint32_t k : s.edges[e]) check(k, "skeleton edge " + std::to_string(e));
  for (std::size_t t = 0; t < s.sheet_triangles.size(); ++t)
    for (const std::uint32_t k : s.sheet_triangles[t]) check(k, "sheet triangle " + std::to_string(t));
}

std::vector<SkeletonPart> node_parts(const SkeletonOverlay& s) {
  validate(s);
  std::vector<int> degree(s.nodes.size(), 0);
  std::vector<char> in_sheet(s.nodes.size(), 0);
  for (const auto& e : s.edges)
    if (e[0] != e[1]) {
      ++degree[e[0]];
      ++degree[e[1]];
    }
  for (const auto& t : s.sheet_triangles)
    for (const std::uint32_t k : t) in_sheet[k] = 1;
  std::vector<SkeletonPart> parts(s.nodes.size(), SkeletonPart::Node);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (degree[i] == 0 && in_sheet[i]) parts[i] = SkeletonPart::Sheet;
    else if (degree[i] == 1 && !in_sheet[i]) parts[i] = SkeletonPart::Leaf;
    else if (degree[i] >= 3) parts[i] = SkeletonPart::Branch;
  }
  if (s.ordered && !parts.empty()) parts[0] = SkeletonPart::First;
  return parts;
}

}  // namespace sdfkit::render
