#include "sdfkit/core/weld.hpp"

#include "sdfkit/core/parallel.hpp"

#include <glm/geometric.hpp>

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdlib>
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

// Mixed one coordinate at a time: the xor of the three coordinates' products with odd
// constants, mixed once, gave distinct cells the same 64 bits (2 pairs among the 6.7M cells of
// the subdivided armadillo), which sent every weld of that mesh down the general path.
std::uint64_t cell_hash(std::int64_t x, std::int64_t y, std::int64_t z) {
  std::uint64_t h = mix(static_cast<std::uint64_t>(x) + 0x9E3779B97F4A7C15ull);
  h = mix(h ^ static_cast<std::uint64_t>(y));
  return mix(h ^ static_cast<std::uint64_t>(z));
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
    const std::size_t threads = hashes.size() < (std::size_t{1} << 16) ? 1 : std::size_t{hardware_threads()};
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

// Fresh pages of a large buffer, before their first touch, faulted in by all threads at once
// (MADV_POPULATE_WRITE, one kernel call per 2 MiB instead of a fault per 4 KiB page on first
// touch, in whatever order the first pass touches them); contents unchanged. Where the kernel
// refuses (before Linux 5.14) or the headers lack it, the pages come as usual on first touch.
// (Huge pages, MADV_HUGEPAGE, were tried too: no gain measured on the 2-core VM, and one
// profile spent 46 % of its samples zeroing them; bench/RESULTS.md, s15load.)
void populate(void* data, std::size_t bytes) {
#ifdef MADV_POPULATE_WRITE
  constexpr std::size_t kChunk = std::size_t{2} << 20;
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  const auto at = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t begin = (at + page - 1) / page * page, end = (at + bytes) / page * page;
  if (end < begin + 2 * kChunk) return;
  parallel_for((end - begin + kChunk - 1) / kChunk, [&](std::size_t b, std::size_t e) {
    const std::uintptr_t lo = begin + b * kChunk, hi = std::min<std::uintptr_t>(end, begin + e * kChunk);
    madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_POPULATE_WRITE);
  }, 4);
#else
  (void)data, (void)bytes;
#endif
}

// A copy of `from` into fresh memory populated on all threads.
template <class T>
std::vector<T> copy_of(std::span<const T> from) {
  std::vector<T> to;
  to.reserve(from.size());
  populate(to.data(), from.size_bytes());
  to.assign(from.begin(), from.end());
  return to;
}

// Weld's result where nothing merges: the input, and the identity map.
WeldResult identity_weld(std::span<const glm::vec3> positions, std::span<const Triangle> triangles) {
  WeldResult r;
  r.mesh.positions = copy_of(positions);
  r.mesh.triangles = copy_of(triangles);
  r.input_to_welded.reserve(positions.size());
  populate(r.input_to_welded.data(), positions.size() * sizeof(std::uint32_t));
  r.input_to_welded.resize(positions.size());
  parallel_for(positions.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) r.input_to_welded[i] = static_cast<std::uint32_t>(i);
  }, std::size_t{1} << 15);
  return r;
}

// Proves in one parallel pass, where it holds, that no vertex has an earlier one within the
// tolerance (the usual case for an indexed file). Each vertex enters a 32-bit tag of every
// cell that its +-tolerance box overlaps (for_each_cell: weld's any_cell; its own bucket when
// exact) into an open-addressing table. weld compares vertex i only with vertices whose own
// cell lies in i's box; each of them entered its own cell, and i entered every cell of its
// box, so a pair weld could merge enters some cell twice. Hence, when no tag is entered twice,
// weld merges nothing. A tag entered twice (a real repeat, or two cells sharing a tag within
// one probe run) only answers false, and weld takes its general path; so does a table that
// fills past 7/8 (boxes over many cells), and the pass stops early then.
template <class ForEachCell>
bool nothing_merges(std::size_t n, std::span<const glm::vec3> positions, ForEachCell&& for_each_cell) {
  if (n < 2) return true;
  const std::size_t size = std::bit_ceil(std::max<std::size_t>(2 * n, 64));
  const std::size_t mask = size - 1;
  const std::size_t limit = size / 8 * 7;
  // calloc: fresh zeroed pages, 0 = an empty slot.
  const std::unique_ptr<std::uint32_t[], decltype(&std::free)> slots(
      static_cast<std::uint32_t*>(std::calloc(size, sizeof(std::uint32_t))), &std::free);
  if (!slots) throw std::bad_alloc();
  populate(slots.get(), size * sizeof(std::uint32_t));
  std::atomic<bool> repeated{false};
  std::atomic<std::size_t> entered{0};
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    // A FIFO of cell hashes: each slot is prefetched when its hash is queued and entered
    // kRing hashes later, so that the table's cache misses overlap.
    constexpr std::size_t kRing = 32;
    std::uint64_t ring[kRing];
    std::size_t head = 0, tail = 0, local = 0, base = 0;  // entries: this thread's since the
                                                         // last count, everyone's then
    const auto enter = [&](std::uint64_t hash) {
      const std::uint32_t tag = static_cast<std::uint32_t>(hash >> 32) | 1u;  // never 0
      for (std::size_t k = hash & mask;; k = (k + 1) & mask) {
        std::atomic_ref<std::uint32_t> slot(slots[k]);
        std::uint32_t seen = slot.load(std::memory_order_relaxed);
        if (seen == 0 && slot.compare_exchange_strong(seen, tag, std::memory_order_relaxed)) return true;
        if (seen == tag) return false;
      }
    };
    bool stop = false;
    for (std::size_t i = b; i < e && !stop; ++i) {
      if ((i - b) % 512 == 511) {
        base = entered.fetch_add(local, std::memory_order_relaxed) + local;
        local = 0;
        if (repeated.load(std::memory_order_relaxed)) return;
      }
      for_each_cell(positions[i], [&](std::uint64_t hash) {
        __builtin_prefetch(&slots[hash & mask], 1);
        if (tail - head == kRing && !enter(ring[head++ % kRing])) stop = true;
        ring[tail++ % kRing] = hash;
        // Other threads add at most 512 x 8 entries each beyond `base`, which the 1/8 of the
        // table above the limit holds (a second thread runs from 2^15 vertices up).
        if (base + ++local > limit) stop = true;
        return stop;
      });
    }
    while (!stop && head < tail) stop = !enter(ring[head++ % kRing]);
    if (stop) repeated = true;
  }, std::size_t{1} << 15);
  return !repeated;
}

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
  if (nothing_merges(n, positions, any_cell)) return identity_weld(positions, triangles);
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

  // Nothing merges after all (cells of several vertices, none close enough): every vertex is
  // its own and keeps its number, which is what the numbering below gives, without its serial
  // pass and the triangles' gather through the map.
  if (pending == 0) return identity_weld(positions, triangles);
  WeldResult r;
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
