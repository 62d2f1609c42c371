// Steps 4 to 6: the SDF per point, the inward shift, agglomerative clustering into an ordered
// polyline, the --segments search, resampling and head/tail consistency over a sequence; and
// point_cloud_skeleton(), which chains all steps.

#include "sdfkit/pointcloud/pointcloud.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/parallel.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <random>
#include <tuple>

#include <time.h>

namespace sdfkit::pointcloud {
namespace {

// Path compression union-find on plain indices (local: MergeTree replays merges in order).
struct Dsu {
  std::vector<std::uint32_t> p;
  explicit Dsu(std::size_t n) : p(n) { std::iota(p.begin(), p.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (p[x] != x) {
      p[x] = p[p[x]];
      x = p[x];
    }
    return x;
  }
};

// Symmetric edge list (i < j) of the neighbour graph, without duplicates, in O(n k^2): the edge
// {i, j} comes from row min(i, j) when that row lists the other, else from the other row.
std::vector<std::pair<std::uint32_t, std::uint32_t>> graph_edges(const Neighbours& nb, std::size_t n) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  edges.reserve(n * static_cast<std::size_t>(nb.k));
  for (std::size_t i = 0; i < n; ++i) {
    const auto row = nb.of(i);
    for (std::size_t m = 0; m < row.size(); ++m) {
      const std::uint32_t j = row[m];
      if (j == i || std::find(row.begin(), row.begin() + static_cast<std::ptrdiff_t>(m), j) != row.begin() + static_cast<std::ptrdiff_t>(m))
        continue;  // itself, or listed twice
      if (j > i) {
        edges.emplace_back(static_cast<std::uint32_t>(i), j);
      } else {
        const auto other = nb.of(j);
        if (std::find(other.begin(), other.end(), static_cast<std::uint32_t>(i)) == other.end())
          edges.emplace_back(j, static_cast<std::uint32_t>(i));
      }
    }
  }
  return edges;
}

double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

std::vector<float> point_sdf(SdfBackend& backend, const Mesh& surface, std::span<const glm::vec3> normals,
                             const SdfOptions& options) {
  if (normals.size() != surface.positions.size())
    throw InputError("point_sdf: one normal per point is needed");
  backend.set_mesh(surface);
  SdfQuery query;
  query.domain = SdfDomain::Vertex;
  query.origins = surface.positions;
  query.normals.assign(normals.begin(), normals.end());
  query.valid.resize(normals.size());
  for (std::size_t i = 0; i < normals.size(); ++i) query.valid[i] = glm::dot(normals[i], normals[i]) > 0.5f;
  query.origin_offset = kOriginOffset * bounding_box(surface.positions).diagonal();
  SdfOptions opts = options;
  opts.domain = SdfDomain::Vertex;
  RawSdf raw = backend.compute(query, opts);
  return finish_field(surface, SdfDomain::Vertex, std::move(raw)).values;
}

std::vector<float> median_filter(std::span<const float> sdf, const Neighbours& nb) {
  const std::size_t n = sdf.size();
  if (nb.k > 0 && nb.index.size() != n * static_cast<std::size_t>(nb.k))
    throw InputError("median_filter: one neighbour row per value is needed");
  std::vector<float> out(n);
  parallel_for(n, [&](std::size_t begin, std::size_t end) {
    std::vector<float> v;
    for (std::size_t i = begin; i < end; ++i) {
      v.assign(1, sdf[i]);
      for (std::uint32_t j : nb.of(i)) v.push_back(sdf[j]);
      const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
      std::nth_element(v.begin(), mid, v.end());
      out[i] = *mid;
    }
  }, 8192);
  return out;
}

std::vector<glm::vec3> shift_inward(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                                    std::span<const float> sdf) {
  std::vector<glm::vec3> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) out[i] = points[i] - normals[i] * (0.5f * sdf[i]);
  return out;
}

// ---- MergeTree ---------------------------------------------------------------------------------

MergeTree::MergeTree(std::span<const glm::vec3> points, const Neighbours& connectivity, Linkage linkage)
    : n_(points.size()) {
  const auto edges = graph_edges(connectivity, n_);
  std::vector<float>& heights = heights_;
  if (linkage == Linkage::Single) {
    // Kruskal: single linkage merges are the minimum spanning tree's edges by length.
    std::vector<std::pair<float, std::uint32_t>> order(edges.size());
    for (std::size_t e = 0; e < edges.size(); ++e)
      order[e] = {glm::distance(points[edges[e].first], points[edges[e].second]), static_cast<std::uint32_t>(e)};
    std::sort(order.begin(), order.end());
    Dsu dsu(n_);
    for (const auto& [d, e] : order) {
      const std::uint32_t a = dsu.find(edges[e].first), b = dsu.find(edges[e].second);
      if (a == b) continue;
      dsu.p[b] = a;
      merges_.emplace_back(a, b);
      heights.push_back(d);
    }
  } else {
    // Average linkage in the root-mean-square sense: the mean squared distance between the
    // points of A and B is |c_A - c_B|^2 + var_A + var_B, kept exactly by each cluster's count,
    // sum and sum of squared norms. Greedy: always merge the closest adjacent pair.
    //
    // Every cluster keeps its nearest adjacent cluster (best) and the heap holds one entry per
    // cluster (stale entries are skipped by a per-cluster stamp), so the heap stays about n
    // entries instead of one per graph edge and update. A merge of a and b only changes the
    // distances to the merged cluster: a neighbour whose best was a or b rescans its adjacency,
    // any other neighbour compares its best with the merged cluster. The merge sequence is the
    // greedy one (tested against a brute-force search).
    std::vector<double> count(n_, 1.0), sumsq(n_), var(n_, 0.0);
    std::vector<glm::dvec3> sum(n_), centre(n_);
    for (std::size_t i = 0; i < n_; ++i) {
      centre[i] = sum[i] = glm::dvec3(points[i]);
      sumsq[i] = glm::dot(sum[i], sum[i]);
    }
    auto dist2 = [&](std::uint32_t a, std::uint32_t b) {
      const glm::dvec3 d = centre[a] - centre[b];
      return std::max(0.0, glm::dot(d, d) + (var[a] + var[b]));
    };
    // Adjacency as CSR first (one allocation), then per-cluster lists that merges rewrite.
    std::vector<std::vector<std::uint32_t>> adj(n_);
    {
      std::vector<std::uint32_t> deg(n_, 0);
      for (const auto& [a, b] : edges) {
        ++deg[a];
        ++deg[b];
      }
      for (std::size_t i = 0; i < n_; ++i) adj[i].reserve(deg[i]);
      for (const auto& [a, b] : edges) {
        adj[a].push_back(b);
        adj[b].push_back(a);
      }
    }
    constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> best(n_, kNone), stamp(n_, 0);
    std::vector<double> best_d2(n_, std::numeric_limits<double>::infinity());
    std::vector<std::uint8_t> alive(n_, 1);
    struct Item {
      double d2;
      std::uint32_t a, stamp;
      bool operator>(const Item& o) const { return d2 > o.d2; }
    };
    std::vector<Item> items;
    items.reserve(2 * n_);
    auto rescan = [&](std::uint32_t c) {
      best[c] = kNone;
      best_d2[c] = std::numeric_limits<double>::infinity();
      for (std::uint32_t x : adj[c]) {
        const double d = dist2(c, x);
        if (d < best_d2[c] || (d == best_d2[c] && x < best[c])) {
          best_d2[c] = d;
          best[c] = x;
        }
      }
    };
    for (std::uint32_t i = 0; i < n_; ++i) {
      rescan(i);
      if (best[i] != kNone) items.push_back({best_d2[i], i, 0u});
    }
    std::priority_queue<Item, std::vector<Item>, std::greater<>> heap(std::greater<>{}, std::move(items));
    while (!heap.empty()) {
      const Item top = heap.top();
      heap.pop();
      if (!alive[top.a] || stamp[top.a] != top.stamp) continue;
      std::uint32_t a = top.a, b = best[top.a];
      if (adj[a].size() < adj[b].size()) std::swap(a, b);  // keep the larger list
      merges_.emplace_back(a, b);
      heights.push_back(static_cast<float>(std::sqrt(top.d2)));
      alive[b] = 0;
      ++stamp[b];
      count[a] += count[b];
      sum[a] += sum[b];
      sumsq[a] += sumsq[b];
      centre[a] = sum[a] / count[a];
      var[a] = sumsq[a] / count[a] - glm::dot(centre[a], centre[a]);
      // b's neighbours now border a: rewrite their lists, and a's own.
      for (std::uint32_t c : adj[b]) {
        if (c == a) continue;
        auto& l = adj[c];
        const bool has_a = std::find(l.begin(), l.end(), a) != l.end();
        auto it = std::find(l.begin(), l.end(), b);
        if (has_a) {
          *it = l.back();
          l.pop_back();
        } else {
          *it = a;
          adj[a].push_back(c);
        }
      }
      adj[a].erase(std::remove(adj[a].begin(), adj[a].end(), b), adj[a].end());
      std::vector<std::uint32_t>().swap(adj[b]);
      rescan(a);
      ++stamp[a];
      if (best[a] != kNone) heap.push({best_d2[a], a, stamp[a]});
      for (std::uint32_t c : adj[a]) {
        if (best[c] == a || best[c] == b) {
          rescan(c);
        } else {
          const double d = dist2(c, a);
          if (!(d < best_d2[c] || (d == best_d2[c] && a < best[c]))) continue;
          best_d2[c] = d;
          best[c] = a;
        }
        ++stamp[c];
        heap.push({best_d2[c], c, stamp[c]});
      }
    }
  }
  prefix_max_.resize(heights.size());
  float running = -std::numeric_limits<float>::infinity();
  for (std::size_t m = 0; m < heights.size(); ++m) prefix_max_[m] = running = std::max(running, heights[m]);
}

std::size_t MergeTree::cluster_count(float t) const {
  const auto m = static_cast<std::size_t>(std::upper_bound(prefix_max_.begin(), prefix_max_.end(), t) - prefix_max_.begin());
  return n_ - m;
}

std::vector<std::uint32_t> MergeTree::labels(float t) const { return labels_after(n_ - cluster_count(t)); }

std::vector<std::uint32_t> MergeTree::labels_after(std::size_t merges) const {
  merges = std::min(merges, merges_.size());
  Dsu dsu(n_);
  for (std::size_t m = 0; m < merges; ++m) dsu.p[merges_[m].second] = merges_[m].first;
  std::vector<std::uint32_t> root(n_), label(n_);
  std::vector<std::uint32_t> id(n_, std::numeric_limits<std::uint32_t>::max());
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    const std::uint32_t r = dsu.find(static_cast<std::uint32_t>(i));
    if (id[r] == std::numeric_limits<std::uint32_t>::max()) id[r] = next++;
    label[i] = id[r];
  }
  return label;
}

std::pair<float, float> MergeTree::threshold_range(std::size_t count) const {
  if (count > n_ || n_ - count > merges_.size() || count == 0) return {0.0f, 0.0f};
  const std::size_t m = n_ - count;  // merges needed
  const float lo = m == 0 ? 0.0f : prefix_max_[m - 1];
  const float hi = m < prefix_max_.size() ? prefix_max_[m] : std::numeric_limits<float>::infinity();
  return {lo, hi};
}

// ---- Ordering ----------------------------------------------------------------------------------

float Polyline::length() const {
  float len = 0.0f;
  for (std::size_t i = 1; i < nodes.size(); ++i) len += glm::distance(nodes[i - 1].position, nodes[i].position);
  return len;
}

Polyline order_clusters(std::span<const glm::vec3> shifted, std::span<const float> sdf,
                        std::span<const std::uint32_t> labels, const Neighbours& connectivity) {
  const std::size_t n = shifted.size();
  std::uint32_t k = 0;
  for (std::uint32_t l : labels) k = std::max(k, l + 1);
  std::vector<glm::dvec3> sum(k, glm::dvec3(0.0));
  std::vector<double> rsum(k, 0.0), cnt(k, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    sum[labels[i]] += glm::dvec3(shifted[i]);
    rsum[labels[i]] += 0.5 * sdf[i];
    cnt[labels[i]] += 1.0;
  }
  std::vector<glm::vec3> centroid(k);
  for (std::uint32_t c = 0; c < k; ++c) centroid[c] = glm::vec3(sum[c] / cnt[c]);
  // Cluster adjacency, then Kruskal's minimum spanning forest by centroid distance.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> cedges;
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t j : connectivity.of(i))
      if (labels[i] != labels[j])
        cedges.emplace_back(std::min(labels[i], labels[j]), std::max(labels[i], labels[j]));
  std::sort(cedges.begin(), cedges.end());
  cedges.erase(std::unique(cedges.begin(), cedges.end()), cedges.end());
  std::sort(cedges.begin(), cedges.end(), [&](const auto& a, const auto& b) {
    return glm::distance(centroid[a.first], centroid[a.second]) < glm::distance(centroid[b.first], centroid[b.second]);
  });
  Dsu dsu(k);
  std::vector<std::vector<std::uint32_t>> tree(k);
  for (const auto& [a, b] : cedges) {
    const std::uint32_t ra = dsu.find(a), rb = dsu.find(b);
    if (ra == rb) continue;
    dsu.p[rb] = ra;
    tree[a].push_back(b);
    tree[b].push_back(a);
  }
  // The component holding the most points.
  std::vector<double> comp_points(k, 0.0);
  for (std::uint32_t c = 0; c < k; ++c) comp_points[dsu.find(c)] += cnt[c];
  const std::uint32_t comp = static_cast<std::uint32_t>(std::max_element(comp_points.begin(), comp_points.end()) - comp_points.begin());
  std::uint32_t start = comp;
  // Farthest node (tree distance) from `from`; fills parent for path recovery.
  std::vector<float> dist(k);
  std::vector<std::uint32_t> parent(k);
  auto farthest = [&](std::uint32_t from) {
    std::fill(dist.begin(), dist.end(), -1.0f);
    std::fill(parent.begin(), parent.end(), std::numeric_limits<std::uint32_t>::max());
    std::vector<std::uint32_t> stack{from};
    dist[from] = 0.0f;
    std::uint32_t best = from;
    while (!stack.empty()) {
      const std::uint32_t c = stack.back();
      stack.pop_back();
      if (dist[c] > dist[best]) best = c;
      for (std::uint32_t d : tree[c])
        if (dist[d] < 0.0f) {
          dist[d] = dist[c] + glm::distance(centroid[c], centroid[d]);
          parent[d] = c;
          stack.push_back(d);
        }
    }
    return best;
  };
  const std::uint32_t end_a = farthest(start);
  const std::uint32_t end_b = farthest(end_a);
  std::vector<std::uint32_t> path;
  for (std::uint32_t c = end_b; c != std::numeric_limits<std::uint32_t>::max(); c = parent[c]) path.push_back(c);
  // Fold every other cluster of the component into the path cluster it hangs from.
  std::vector<std::uint32_t> owner(k, std::numeric_limits<std::uint32_t>::max());
  std::vector<std::uint32_t> queue;
  for (std::size_t p = 0; p < path.size(); ++p) {
    owner[path[p]] = static_cast<std::uint32_t>(p);
    queue.push_back(path[p]);
  }
  for (std::size_t q = 0; q < queue.size(); ++q)
    for (std::uint32_t d : tree[queue[q]])
      if (owner[d] == std::numeric_limits<std::uint32_t>::max()) {
        owner[d] = owner[queue[q]];
        queue.push_back(d);
      }
  std::vector<glm::dvec3> psum(path.size(), glm::dvec3(0.0));
  std::vector<double> pr(path.size(), 0.0), pc(path.size(), 0.0);
  for (std::uint32_t c = 0; c < k; ++c) {
    if (owner[c] == std::numeric_limits<std::uint32_t>::max()) continue;
    psum[owner[c]] += sum[c];
    pr[owner[c]] += rsum[c];
    pc[owner[c]] += cnt[c];
  }
  Polyline line;
  line.nodes.resize(path.size());
  for (std::size_t p = 0; p < path.size(); ++p) {
    line.nodes[p].position = glm::vec3(psum[p] / pc[p]);
    line.nodes[p].radius = static_cast<float>(pr[p] / pc[p]);
  }
  return line;
}

SegmentSearch polyline_with_segments(std::span<const glm::vec3> shifted, std::span<const float> sdf,
                                     const MergeTree& tree, const Neighbours& connectivity, int segments) {
  if (segments < 1) throw InputError("--segments must be at least 1");
  const std::size_t n = tree.point_count();
  const std::size_t target = static_cast<std::size_t>(segments) + 1;
  if (target > n) throw InputError("--segments " + std::to_string(segments) + " needs more points than the cloud has");
  SegmentSearch result;
  // Cluster counts from the target up: the path can be shorter than the cluster count when a
  // cluster hangs off it (folded into its neighbour).
  for (std::size_t c = target; c <= std::min(n, target + 16); ++c) {
    ++result.iterations;
    const auto [lo, hi] = tree.threshold_range(c);
    if (n - c > tree.merge_count()) continue;  // the graph has more than c parts
    Polyline line = order_clusters(shifted, sdf, tree.labels_after(n - c), connectivity);
    if (line.nodes.size() < target) continue;
    result.exact = c == target && line.nodes.size() == target && lo < hi;
    result.threshold = lo;
    // Too many path nodes (a later count jumped past the target): merge the closest neighbours.
    while (line.nodes.size() > target) {
      std::size_t best = 0;
      float bd = std::numeric_limits<float>::infinity();
      for (std::size_t p = 0; p + 1 < line.nodes.size(); ++p) {
        const float d = glm::distance(line.nodes[p].position, line.nodes[p + 1].position);
        if (d < bd) {
          bd = d;
          best = p;
        }
      }
      line.nodes[best].position = 0.5f * (line.nodes[best].position + line.nodes[best + 1].position);
      line.nodes[best].radius = 0.5f * (line.nodes[best].radius + line.nodes[best + 1].radius);
      line.nodes.erase(line.nodes.begin() + static_cast<std::ptrdiff_t>(best) + 1);
      result.exact = false;
    }
    result.polyline = std::move(line);
    return result;
  }
  // No count gave enough path nodes: the longest path found, resampled.
  Polyline line = order_clusters(shifted, sdf, tree.labels_after(n - std::min(n, target)), connectivity);
  result.polyline = line.nodes.size() >= 2 ? resample(line, static_cast<int>(target)) : line;
  result.exact = false;
  return result;
}

Polyline resample(const Polyline& polyline, int nodes) {
  if (nodes < 2) throw InputError("a resampled skeleton needs at least 2 nodes");
  Polyline out;
  const auto& in = polyline.nodes;
  if (in.empty()) return out;
  if (in.size() == 1) {
    out.nodes.assign(static_cast<std::size_t>(nodes), in[0]);
    return out;
  }
  std::vector<float> acc(in.size(), 0.0f);
  for (std::size_t i = 1; i < in.size(); ++i) acc[i] = acc[i - 1] + glm::distance(in[i - 1].position, in[i].position);
  const float total = acc.back();
  out.nodes.resize(static_cast<std::size_t>(nodes));
  std::size_t seg = 0;
  for (int j = 0; j < nodes; ++j) {
    const float s = total * static_cast<float>(j) / static_cast<float>(nodes - 1);
    while (seg + 2 < in.size() && acc[seg + 1] < s) ++seg;
    const float len = acc[seg + 1] - acc[seg];
    const float u = len > 0.0f ? std::clamp((s - acc[seg]) / len, 0.0f, 1.0f) : 0.0f;
    out.nodes[static_cast<std::size_t>(j)].position = glm::mix(in[seg].position, in[seg + 1].position, u);
    out.nodes[static_cast<std::size_t>(j)].radius = in[seg].radius + u * (in[seg + 1].radius - in[seg].radius);
  }
  return out;
}

std::size_t orient_sequence(std::vector<Polyline>& frames) {
  std::size_t reversed = 0;
  for (std::size_t f = 1; f < frames.size(); ++f) {
    const auto& prev = frames[f - 1].nodes;
    auto& cur = frames[f].nodes;
    if (prev.empty() || cur.empty()) continue;
    const float same = glm::distance(prev.front().position, cur.front().position) +
                       glm::distance(prev.back().position, cur.back().position);
    const float swapped = glm::distance(prev.front().position, cur.back().position) +
                          glm::distance(prev.back().position, cur.front().position);
    if (swapped < same) {
      std::reverse(cur.begin(), cur.end());
      ++reversed;
    }
  }
  return reversed;
}

float distance_to_polyline(const glm::vec3& p, const Polyline& line) {
  const auto& nd = line.nodes;
  if (nd.empty()) return std::numeric_limits<float>::infinity();
  float best = glm::distance(p, nd[0].position);
  for (std::size_t i = 1; i < nd.size(); ++i) {
    const glm::vec3 a = nd[i - 1].position, b = nd[i].position, ab = b - a;
    const float l2 = glm::dot(ab, ab);
    const float u = l2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / l2, 0.0f, 1.0f) : 0.0f;
    best = std::min(best, glm::distance(p, a + u * ab));
  }
  return best;
}

float mean_distance(const Polyline& a, const Polyline& b, float step) {
  if (a.nodes.empty()) return 0.0f;
  double total = 0.0;
  std::size_t count = 0;
  total += distance_to_polyline(a.nodes[0].position, b);
  ++count;
  for (std::size_t i = 1; i < a.nodes.size(); ++i) {
    const glm::vec3 p = a.nodes[i - 1].position, q = a.nodes[i].position;
    const int pieces = std::max(1, static_cast<int>(std::ceil(glm::distance(p, q) / step)));
    for (int s = 1; s <= pieces; ++s) {
      total += distance_to_polyline(glm::mix(p, q, static_cast<float>(s) / static_cast<float>(pieces)), b);
      ++count;
    }
  }
  return static_cast<float>(total / static_cast<double>(count));
}

// ---- The pipeline --------------------------------------------------------------------------------

void validate_options(const SkeletonOptions& o) {
  if (o.neighbours < 4 || o.neighbours > 64)
    throw InputError("neighbour count must be in [4, 64] (got " + std::to_string(o.neighbours) + ")");
  if (o.cluster_neighbours < 2 || o.cluster_neighbours > o.neighbours)
    throw InputError("the clustering's neighbour count must be in [2, neighbours]");
  if (o.up_axis < 0 || o.up_axis > 2) throw InputError("up axis must be x, y or z");
  if (o.max_points != 0 && o.max_points < 64) throw InputError("max points must be 0 (all) or at least 64");
  if (o.segments < 0) throw InputError("--segments must be at least 1");
  if (!(o.threshold >= 0.0f) || !std::isfinite(o.threshold)) throw InputError("--threshold must be a finite length >= 0");
  validate_options(o.sdf);
}

SkeletonResult point_cloud_skeleton(std::span<const glm::vec3> points, SdfBackend& backend,
                                    const SkeletonOptions& options) {
  validate_options(options);
  if (points.size() < 8) throw InputError("a point cloud needs at least 8 points (got " + std::to_string(points.size()) + ")");
  for (const glm::vec3& p : points)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError("the point cloud has a non-finite coordinate");
  SkeletonResult r;
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  double c0 = process_cpu_ms();
  auto lap = [&](const char* step) {
    const auto t1 = Clock::now();
    const double c1 = process_cpu_ms();
    r.times.push_back({step, std::chrono::duration<double, std::milli>(t1 - t0).count(), c1 - c0});
    t0 = t1;
    c0 = c1;
  };
  std::vector<glm::vec3> subsample;
  if (options.max_points > 0 && points.size() > options.max_points) {
    // A uniform random subset (partial Fisher-Yates with a fixed seed), kept in input order.
    std::vector<std::uint32_t> idx(points.size());
    std::iota(idx.begin(), idx.end(), 0u);
    std::mt19937 rng(12345);
    for (std::size_t i = 0; i < options.max_points; ++i) {
      std::uniform_int_distribution<std::size_t> pick(i, idx.size() - 1);
      std::swap(idx[i], idx[pick(rng)]);
    }
    idx.resize(options.max_points);
    std::sort(idx.begin(), idx.end());
    subsample.reserve(idx.size());
    for (std::uint32_t i : idx) subsample.push_back(points[i]);
    r.sample = std::move(idx);
    points = subsample;
    lap("subsample");
  }
  const Neighbours nb = k_nearest(points, options.neighbours);
  lap("neighbours");
  const std::vector<glm::vec3> raw = pca_normals(points, nb);
  lap("normals");
  Orientation orient = orient_normals_mst(points, raw, nb, options.up_axis);
  r.normals = std::move(orient.normals);
  r.ambiguous = std::move(orient.ambiguous);
  lap("orientation");
  const Mesh surface = tangent_plane_surface(points, r.normals, nb);
  r.surface_triangles = surface.triangles.size();
  lap("surface");
  if (surface.triangles.empty()) throw InputError("the point cloud gave no surface triangles (all points on a line?)");
  r.sdf = point_sdf(backend, surface, r.normals, options.sdf);
  if (options.median) r.sdf = median_filter(r.sdf, nb);
  lap("sdf");
  r.shifted = shift_inward(points, r.normals, r.sdf);
  lap("shift");
  const Neighbours graph = first_neighbours(nb, options.cluster_neighbours);
  const MergeTree tree(r.shifted, graph, options.linkage);
  lap("clustering");
  if (options.segments > 0) {
    SegmentSearch s = polyline_with_segments(r.shifted, r.sdf, tree, graph, options.segments);
    r.polyline = std::move(s.polyline);
    r.threshold = s.threshold;
    r.exact = s.exact;
  } else {
    float t = options.threshold;
    if (t <= 0.0f) {
      double sum = 0.0;
      for (float v : r.sdf) sum += v;
      t = static_cast<float>(sum / static_cast<double>(r.sdf.size()));
    }
    r.threshold = t;
    r.polyline = order_clusters(r.shifted, r.sdf, tree.labels(t), graph);
  }
  lap("polyline");
  return r;
}

}  // namespace sdfkit::pointcloud
