#include "sdfkit/core/weld.hpp"

#include "sdfkit/core/parallel.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <memory>
#include <span>
#include <thread>
#include <vector>

namespace sdfkit {
namespace {

constexpr std::uint32_t kNone = UINT32_MAX;
// A grid cell is this many tolerances wide: the +-tolerance box of a point then overlaps one
// cell per axis in 15 cases of 16, so a lookup visits ~1.2 cells (27 with cells of 1 tolerance).
constexpr double kCellInTolerances = 16.0;

std::uint32_t float_bits(float f) {
  if (f == 0.0f) f = 0.0f;  // -0 and +0 weld
  return std::bit_cast<std::uint32_t>(f);
}

std::uint64_t mix(std::uint64_t h) {
  h ^= h >> 33;
  h *= 0xFF51AFD7ED558CCDull;
  h ^= h >> 33;
  h *= 0xC4CEB9FE1A85EC53ull;
  return h ^ (h >> 33);
}

std::uint64_t cell_hash(std::int64_t x, std::int64_t y, std::int64_t z) {
  return mix(static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ull ^
             static_cast<std::uint64_t>(y) * 0xBF58476D1CE4E5B9ull ^
             static_cast<std::uint64_t>(z) * 0x94D049BB133111EBull);
}

// Grid cell coordinate, clamped so that +-1 never overflows (a clamped cell holds many points,
// which only costs time: matches are decided by distance, never by cell).
std::int64_t cell_of(double v) {
  constexpr double kLimit = 4.0e18;
  v = std::clamp(v, -kLimit, kLimit);  // NaN never reaches here: inputs are validated finite
  const auto t = static_cast<std::int64_t>(v);  // floor without a libm call (no SSE4.1 by default)
  return t - static_cast<std::int64_t>(static_cast<double>(t) > v);
}

// A hash table of chains: bucket -> first vertex, next[vertex] -> the next vertex in that
// bucket. Vertices of different cells may share a bucket; lookups compare positions.
class Buckets {
public:
  explicit Buckets(std::size_t n) : next_(n, kNone) {
    const std::size_t size = std::bit_ceil(std::max<std::size_t>(2 * n, 64));
    head_.assign(size, kNone);
    mask_ = size - 1;
  }
  // Pushes vertices n-1 .. 0 (hashes[v] for vertex v) on their buckets' chains. Inserted in
  // decreasing index order, every chain lists its vertices in increasing order: a lookup for
  // vertex i stops at the first index >= i, and the first match it meets is the earliest (so 20k
  // copies of one point cost 20k steps, not 20k^2). On all threads: each thread takes one range
  // of buckets and pushes its vertices in that same order, so the chains do not depend on the
  // thread count.
  void insert_all(std::span<const std::uint64_t> hashes) {
    const std::size_t threads = hashes.size() < (std::size_t{1} << 16) ? 1 : std::max(1u, std::thread::hardware_concurrency());
    const std::size_t buckets = mask_ + 1;
    parallel_for(threads, [&](std::size_t tb, std::size_t te) {
      for (std::size_t t = tb; t < te; ++t) {
        const std::size_t lo = buckets * t / threads, hi = buckets * (t + 1) / threads;
        for (std::size_t i = hashes.size(); i-- > 0;) {
          const std::size_t b = hashes[i] & mask_;
          if (b < lo || b >= hi) continue;
          next_[i] = head_[b];
          head_[b] = static_cast<std::uint32_t>(i);
        }
      }
    }, 1);
  }
  // Brings the bucket's head into the cache ahead of use: the table is far larger than the
  // caches, and overlapping these misses is what makes the passes fast.
  void prefetch(std::uint64_t hash) const { __builtin_prefetch(&head_[hash & mask_]); }
  // Calls visit(v) for the bucket's vertices v < below, in increasing order, until it returns
  // true.
  template <class Visit>
  void for_each_below(std::uint64_t hash, std::uint32_t below, Visit&& visit) const {
    for (std::uint32_t v = head_[hash & mask_]; v != kNone && v < below; v = next_[v])
      if (visit(v)) return;
  }

private:
  std::vector<std::uint32_t> head_, next_;
  std::size_t mask_ = 0;
};

// The first pass's question, "has vertex i an earlier vertex within the tolerance?", through
// an open-addressing table with one 8-byte entry per cell (32 bits of its hash, and its vertex
// when it holds one, or kMulti), filled by all threads. A cell of one vertex, the usual case,
// costs a lookup one run of neighbouring slots (one cache line, prefetched ahead), where the
// chains cost a miss per step (head, next, position); a cell of several (or two cells whose
// hashes share those bits) is answered by the chains, built only then.
class Probe {
public:
  static constexpr std::uint32_t kMulti = UINT32_MAX - 1;
  explicit Probe(std::size_t n) {
    const std::size_t size = std::bit_ceil(std::max<std::size_t>(2 * n, 64));
    slots_.reset(new std::uint64_t[size]);
    mask_ = size - 1;
    parallel_for(size, [&](std::size_t b, std::size_t e) {
      std::fill(slots_.get() + b, slots_.get() + e, kEmpty);
    }, std::size_t{1} << 18);
  }
  // Enters vertices [0, hashes.size()) on all threads (their slots do not matter to lookups);
  // returns whether some cell holds several.
  bool insert_all(std::span<const std::uint64_t> hashes) {
    std::atomic<bool> multi{false};
    parallel_for(hashes.size(), [&](std::size_t b, std::size_t e) {
      bool local = false;
      for (std::size_t i = b; i < e; ++i) {
        const std::uint64_t tag = hashes[i] >> 32;
        for (std::size_t k = hashes[i] & mask_;; k = (k + 1) & mask_) {
          std::atomic_ref<std::uint64_t> slot(slots_[k]);
          std::uint64_t seen = slot.load(std::memory_order_relaxed);
          if (seen == kEmpty && slot.compare_exchange_strong(seen, tag << 32 | i, std::memory_order_relaxed))
            break;
          // Taken (seen now holds the entry): the same cell's makes it several, another goes on.
          if (seen >> 32 == tag) {
            slot.store(tag << 32 | kMulti, std::memory_order_relaxed);
            local = true;
            break;
          }
        }
      }
      if (local) multi = true;
    }, std::size_t{1} << 15);
    return multi;
  }
  void prefetch(std::uint64_t hash) const { __builtin_prefetch(&slots_[hash & mask_]); }
  // The cell's vertex, kMulti, or kNone when no vertex has that hash.
  std::uint32_t find(std::uint64_t hash) const {
    const std::uint64_t tag = hash >> 32;
    for (std::size_t k = hash & mask_;; k = (k + 1) & mask_) {
      const std::uint64_t e = slots_[k];
      if (e == kEmpty) return kNone;
      if (e >> 32 == tag) return static_cast<std::uint32_t>(e);
    }
  }

private:
  static constexpr std::uint64_t kEmpty = UINT64_MAX;  // vertex 2^32 - 1 does not exist
  std::unique_ptr<std::uint64_t[]> slots_;
  std::size_t mask_ = 0;
};

}  // namespace

float default_weld_tolerance(std::span<const glm::vec3> positions) {
  if (positions.empty()) return 0.0f;
  const Aabb box = bounding_box(positions);
  const float magnitude = std::max({std::abs(box.min.x), std::abs(box.min.y), std::abs(box.min.z),
                                    std::abs(box.max.x), std::abs(box.max.y), std::abs(box.max.z)});
  const float t = 1e-6f * std::max(box.diagonal(), magnitude);
  return std::isfinite(t) ? t : 0.0f;
}

WeldResult weld(std::span<const glm::vec3> positions, std::span<const Triangle> triangles,
                float tolerance) {
  const std::size_t n = positions.size();
  const bool exact = !(tolerance > 0.0f);
  const double cell = exact ? 1.0 : kCellInTolerances * static_cast<double>(tolerance);
  const double inv_cell = 1.0 / cell;
  const float tol2 = tolerance * tolerance;

  // Exact: one bucket per bit pattern. Tolerance: the cell's hash.
  const auto hash_of = [&](const glm::vec3& p) {
    if (exact)
      return mix((static_cast<std::uint64_t>(float_bits(p.x)) << 32 | float_bits(p.y)) ^
                 (static_cast<std::uint64_t>(float_bits(p.z)) * 0x9E3779B97F4A7C15ull));
    return cell_hash(cell_of(p.x * inv_cell), cell_of(p.y * inv_cell), cell_of(p.z * inv_cell));
  };
  const auto same = [&](const glm::vec3& a, const glm::vec3& b) {
    if (exact)
      return float_bits(a.x) == float_bits(b.x) && float_bits(a.y) == float_bits(b.y) &&
             float_bits(a.z) == float_bits(b.z);
    const glm::vec3 d = a - b;
    return glm::dot(d, d) <= tol2;
  };
  // Calls visit_cell(hash) for the hash of every cell a match of p can lie in (exact: p's bucket),
  // until it returns true; returns whether one did.
  const auto any_cell = [&](const glm::vec3& p, auto&& visit_cell) {
    if (exact) return visit_cell(hash_of(p));
    const double t = static_cast<double>(tolerance);
    std::int64_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = cell_of((static_cast<double>(p[a]) - t) * inv_cell);
      hi[a] = cell_of((static_cast<double>(p[a]) + t) * inv_cell);
    }
    for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
      for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
        for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
          if (visit_cell(cell_hash(x, y, z))) return true;
    return false;
  };

  constexpr std::size_t kGrain = 1 << 15;
  constexpr std::size_t kAhead = 16;  // prefetch distance, vertices
  std::vector<std::uint64_t> hashes(n);  // of each vertex's own cell (exact: of its bits)
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) hashes[i] = hash_of(positions[i]);
  }, kGrain);

  // rep[i]: the input vertex that i welds to. First pass, in parallel: a vertex with no earlier
  // vertex within the tolerance is its own; the others (kNone) are resolved in input order.
  std::vector<std::uint32_t> rep(n);
  std::atomic<std::size_t> pending{0};
  std::unique_ptr<Buckets> buckets;  // the chains, once some cell holds several vertices
  const auto chains = [&] {
    if (!buckets) {
      buckets = std::make_unique<Buckets>(n);
      buckets->insert_all(hashes);
    }
    return buckets.get();
  };
  {
    Probe probe(n);
    const Buckets* several = probe.insert_all(hashes) ? chains() : nullptr;
    parallel_for(n, [&](std::size_t b, std::size_t e) {
      std::size_t local = 0;
      for (std::size_t i = b; i < e; ++i) {
        if (i + kAhead < e) probe.prefetch(hashes[i + kAhead]);
        const glm::vec3& p = positions[i];
        const auto below = static_cast<std::uint32_t>(i);
        const bool earlier = any_cell(p, [&](std::uint64_t hash) {
          const std::uint32_t v = probe.find(hash);
          if (v != Probe::kMulti) return v < below && same(positions[v], p);
          bool found = false;
          several->for_each_below(hash, below, [&](std::uint32_t j) { return found = same(positions[j], p); });
          return found;
        });
        rep[i] = earlier ? kNone : below;
        local += earlier;
      }
      pending += local;
    }, kGrain);
  }
  if (pending > 0) {
    // Greedy in input order: i joins the earliest earlier vertex within the tolerance that is
    // itself a welded vertex (all rep[j], j < i, are final here). The chains list each bucket's
    // vertices in increasing order (see Buckets::insert_all).
    Buckets* bucket_chains = chains();
    for (std::size_t i = 0; i < n; ++i) {
      if (rep[i] != kNone) continue;
      const glm::vec3& p = positions[i];
      std::uint32_t best = kNone;
      any_cell(p, [&](std::uint64_t hash) {
        bucket_chains->for_each_below(hash, static_cast<std::uint32_t>(i), [&](std::uint32_t j) {
          if (j >= best) return true;  // a later bucket's candidates can only be earlier
          if (rep[j] == j && same(positions[j], p)) {
            best = j;
            return true;
          }
          return false;
        });
        return false;
      });
      rep[i] = best == kNone ? static_cast<std::uint32_t>(i) : best;
    }
  }
  hashes = std::vector<std::uint64_t>();

  WeldResult r;
  if (pending == 0) {
    // Nothing merges (the usual case for an indexed file): every vertex is its own and keeps
    // its number, which is what the general path below gives, without its serial numbering
    // pass and the triangles' gather through the map.
    r.mesh.positions.assign(positions.begin(), positions.end());
    r.mesh.triangles.assign(triangles.begin(), triangles.end());
    r.input_to_welded.resize(n);
    parallel_for(n, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) r.input_to_welded[i] = static_cast<std::uint32_t>(i);
    }, kGrain);
    return r;
  }
  // Number the welded vertices in input order; map every input vertex.
  r.input_to_welded.resize(n);
  std::uint32_t count = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (rep[i] == i) r.input_to_welded[i] = count++;
  r.mesh.positions.resize(count);
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (rep[i] == i) r.mesh.positions[r.input_to_welded[i]] = positions[i];
      else r.input_to_welded[i] = r.input_to_welded[rep[i]];
    }
  }, kGrain);
  r.mesh.triangles.resize(triangles.size());
  parallel_for(triangles.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t f = b; f < e; ++f)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t idx = triangles[f][k];
        r.mesh.triangles[f][k] = idx < n ? r.input_to_welded[idx] : idx;
      }
  }, kGrain);
  return r;
}

}  // namespace sdfkit
