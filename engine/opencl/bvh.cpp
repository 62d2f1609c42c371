#include "sdfkit/opencl/bvh.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/parallel.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <immintrin.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <limits>
#include <string>
#include <memory>
#include <type_traits>
#include <utility>

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

// Four-lane boxes (lane 3 unused) for the passes over the refs: the same min/max as Box::grow
// (an accumulated value is replaced only by a strictly smaller or larger one), so the same
// bounds bit for bit, in two SSE operations a box instead of six scalar ones.
struct Box4 {
  __m128 lo = _mm_set1_ps(std::numeric_limits<float>::max());
  __m128 hi = _mm_set1_ps(-std::numeric_limits<float>::max());
  void grow(__m128 l, __m128 h) {
    lo = _mm_min_ps(l, lo);  // l < lo ? l : lo, as glm::min(lo, l)
    hi = _mm_max_ps(h, hi);  // h > hi ? h : hi, as glm::max(hi, h)
  }
  void grow(__m128 p) { grow(p, p); }
  // Box::half_area, the same operations in the same order: (x*y + y*z) + z*x, 0 when empty.
  float half_area() const {
    if (_mm_cvtss_f32(lo) > _mm_cvtss_f32(hi)) return 0.0f;
    const __m128 e = _mm_sub_ps(hi, lo);
    const __m128 p = _mm_mul_ps(e, _mm_shuffle_ps(e, e, _MM_SHUFFLE(3, 0, 2, 1)));  // xy, yz, zx
    return (_mm_cvtss_f32(p) + _mm_cvtss_f32(_mm_shuffle_ps(p, p, 1))) + _mm_cvtss_f32(_mm_shuffle_ps(p, p, 2));
  }
  Box box() const {
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo);
    _mm_store_ps(h, hi);
    return Box{{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
  }
};

// One triangle being partitioned: its padded box and face index, 32 bytes, moved as a whole so
// that every pass over a node's triangles reads memory in order.
struct Ref {
  glm::vec3 lo;
  std::uint32_t face;
  glm::vec3 hi;
  std::uint32_t pad;  // 0, set by the fill
  glm::vec3 centroid() const { return (lo + hi) * 0.5f; }
};
static_assert(sizeof(Ref) == 32);
static_assert(std::is_trivially_default_constructible_v<Ref>);

// A ref's corners as four lanes, lane 3 zero (the face index's bits would be a denormal float).
inline __m128 ref_lo(const Ref& r) {
  return _mm_and_ps(_mm_loadu_ps(&r.lo.x), _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1)));
}
inline __m128 ref_hi(const Ref& r) { return _mm_loadu_ps(&r.hi.x); }  // lane 3: pad, 0
// Ref::centroid(), lane for lane.
inline __m128 centroid4(__m128 lo, __m128 hi) { return _mm_mul_ps(_mm_add_ps(lo, hi), _mm_set1_ps(0.5f)); }
inline __m128 vec4(const glm::vec3& v) { return _mm_set_ps(0.0f, v.z, v.y, v.x); }

// Leaves a vector's new elements uninitialized: the refs (32 bytes per triangle, 426 MB at 13M)
// are first written by the parallel fill, not zeroed on one thread before it.
template <class T>
struct Uninitialized : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = Uninitialized<U>;
  };
  Uninitialized() = default;
  template <class U>
  Uninitialized(const Uninitialized<U>&) {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// Where a node's triangles go: a leaf, or two children split at `mid` (refs partitioned).
struct Split {
  Box bounds;
  bool leaf = true;
  std::size_t mid = 0;
  // Bounds and centroid bounds of [begin, mid) and [mid, end), when the partition measured
  // them (SAH splits); an object-median split leaves them to the children's own pass.
  bool children_measured = false;
  Box child_bounds[2], child_cbounds[2];
};

// What a node already knows of its triangles: their bounds and centroid bounds (from its
// parent's partition), or nothing (measured by a pass of its own).
struct Known {
  const Box* bounds = nullptr;
  const Box* cbounds = nullptr;
};
Known child_known(const Split& s, int side) {
  if (!s.children_measured) return {};
  return {&s.child_bounds[side], &s.child_cbounds[side]};
}

// Nodes of one subtree, depth-first, indices local to `nodes`.
struct Subtree {
  std::vector<BvhNode> nodes;
  int depth = 0;
  std::size_t leaf_count = 0;
};

// Nodes with at least this many triangles bin on all threads (a pass over 1M refs is ~2 ms).
constexpr std::size_t kParallelBinning = 1 << 18;

// Per axis and bin: the bounds of the refs whose centroid falls in it, and their count. Only
// the first `bins` of each axis are set (reset): most nodes are small, and setting all 3 x 16
// (1.5 KB) per node cost more than their binning.
struct Bins {
  __m128 lo[3][kBins], hi[3][kBins];
  std::size_t count[3][kBins];
  void reset(int bins) {
    const __m128 big = _mm_set1_ps(std::numeric_limits<float>::max());
    const __m128 small = _mm_set1_ps(-std::numeric_limits<float>::max());
    for (int axis = 0; axis < 3; ++axis)
      for (int k = 0; k < bins; ++k) lo[axis][k] = big, hi[axis][k] = small, count[axis][k] = 0;
  }
};

struct Builder {
  BvhParams params;
  unsigned threads = 1;  // >= 1
  std::vector<Ref, Uninitialized<Ref>> refs;

  // Bounds and centroid bounds of refs [begin, end).
  // `parallel`: on all threads when the range is large (the caller's thread is the only one
  // building).
  void measure(std::size_t begin, std::size_t end, Box& bounds, Box& cbounds, bool parallel) const {
    const auto pass = [&](std::size_t b, std::size_t e, Box& bb, Box& cb) {
      Box4 b4, c4;
      for (std::size_t i = b; i < e; ++i) {
        const __m128 lo = ref_lo(refs[i]), hi = ref_hi(refs[i]);
        b4.grow(lo, hi);
        c4.grow(centroid4(lo, hi));
      }
      bb.grow(b4.box());
      cb.grow(c4.box());
    };
    if (!parallel || end - begin < kParallelBinning) return pass(begin, end, bounds, cbounds);
    std::vector<Box> bb(threads), cb(bb.size());
    std::atomic<std::size_t> slot{0};
    parallel_for(end - begin, [&](std::size_t b, std::size_t e) {
      const std::size_t k = slot++;
      pass(begin + b, begin + e, bb[k], cb[k]);
    }, kParallelBinning / 2, threads);
    for (std::size_t k = 0; k < bb.size(); ++k) bounds.grow(bb[k]), cbounds.grow(cb[k]);
  }

  // Bins refs [begin, end) by centroid on the three axes.
  void bin(std::size_t begin, std::size_t end, int bins, const Box& cbounds, const glm::vec3& scale,
           Bins& out, bool parallel) const {
    // rel = (centroid - cbounds.lo) * scale and its truncation, lane for lane as in glm.
    // rel >= 0 (a centroid is not below cbounds.lo), so truncating min(rel, bins - 1) is
    // min(bins - 1, truncated rel); an infinite or NaN rel (a denormal extent) goes to the last
    // bin instead of a negative index.
    const __m128 clo = vec4(cbounds.lo), sc = vec4(scale), last = _mm_set1_ps(static_cast<float>(bins - 1));
    const auto bin_one = [&](const Ref& ref, Bins& r) {
      const __m128 lo = ref_lo(ref), hi = ref_hi(ref);
      const __m128i k = _mm_cvttps_epi32(_mm_min_ps(_mm_mul_ps(_mm_sub_ps(centroid4(lo, hi), clo), sc), last));
      const auto update = [&](int axis, int kk) {
        r.lo[axis][kk] = _mm_min_ps(lo, r.lo[axis][kk]);
        r.hi[axis][kk] = _mm_max_ps(hi, r.hi[axis][kk]);
        ++r.count[axis][kk];
      };
      update(0, _mm_cvtsi128_si32(k));
      update(1, _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 1)));
      update(2, _mm_cvtsi128_si32(_mm_shuffle_epi32(k, 2)));
    };
    // Neighbouring refs mostly fall in the same bins, and each update waits for the previous
    // one's store: larger ranges alternate between two sets of bins, merged at the end. (The
    // bounds do not depend on the order: min and max of finite values, and the padded boxes
    // hold no -0.)
    const auto pass = [&](std::size_t b, std::size_t e, Bins& r) {
      r.reset(bins);
      if (e - b < 64) {
        for (std::size_t i = b; i < e; ++i) bin_one(refs[i], r);
        return;
      }
      Bins other;
      other.reset(bins);
      std::size_t i = b;
      if (e - b >= 1024) {  // four sets: longer chains apart
        Bins third, fourth;
        third.reset(bins), fourth.reset(bins);
        for (; i + 3 < e; i += 4)
          bin_one(refs[i], r), bin_one(refs[i + 1], other), bin_one(refs[i + 2], third), bin_one(refs[i + 3], fourth);
        merge(other, third, bins);
        merge(r, fourth, bins);
      }
      for (; i + 1 < e; i += 2) bin_one(refs[i], r), bin_one(refs[i + 1], other);
      if (i < e) bin_one(refs[i], r);
      merge(r, other, bins);
    };
    if (!parallel || end - begin < kParallelBinning) return pass(begin, end, out);
    std::vector<Bins> partial(threads);
    for (Bins& p : partial) p.reset(bins);
    std::atomic<std::size_t> slot{0};
    parallel_for(end - begin, [&](std::size_t b, std::size_t e) { pass(begin + b, begin + e, partial[slot++]); },
                 kParallelBinning / 2, threads);
    out.reset(bins);
    for (const Bins& p : partial) merge(out, p, bins);
  }
  static void merge(Bins& into, const Bins& from, int bins) {
    for (int axis = 0; axis < 3; ++axis)
      for (int k = 0; k < bins; ++k) {
        into.lo[axis][k] = _mm_min_ps(from.lo[axis][k], into.lo[axis][k]);
        into.hi[axis][k] = _mm_max_ps(from.hi[axis][k], into.hi[axis][k]);
        into.count[axis][k] += from.count[axis][k];
      }
  }

  // Partitions refs [begin, end) by `left` in place (the same element order as libstdc++'s
  // std::partition, which this replaced: the tree and its triangle order are unchanged) and
  // measures both sides on the way, so that the children need no pass of their own.
  template <class Pred>
  std::size_t partition_measured(std::size_t begin, std::size_t end, Split& s, Pred left) {
    Box4 bb[2], cb[2];
    const auto take = [&](const Ref& r, int side) {
      const __m128 lo = ref_lo(r), hi = ref_hi(r);
      bb[side].grow(lo, hi);
      cb[side].grow(centroid4(lo, hi));
    };
    s.children_measured = true;
    const std::size_t mid = partition_taking(begin, end, left, take);
    for (int side = 0; side < 2; ++side) s.child_bounds[side] = bb[side].box(), s.child_cbounds[side] = cb[side].box();
    return mid;
  }
  template <class Pred, class Take>
  std::size_t partition_taking(std::size_t begin, std::size_t end, Pred left, Take take) {
    std::size_t first = begin, last = end;
    for (;;) {
      for (;;) {
        if (first == last) return first;
        if (!left(refs[first])) break;
        take(refs[first], 0);
        ++first;
      }
      take(refs[first], 1);
      --last;
      for (;;) {
        if (first == last) return first;
        if (left(refs[last])) break;
        take(refs[last], 1);
        --last;
      }
      take(refs[last], 0);
      std::swap(refs[first], refs[last]);
      ++first;
    }
  }

  // Bounds of refs [begin, end) and the split the SAH (or the object median) chooses; a split
  // partitions the range in place. Subtrees over disjoint ranges may be built concurrently.
  Split choose(std::size_t begin, std::size_t end, int depth, Known known, bool parallel_passes) {
    Split s;
    Box cbounds;
    if (known.bounds) s.bounds = *known.bounds, cbounds = *known.cbounds;
    else measure(begin, end, s.bounds, cbounds, parallel_passes);
    const std::size_t n = end - begin;
    if (n <= 1) return s;
    std::size_t mid = begin;
    const glm::vec3 extent = cbounds.hi - cbounds.lo;
    const bool flat = !(extent.x > 0.0f || extent.y > 0.0f || extent.z > 0.0f);
    if (!flat && depth < kMedianBelowDepth) {
      // Binned SAH over the three axes, binned in one pass over the triangles.
      // As many bins as triangles up to kBins: a small node's sweep over empty bins costs more
      // than its binning (most nodes are small).
      const int bins = static_cast<int>(std::min<std::size_t>(kBins, std::max<std::size_t>(n, 2)));
      glm::vec3 scale(0.0f);
      for (int axis = 0; axis < 3; ++axis)
        if (extent[axis] > 0.0f) scale[axis] = static_cast<float>(bins) / extent[axis];
      Bins binned;  // reset by bin
      bin(begin, end, bins, cbounds, scale, binned, parallel_passes);
      float best_cost = std::numeric_limits<float>::max();
      int best_axis = -1, best_split = 0;
      for (int axis = 0; axis < 3; ++axis) {
        if (!(extent[axis] > 0.0f)) continue;
        const __m128* blo = binned.lo[axis];
        const __m128* bhi = binned.hi[axis];
        const std::size_t* bc = binned.count[axis];
        float right_cost[kBins];  // [1, bins) set
        Box4 acc;
        std::size_t count = 0;
        for (int b = bins - 1; b > 0; --b) {
          acc.grow(blo[b], bhi[b]);
          count += bc[b];
          right_cost[b] = acc.half_area() * static_cast<float>(count);
        }
        acc = Box4{};
        count = 0;
        for (int b = 0; b < bins - 1; ++b) {
          acc.grow(blo[b], bhi[b]);
          count += bc[b];
          const float cost = acc.half_area() * static_cast<float>(count) + right_cost[b + 1];
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
        // The bin as bin() takes it: clamped in float before the truncation, so an infinite
        // or NaN product (a denormal extent) is the last bin, not an out-of-range cast.
        const float sc = scale[best_axis], lo = cbounds.lo[best_axis], last = static_cast<float>(bins - 1);
        mid = partition_measured(begin, end, s, [&](const Ref& r) {
          return static_cast<int>(std::min(last, (r.centroid()[best_axis] - lo) * sc)) <= best_split;
        });
      }
    } else if (n <= static_cast<std::size_t>(params.leaf_size)) {
      return s;
    }
    if (mid == begin || mid == end) {
      s.children_measured = false;
      // Object median along the longest centroid axis (or by index when all coincide).
      const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
      mid = begin + n / 2;
      std::nth_element(refs.begin() + static_cast<std::ptrdiff_t>(begin),
                       refs.begin() + static_cast<std::ptrdiff_t>(mid),
                       refs.begin() + static_cast<std::ptrdiff_t>(end), [&](const Ref& a, const Ref& b) {
                         const float ca = a.centroid()[axis], cb = b.centroid()[axis];
                         return ca != cb ? ca < cb : a.face < b.face;
                       });
    }
    s.leaf = false;
    s.mid = mid;
    return s;
  }

  // Fills node `index` of `t` (already allocated) with refs [begin, end), depth-first.
  void build(Subtree& t, std::uint32_t index, std::size_t begin, std::size_t end, int depth, Known known) {
    t.depth = std::max(t.depth, depth);
    const Split s = choose(begin, end, depth, known, false);
    set_bounds(t.nodes[index], s.bounds);
    if (s.leaf) return make_leaf(t, index, begin, end);
    const auto left = static_cast<std::uint32_t>(t.nodes.size());
    t.nodes.emplace_back();
    build(t, left, begin, s.mid, depth + 1, child_known(s, 0));
    const auto right = static_cast<std::uint32_t>(t.nodes.size());
    t.nodes.emplace_back();
    t.nodes[index].first_or_second = right;
    t.nodes[index].count = 0;
    build(t, right, s.mid, end, depth + 1, child_known(s, 1));
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

  // The top of the tree: nodes with more than `task_size` triangles. The root is split on the
  // calling thread (its passes on all threads); then every thread takes the largest node left,
  // splits it (its children join the queue) or, at most `task_size` triangles, builds its whole
  // subtree. The split of a node depends only on its own triangles, so the tree does not depend
  // on which thread took what.
  struct Top {
    Split split;
    std::size_t begin = 0, end = 0;
    int depth = 0;
    Top* child[2] = {nullptr, nullptr};  // internal
    bool task = false;                   // a part, built whole
    bool known = false;                  // bounds measured by the parent's partition
    Box bounds, cbounds;
    Subtree part;
    std::size_t at = 0;  // a part: where its nodes go
    Known given() const { return known ? Known{&bounds, &cbounds} : Known{}; }
  };

  // The whole tree: the top split and its parts built by all threads, then laid out depth-first
  // exactly as a sequential build would.
  Bvh build_all(Known root_known) {
    const std::size_t n = refs.size();
    // Large meshes: parts of ~1/16 of the triangles per thread keep the threads busy to the
    // end. Small ones: the root's two halves, as the top costs more than imbalance there.
    const std::size_t task_size = n < kParallelBelow || threads == 1 ? n
                                  : n < (std::size_t{1} << 20)        ? (n + 1) / 2
                                                                      : n / (16 * threads);
    std::vector<std::unique_ptr<Top>> top;  // a node's address is stable; the vector is locked
    std::vector<Top*> pending, tasks;
    std::mutex lock;
    std::condition_variable wake;
    std::size_t busy = 0;
    // Under the lock.
    const auto add = [&](std::size_t begin, std::size_t end, int depth, Known known) {
      top.push_back(std::make_unique<Top>());
      Top* t = top.back().get();
      t->begin = begin, t->end = end, t->depth = depth;
      if (known.bounds) t->known = true, t->bounds = *known.bounds, t->cbounds = *known.cbounds;
      pending.push_back(t);
      return t;
    };
    const auto split = [&](Top& t, bool parallel_passes) {
      t.split = choose(t.begin, t.end, t.depth, t.given(), parallel_passes);
      if (t.split.leaf) return;
      const std::scoped_lock guard(lock);
      t.child[0] = add(t.begin, t.split.mid, t.depth + 1, child_known(t.split, 0));
      t.child[1] = add(t.split.mid, t.end, t.depth + 1, child_known(t.split, 1));
    };
    Top* root = add(0, n, 0, root_known);
    if (n > task_size) {
      pending.clear();
      split(*root, true);
    }
    const auto worker = [&] {
      for (;;) {
        Top* t = nullptr;
        {
          std::unique_lock<std::mutex> guard(lock);
          wake.wait(guard, [&] { return !pending.empty() || busy == 0; });
          if (pending.empty()) return;  // and no thread can add more
          const auto largest = std::max_element(pending.begin(), pending.end(), [](const Top* a, const Top* b) {
            return a->end - a->begin < b->end - b->begin;
          });
          t = *largest;
          pending.erase(largest);
          ++busy;
        }
        if (t->end - t->begin > task_size) {
          split(*t, false);
        } else {
          t->task = true;
          // At most 2m - 1 nodes for m triangles: no reallocation (and copy) while it grows;
          // only the pages it fills are touched.
          t->part.nodes.reserve(2 * (t->end - t->begin));
          t->part.nodes.emplace_back();
          build(t->part, 0, t->begin, t->end, t->depth, t->given());
        }
        {
          const std::scoped_lock guard(lock);
          --busy;
          if (t->task) tasks.push_back(t);
        }
        wake.notify_all();
      }
    };
    parallel_for(threads, [&](std::size_t, std::size_t) { worker(); }, 1, threads);
    // The copy below takes the largest parts first.
    std::sort(tasks.begin(), tasks.end(), [](const Top* a, const Top* b) { return a->end - a->begin > b->end - b->begin; });

    // The layout: the top's nodes written here in depth-first order, each part's block placed
    // where its subtree goes; the parts are then copied (their child indices shifted) on all
    // threads.
    Bvh out;
    std::size_t total = 0;
    for (const auto& t : top) total += t->task ? t->part.nodes.size() : 1;
    out.nodes.resize(total);
    std::size_t at = 0;
    const auto emit = [&](auto&& self, Top& t) -> void {
      out.depth = std::max(out.depth, t.depth);
      if (t.task) {
        t.at = at;
        at += t.part.nodes.size();
        out.depth = std::max(out.depth, t.part.depth);
        out.leaf_count += t.part.leaf_count;
        return;
      }
      const std::size_t here = at++;
      set_bounds(out.nodes[here], t.split.bounds);
      if (t.split.leaf) {
        out.nodes[here].first_or_second = static_cast<std::uint32_t>(t.begin);
        out.nodes[here].count = BvhNode::kLeafBit | static_cast<std::uint32_t>(t.end - t.begin);
        ++out.leaf_count;
        return;
      }
      self(self, *t.child[0]);
      out.nodes[here].first_or_second = static_cast<std::uint32_t>(at);
      self(self, *t.child[1]);
    };
    emit(emit, *root);
    // Parts differ in size: each thread takes the next one left.
    std::atomic<std::size_t> next_copy{0};
    parallel_for(tasks.size(), [&](std::size_t, std::size_t) {
      for (std::size_t k; (k = next_copy++) < tasks.size();) {
        Subtree& p = tasks[k]->part;
        const auto offset = static_cast<std::uint32_t>(tasks[k]->at);
        BvhNode* dst = out.nodes.data() + offset;
        for (std::size_t i = 0; i < p.nodes.size(); ++i) {
          BvhNode node = p.nodes[i];
          if (!node.is_leaf()) node.first_or_second += offset;
          dst[i] = node;
        }
        p.nodes = std::vector<BvhNode>();
      }
    }, 1, threads);
    out.order.resize(n);
    parallel_for(n, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) out.order[i] = refs[i].face;
    }, 1 << 16, threads);
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
  if (params.threads < 0) throw InputError("the BVH build's thread count must be 0 (all) or more, got " + std::to_string(params.threads));
  const unsigned threads = params.threads > 0 ? static_cast<unsigned>(params.threads) : hardware_threads();
  Builder b{params, threads, {}};
  // Chunks of faces, each filling the refs of its kept (non-degenerate, as degenerate_faces
  // tells them) faces from its first face's slot on, on all threads; then the runs are moved
  // together (only when some face was left out). Face order, one pass over the triangles.
  const std::size_t faces = mesh.triangles.size();
  const std::size_t vertices = mesh.positions.size();
  const std::size_t chunks = std::clamp<std::size_t>(faces >> 16, 1, 64);
  const auto chunk_begin = [&](std::size_t c) { return faces * c / chunks; };
  b.refs.resize(faces);
  std::vector<std::size_t> kept(chunks, 0);
  // Unpadded boxes and the padding (as before: of the boxes' corners).
  std::vector<float> largest(chunks, 0.0f);
  parallel_for(chunks, [&](std::size_t cb, std::size_t ce) {
    for (std::size_t c = cb; c < ce; ++c) {
      float big = 0.0f;
      std::size_t k = chunk_begin(c);
      for (std::size_t f = chunk_begin(c); f < chunk_begin(c + 1); ++f) {
        const Triangle& t = mesh.triangles[f];
        if (t[0] >= vertices || t[1] >= vertices || t[2] >= vertices) continue;
        const glm::vec3 &p0 = mesh.positions[t[0]], &p1 = mesh.positions[t[1]], &p2 = mesh.positions[t[2]];
        if (triangle_is_degenerate(p0, p1, p2)) continue;
        Box box;
        box.grow(p0), box.grow(p1), box.grow(p2);
        b.refs[k++] = Ref{box.lo, static_cast<std::uint32_t>(f), box.hi, 0};
        big = std::max({big, glm::length(box.lo), glm::length(box.hi)});
      }
      kept[c] = k - chunk_begin(c);
      largest[c] = big;
    }
  }, 1, threads);
  std::size_t total = kept[0];
  for (std::size_t c = 1; c < chunks; ++c) {
    // Left, in chunk order: a run never lands on one not yet moved.
    if (total < chunk_begin(c))
      std::memmove(&b.refs[total], &b.refs[chunk_begin(c)], kept[c] * sizeof(Ref));
    total += kept[c];
  }
  b.refs.resize(total);
  // The padding, and with it the root's bounds and centroid bounds (so the root needs no pass
  // of its own).
  const glm::vec3 pad(1e-6f * *std::max_element(largest.begin(), largest.end()) + std::numeric_limits<float>::min());
  std::vector<Box> bb(threads), cb(threads);
  std::atomic<std::size_t> slot{0};
  parallel_for(b.refs.size(), [&](std::size_t begin, std::size_t end) {
    Box4 b4, c4;
    for (std::size_t i = begin; i < end; ++i) {
      Ref& r = b.refs[i];
      r.lo -= pad, r.hi += pad;
      const __m128 lo = ref_lo(r), hi = ref_hi(r);
      b4.grow(lo, hi);
      c4.grow(centroid4(lo, hi));
    }
    const std::size_t k = slot++;
    bb[k] = b4.box(), cb[k] = c4.box();
  }, 1 << 16, threads);
  Box bounds, cbounds;
  for (std::size_t k = 0; k < bb.size(); ++k) bounds.grow(bb[k]), cbounds.grow(cb[k]);
  return b.build_all(Known{&bounds, &cbounds});
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
  // Summed in fixed blocks (on all threads), then the blocks' sums in order: the same value for
  // any thread count.
  constexpr std::size_t kBlock = 1 << 16;
  std::vector<double> block((bvh.nodes.size() + kBlock - 1) / kBlock, 0.0);
  parallel_for(block.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      double sum = 0.0;
      for (std::size_t i = k * kBlock; i < std::min(bvh.nodes.size(), (k + 1) * kBlock); ++i) {
        const BvhNode& n = bvh.nodes[i];
        sum += area(n) * (n.is_leaf() ? n.triangles() : 1.0);
      }
      block[k] = sum;
    }
  }, 8);
  double sum = 0.0;
  for (double s : block) sum += s;
  const double root = area(bvh.nodes[0]);
  return root > 0.0 ? sum / root : 0.0;
}

}  // namespace sdfkit::cl
