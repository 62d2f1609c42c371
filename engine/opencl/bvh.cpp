#include "sdfkit/opencl/bvh.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <future>
#include <limits>
#include <string>

namespace sdfkit::cl {

namespace {

constexpr int kBins = 16;
constexpr int kMedianBelowDepth = 40;
// Meshes with at least this many triangles build the root's two subtrees concurrently (a thread
// costs ~0.1 ms; elephant, 5.5k triangles: 2.7 -> 2.0 ms per build).
constexpr std::size_t kParallelBelow = 1024;

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

// Where a node's triangles go: a leaf, or two children split at `mid` (items partitioned).
struct Split {
  Box bounds;
  bool leaf = true;
  std::size_t mid = 0;
};

// Nodes of one subtree, depth-first, indices local to `nodes`.
struct Subtree {
  std::vector<BvhNode> nodes;
  int depth = 0;
  std::size_t leaf_count = 0;
};

struct Builder {
  BvhParams params;
  std::vector<Box> boxes;           // per face
  std::vector<glm::vec3> centroid;  // per face (of its box)
  std::vector<std::uint32_t> items;  // face indices being partitioned

  // Bounds of items [begin, end) and the split the SAH (or the object median) chooses; a split
  // partitions the range in place. Subtrees over disjoint ranges may be built concurrently.
  Split choose(std::size_t begin, std::size_t end, int depth) {
    Split s;
    Box cbounds;
    for (std::size_t i = begin; i < end; ++i) {
      s.bounds.grow(boxes[items[i]]);
      cbounds.grow(centroid[items[i]]);
    }
    const std::size_t n = end - begin;
    if (n <= 1) return s;
    std::size_t mid = begin;
    const glm::vec3 extent = cbounds.hi - cbounds.lo;
    const bool flat = !(extent.x > 0.0f || extent.y > 0.0f || extent.z > 0.0f);
    if (!flat && depth < kMedianBelowDepth) {
      // Binned SAH over the three axes, binned in one pass over the triangles.
      std::array<std::array<Box, kBins>, 3> bin_box{};
      std::array<std::array<std::size_t, kBins>, 3> bin_count{};
      // As many bins as triangles up to kBins: a small node's sweep over empty bins costs more
      // than its binning (most nodes are small).
      const int bins = static_cast<int>(std::min<std::size_t>(kBins, std::max<std::size_t>(n, 2)));
      glm::vec3 scale(0.0f);
      for (int axis = 0; axis < 3; ++axis)
        if (extent[axis] > 0.0f) scale[axis] = static_cast<float>(bins) / extent[axis];
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t f = items[i];
        const glm::vec3 rel = (centroid[f] - cbounds.lo) * scale;
        for (int axis = 0; axis < 3; ++axis) {
          const auto b = static_cast<std::size_t>(std::min(bins - 1, static_cast<int>(rel[axis])));
          bin_box[static_cast<std::size_t>(axis)][b].grow(boxes[f]);
          ++bin_count[static_cast<std::size_t>(axis)][b];
        }
      }
      float best_cost = std::numeric_limits<float>::max();
      int best_axis = -1, best_split = 0;
      for (int axis = 0; axis < 3; ++axis) {
        if (!(extent[axis] > 0.0f)) continue;
        const auto& bb = bin_box[static_cast<std::size_t>(axis)];
        const auto& bc = bin_count[static_cast<std::size_t>(axis)];
        std::array<float, kBins> right_cost{};
        Box acc;
        std::size_t count = 0;
        for (int b = bins - 1; b > 0; --b) {
          acc.grow(bb[static_cast<std::size_t>(b)]);
          count += bc[static_cast<std::size_t>(b)];
          right_cost[static_cast<std::size_t>(b)] = acc.half_area() * static_cast<float>(count);
        }
        acc = Box{};
        count = 0;
        for (int b = 0; b < bins - 1; ++b) {
          acc.grow(bb[static_cast<std::size_t>(b)]);
          count += bc[static_cast<std::size_t>(b)];
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
      const float split_cost = params.traversal_cost + best_cost / std::max(s.bounds.half_area(), 1e-30f);
      if (n <= static_cast<std::size_t>(params.leaf_size) && (best_axis < 0 || split_cost >= leaf_cost)) return s;
      if (best_axis >= 0) {
        const float sc = scale[best_axis], lo = cbounds.lo[best_axis];
        const auto it = std::partition(items.begin() + static_cast<std::ptrdiff_t>(begin),
                                       items.begin() + static_cast<std::ptrdiff_t>(end),
                                       [&](std::uint32_t f) {
                                         return std::min(bins - 1, static_cast<int>((centroid[f][best_axis] - lo) * sc)) <= best_split;
                                       });
        mid = static_cast<std::size_t>(it - items.begin());
      }
    } else if (n <= static_cast<std::size_t>(params.leaf_size)) {
      return s;
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
    s.leaf = false;
    s.mid = mid;
    return s;
  }

  // Fills node `index` of `t` (already allocated) with items [begin, end), depth-first.
  void build(Subtree& t, std::uint32_t index, std::size_t begin, std::size_t end, int depth) {
    t.depth = std::max(t.depth, depth);
    const Split s = choose(begin, end, depth);
    set_bounds(t.nodes[index], s.bounds);
    if (s.leaf) return make_leaf(t, index, begin, end);
    const auto left = static_cast<std::uint32_t>(t.nodes.size());
    t.nodes.emplace_back();
    build(t, left, begin, s.mid, depth + 1);
    const auto right = static_cast<std::uint32_t>(t.nodes.size());
    t.nodes.emplace_back();
    t.nodes[index].first_or_second = right;
    t.nodes[index].count = 0;
    build(t, right, s.mid, end, depth + 1);
  }

  static void set_bounds(BvhNode& node, const Box& b) {
    node.min = b.empty() ? glm::vec3(0.0f) : b.lo;
    node.max = b.empty() ? glm::vec3(0.0f) : b.hi;
  }
  static void make_leaf(Subtree& t, std::uint32_t index, std::size_t begin, std::size_t end) {
    t.nodes[index].first_or_second = static_cast<std::uint32_t>(begin);
    t.nodes[index].count = BvhNode::kLeafBit | static_cast<std::uint32_t>(end - begin);
    ++t.leaf_count;
  }

  // The whole tree. Large meshes: the root's two subtrees are built on two threads into their
  // own arrays and spliced behind the root, which gives the sequential depth-first layout.
  Bvh build_all() {
    Bvh out;
    const std::size_t n = items.size();
    Subtree whole;
    whole.nodes.emplace_back();
    const Split s = n >= kParallelBelow ? choose(0, n, 0) : Split{};
    if (n < kParallelBelow || s.leaf) {
      build(whole, 0, 0, n, 0);
    } else {
      set_bounds(whole.nodes[0], s.bounds);
      Subtree left, right;
      left.nodes.emplace_back();
      right.nodes.emplace_back();
      auto done = std::async(std::launch::async, [&] { build(right, 0, s.mid, n, 1); });
      build(left, 0, 0, s.mid, 1);
      done.get();
      const auto splice = [&](const Subtree& t) {
        const auto offset = static_cast<std::uint32_t>(whole.nodes.size());
        for (BvhNode node : t.nodes) {
          if (!node.is_leaf()) node.first_or_second += offset;
          whole.nodes.push_back(node);
        }
        whole.depth = std::max(whole.depth, t.depth);
        whole.leaf_count += t.leaf_count;
      };
      whole.nodes.reserve(1 + left.nodes.size() + right.nodes.size());
      splice(left);
      whole.nodes[0].first_or_second = static_cast<std::uint32_t>(whole.nodes.size());
      splice(right);
    }
    out.nodes = std::move(whole.nodes);
    out.depth = whole.depth;
    out.leaf_count = whole.leaf_count;
    out.order = std::move(items);
    return out;
  }
};

// Pad every triangle's box by a millionth of the mesh's largest coordinate: the device's slab
// tests and its triangle tests round differently, and a box shaved by rounding (a flat box
// of an axis-aligned face, a hit on a box's edge) would hide a hit the triangle test finds.
glm::vec3 box_padding(const std::vector<Box>& boxes, const std::vector<std::uint32_t>& faces) {
  float largest = 0.0f;
  for (std::uint32_t f : faces) largest = std::max({largest, glm::length(boxes[f].lo), glm::length(boxes[f].hi)});
  return glm::vec3(1e-6f * largest + std::numeric_limits<float>::min());
}

}  // namespace

Bvh build_bvh(const Mesh& mesh, const BvhParams& params) {
  if (params.leaf_size < 1)
    throw InputError("the BVH leaf size must be at least 1, got " + std::to_string(params.leaf_size));
  if (!(params.traversal_cost > 0.0f) || !std::isfinite(params.traversal_cost))
    throw InputError("the BVH traversal cost must be positive, got " + std::to_string(params.traversal_cost));
  Builder b{params, {}, {}, {}};
  const auto degenerate = degenerate_faces(mesh);
  b.boxes.resize(mesh.triangles.size());
  b.centroid.resize(mesh.triangles.size());
  for (std::uint32_t f = 0; f < mesh.triangles.size(); ++f) {
    if (degenerate[f]) continue;
    for (std::uint32_t v : mesh.triangles[f]) b.boxes[f].grow(mesh.positions[v]);
    b.centroid[f] = (b.boxes[f].lo + b.boxes[f].hi) * 0.5f;
    b.items.push_back(f);
  }
  const glm::vec3 pad = box_padding(b.boxes, b.items);
  for (std::uint32_t f : b.items) {
    b.boxes[f].lo -= pad;
    b.boxes[f].hi += pad;
  }
  return b.build_all();
}

bool refit_bvh(Bvh& bvh, const Mesh& mesh) {
  const auto degenerate = degenerate_faces(mesh);
  std::vector<std::uint8_t> in_tree(mesh.triangles.size(), 0);
  for (std::uint32_t f : bvh.order) in_tree[f] = 1;
  for (std::size_t f = 0; f < in_tree.size(); ++f)
    if (!in_tree[f] && !degenerate[f]) return false;
  std::vector<Box> boxes(mesh.triangles.size());
  for (std::uint32_t f : bvh.order)
    for (std::uint32_t v : mesh.triangles[f]) boxes[f].grow(mesh.positions[v]);
  const glm::vec3 pad = box_padding(boxes, bvh.order);
  // Children follow their parent in the depth-first layout: a reverse sweep visits them first.
  std::vector<Box> node_box(bvh.nodes.size());
  for (std::size_t i = bvh.nodes.size(); i-- > 0;) {
    BvhNode& node = bvh.nodes[i];
    Box b;
    if (node.is_leaf()) {
      for (std::uint32_t k = node.first_or_second; k < node.first_or_second + node.triangles(); ++k)
        b.grow(boxes[bvh.order[k]]);
      if (!b.empty()) b.lo -= pad, b.hi += pad;
    } else {
      b.grow(node_box[i + 1]);
      b.grow(node_box[node.first_or_second]);
    }
    node_box[i] = b;
    Builder::set_bounds(node, b);
  }
  return true;
}

double sah_cost(const Bvh& bvh) {
  if (bvh.nodes.empty()) return 0.0;
  const auto area = [](const BvhNode& n) {
    const glm::dvec3 e = glm::dvec3(n.max) - glm::dvec3(n.min);
    return e.x * e.y + e.y * e.z + e.z * e.x;
  };
  double sum = 0.0;
  for (const BvhNode& n : bvh.nodes) sum += area(n) * (n.is_leaf() ? n.triangles() : 1.0);
  const double root = area(bvh.nodes[0]);
  return root > 0.0 ? sum / root : 0.0;
}

}  // namespace sdfkit::cl
