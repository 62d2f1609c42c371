#include "sdfkit/opencl/bvh.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <limits>
#include <string>

namespace sdfkit::cl {

namespace {

constexpr int kBins = 16;
constexpr int kMedianBelowDepth = 40;

struct Box {
  glm::vec3 lo{std::numeric_limits<float>::max()};
  glm::vec3 hi{-std::numeric_limits<float>::max()};
  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x; }
  float half_area() const {
    if (empty()) return 0.0f;
    const glm::vec3 e = hi - lo;
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
};

struct Builder {
  BvhParams params;
  std::vector<Box> boxes;           // per face
  std::vector<glm::vec3> centroid;  // per face (of its box)
  std::vector<std::uint32_t> items;  // face indices being partitioned
  Bvh out;

  // Fills node `index` with items [begin, end).
  void build(std::uint32_t index, std::size_t begin, std::size_t end, int depth) {
    out.depth = std::max(out.depth, depth);
    Box bounds, cbounds;
    for (std::size_t i = begin; i < end; ++i) {
      bounds.grow(boxes[items[i]]);
      cbounds.grow(centroid[items[i]]);
    }
    const std::size_t n = end - begin;
    BvhNode& node = out.nodes[index];
    node.min = bounds.empty() ? glm::vec3(0.0f) : bounds.lo;
    node.max = bounds.empty() ? glm::vec3(0.0f) : bounds.hi;
    const auto make_leaf = [&] {
      BvhNode& leaf = out.nodes[index];
      leaf.first_or_second = static_cast<std::uint32_t>(begin);
      leaf.count = BvhNode::kLeafBit | static_cast<std::uint32_t>(n);
      ++out.leaf_count;
    };
    if (n <= 1) return make_leaf();

    std::size_t mid = begin;
    const glm::vec3 extent = cbounds.hi - cbounds.lo;
    const bool flat = !(extent.x > 0.0f || extent.y > 0.0f || extent.z > 0.0f);
    if (!flat && depth < kMedianBelowDepth) {
      // Binned SAH over all three axes.
      float best_cost = std::numeric_limits<float>::max();
      int best_axis = -1, best_split = 0;
      for (int axis = 0; axis < 3; ++axis) {
        if (!(extent[axis] > 0.0f)) continue;
        std::array<Box, kBins> bin_box{};
        std::array<std::size_t, kBins> bin_count{};
        const float scale = kBins / extent[axis];
        for (std::size_t i = begin; i < end; ++i) {
          const std::uint32_t f = items[i];
          const int b = std::min(kBins - 1, static_cast<int>((centroid[f][axis] - cbounds.lo[axis]) * scale));
          bin_box[static_cast<std::size_t>(b)].grow(boxes[f]);
          ++bin_count[static_cast<std::size_t>(b)];
        }
        std::array<float, kBins> right_cost{};
        Box acc;
        std::size_t count = 0;
        for (int b = kBins - 1; b > 0; --b) {
          acc.grow(bin_box[static_cast<std::size_t>(b)]);
          count += bin_count[static_cast<std::size_t>(b)];
          right_cost[static_cast<std::size_t>(b)] = acc.half_area() * static_cast<float>(count);
        }
        acc = Box{};
        count = 0;
        for (int b = 0; b < kBins - 1; ++b) {
          acc.grow(bin_box[static_cast<std::size_t>(b)]);
          count += bin_count[static_cast<std::size_t>(b)];
          const float cost = acc.half_area() * static_cast<float>(count) + right_cost[static_cast<std::size_t>(b) + 1];
          if (count > 0 && count < n && cost < best_cost) {
            best_cost = cost;
            best_axis = axis;
            best_split = b;
          }
        }
      }
      // SAH: a split costs one traversal step plus its children's expected triangle tests.
      const float leaf_cost = static_cast<float>(n);
      const float split_cost = 1.0f + best_cost / std::max(bounds.half_area(), 1e-30f);
      if (n <= static_cast<std::size_t>(params.leaf_size) && (best_axis < 0 || split_cost >= leaf_cost))
        return make_leaf();
      if (best_axis >= 0) {
        const float scale = kBins / extent[best_axis];
        const auto it = std::partition(items.begin() + static_cast<std::ptrdiff_t>(begin),
                                       items.begin() + static_cast<std::ptrdiff_t>(end),
                                       [&](std::uint32_t f) {
                                         const int b = std::min(kBins - 1, static_cast<int>((centroid[f][best_axis] - cbounds.lo[best_axis]) * scale));
                                         return b <= best_split;
                                       });
        mid = static_cast<std::size_t>(it - items.begin());
      }
    } else if (n <= static_cast<std::size_t>(params.leaf_size)) {
      return make_leaf();
    }
    if (mid == begin || mid == end) {
      // Object median along the longest centroid axis (or by index when all coincide).
      const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
      mid = begin + n / 2;
      std::nth_element(items.begin() + static_cast<std::ptrdiff_t>(begin),
                       items.begin() + static_cast<std::ptrdiff_t>(mid),
                       items.begin() + static_cast<std::ptrdiff_t>(end),
                       [&](std::uint32_t a, std::uint32_t b) {
                         return centroid[a][axis] != centroid[b][axis] ? centroid[a][axis] < centroid[b][axis] : a < b;
                       });
    }
    const auto left = static_cast<std::uint32_t>(out.nodes.size());
    out.nodes.emplace_back();
    build(left, begin, mid, depth + 1);
    const auto right = static_cast<std::uint32_t>(out.nodes.size());
    out.nodes.emplace_back();
    out.nodes[index].first_or_second = right;
    out.nodes[index].count = 0;
    build(right, mid, end, depth + 1);
  }
};

}  // namespace

Bvh build_bvh(const Mesh& mesh, const BvhParams& params) {
  if (params.leaf_size < 1)
    throw InputError("the BVH leaf size must be at least 1, got " + std::to_string(params.leaf_size));
  Builder b{params, {}, {}, {}, {}};
  const auto degenerate = degenerate_faces(mesh);
  b.boxes.resize(mesh.triangles.size());
  b.centroid.resize(mesh.triangles.size());
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f) {
    if (degenerate[f]) continue;
    for (std::uint32_t v : mesh.triangles[f]) b.boxes[f].grow(mesh.positions[v]);
    b.centroid[f] = (b.boxes[f].lo + b.boxes[f].hi) * 0.5f;
    b.items.push_back(f);
  }
  // Pad every triangle's box by a millionth of the mesh's largest coordinate: the device's slab
  // tests and its triangle tests round differently, and a box shaved by rounding (a flat box
  // of an axis-aligned face, a hit on a box's edge) would hide a hit the triangle test finds.
  float largest = 0.0f;
  for (std::uint32_t f : b.items) largest = std::max({largest, glm::length(b.boxes[f].lo), glm::length(b.boxes[f].hi)});
  const glm::vec3 pad(1e-6f * largest + std::numeric_limits<float>::min());
  for (std::uint32_t f : b.items) {
    b.boxes[f].lo -= pad;
    b.boxes[f].hi += pad;
  }
  b.out.nodes.reserve(2 * b.items.size() / static_cast<std::size_t>(params.leaf_size) + 1);
  b.out.nodes.emplace_back();
  b.build(0, 0, b.items.size(), 0);
  b.out.order = std::move(b.items);
  return std::move(b.out);
}

}  // namespace sdfkit::cl
