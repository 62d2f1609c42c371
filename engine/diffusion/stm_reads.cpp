// The blended read-back's samples, each kept only where its chart shows the vertex's own
// surroundings (stm.hpp; build_stm's step 7b). Measured on CGAL's femur at sigma 5 edges: a
// crumple of faces below a texel had vertices read 1.10 where heat diffusion and their
// neighbours give 1.23 (bench/RESULTS.md, "reads that see the vertex").
#include "sdfkit/diffusion/stm.hpp"

#include "sdfkit/core/topology.hpp"

#include "sdfkit/core/error.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace sdfkit::diffusion {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

double signed_area2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

}  // namespace

ReadCheck keep_reads_that_see_the_vertex(const Mesh& mesh, AtlasMapping& am) {
  constexpr int kBorrowRings = 8;
  constexpr long kCell = 4;  // texels per cell of the charts' triangle grids
  const std::size_t V = mesh.positions.size(), C = am.charts.size();
  ReadCheck check;
  std::size_t& dropped_own = check.dropped_own;
  if (am.samples.empty()) return check;
  for (const VertexSample& s : am.samples)
    if (s.vertex >= V || s.chart >= C) throw InputError("the mapping's samples name a vertex or chart out of range");
  for (const AtlasTriangle& t : am.triangles)
    if (t.chart >= C || t.face >= mesh.triangles.size()) throw InputError("the mapping's triangles name a chart or face out of range");
  if (am.vertex_chart.size() != V) throw InputError("the mapping needs one chart per vertex");
  for (std::size_t k = 1; k < am.samples.size(); ++k)
    if (am.samples[k].vertex < am.samples[k - 1].vertex) throw InputError("the mapping's samples must be sorted by vertex");
  for (const Chart& ch : am.charts)
    if (ch.width == 0 || ch.height == 0) throw InputError("the mapping has a chart of no texels");
  const Adjacency adjacency = vertex_adjacency(mesh);
  const std::vector<std::uint32_t>& adj_start = adjacency.offsets;
  const std::vector<std::uint32_t>& adj = adjacency.indices;
  // Triangles and samples by chart (counting sorts).
  std::vector<std::uint32_t> tri_start(C + 1, 0), tri_of(am.triangles.size()), smp_start(C + 1, 0), smp_of(am.samples.size());
  for (const AtlasTriangle& t : am.triangles) ++tri_start[t.chart + 1];
  for (const VertexSample& s : am.samples) ++smp_start[s.chart + 1];
  for (std::size_t c = 0; c < C; ++c) tri_start[c + 1] += tri_start[c], smp_start[c + 1] += smp_start[c];
  {
    std::vector<std::uint32_t> fill(tri_start.begin(), tri_start.end() - 1), fill2(smp_start.begin(), smp_start.end() - 1);
    for (std::uint32_t i = 0; i < am.triangles.size(); ++i) tri_of[fill[am.triangles[i].chart]++] = i;
    for (std::uint32_t i = 0; i < am.samples.size(); ++i) smp_of[fill2[am.samples[i].chart]++] = i;
  }
  std::vector<std::uint8_t> good(am.samples.size(), 0);
  std::vector<std::uint32_t> face_at, first_face;  // the last and the first face drawn at each texel
  std::vector<std::uint8_t> count_at;
  struct Entry {
    std::uint32_t cell, tri;
    std::int32_t shift;
  };
  std::vector<Entry> entries;
  std::vector<std::uint32_t> cell_start;
  struct Near {
    std::uint32_t face, tri;
    std::int32_t shift;
  };
  std::vector<Near> near;
  std::vector<std::uint32_t> parent;
  // Per sample (stamp), the faces gathered and the corners seen: their slots in `near`.
  const std::size_t F = mesh.triangles.size();
  std::vector<std::uint32_t> face_mark(F, 0), face_slot(F, 0), vertex_mark(V, 0), vertex_slot(V, 0);
  std::uint32_t stamp = 0;
  for (std::uint32_t c = 0; c < C; ++c) {
    if (smp_start[c] == smp_start[c + 1]) continue;
    const Chart& ch = am.charts[c];
    const long W = ch.width, H = ch.height;
    face_at.assign(static_cast<std::size_t>(W * H), kNone);
    first_face.assign(static_cast<std::size_t>(W * H), kNone);
    count_at.assign(static_cast<std::size_t>(W * H), 0);
    // The grid spans x in [-W, 2W) for a wrapping chart (its triangles one width to either side).
    const long gx0 = ch.wraps_x ? -W : 0, gx1 = ch.wraps_x ? 2 * W : W;
    const long ncx = (gx1 - gx0 + kCell - 1) / kCell + 1, ncy = (H + kCell - 1) / kCell + 1;
    entries.clear();
    const auto corner_of = [&](const AtlasTriangle& at, int k, std::int32_t sh) {
      return glm::dvec2(at.uv[k].x - double(ch.x0) + sh * double(W), at.uv[k].y - double(ch.y0));
    };
    for (std::uint32_t k = tri_start[c]; k < tri_start[c + 1]; ++k) {
      const AtlasTriangle& at = am.triangles[tri_of[k]];
      for (std::int32_t sh = ch.wraps_x ? -1 : 0; sh <= (ch.wraps_x ? 1 : 0); ++sh) {
        const glm::dvec2 a = corner_of(at, 0, sh), b = corner_of(at, 1, sh), d = corner_of(at, 2, sh);
        const glm::dvec2 lo = glm::min(glm::min(a, b), d), hi = glm::max(glm::max(a, b), d);
        if (!(hi.x >= double(gx0) && lo.x < double(gx1) && hi.y >= 0 && lo.y < double(H))) continue;
        const long cx0 = std::max(0L, static_cast<long>(std::floor((lo.x - double(gx0)) / kCell)));
        const long cx1 = std::min(ncx - 1, static_cast<long>(std::floor((hi.x - double(gx0)) / kCell)));
        const long cy0 = std::max(0L, static_cast<long>(std::floor(lo.y / kCell)));
        const long cy1 = std::min(ncy - 1, static_cast<long>(std::floor(hi.y / kCell)));
        for (long cy = cy0; cy <= cy1; ++cy)
          for (long cx = cx0; cx <= cx1; ++cx) entries.push_back({static_cast<std::uint32_t>(cy * ncx + cx), tri_of[k], sh});
        // The texels whose centres it covers (half-open, as the quality's coverage), inside the rectangle.
        const double den = signed_area2(a, b, d);
        if (den == 0) continue;
        const long x0 = std::max(0L, static_cast<long>(std::floor(lo.x))), x1 = std::min(W - 1, static_cast<long>(std::floor(hi.x)));
        const long y0 = std::max(0L, static_cast<long>(std::floor(lo.y))), y1 = std::min(H - 1, static_cast<long>(std::floor(hi.y)));
        for (long y = y0; y <= y1; ++y)
          for (long x = x0; x <= x1; ++x) {
            const glm::dvec2 p(x + 0.5, y + 0.5);
            const double w0 = signed_area2(b, d, p) / den, w1 = signed_area2(d, a, p) / den, w2 = 1 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 <= 0) continue;
            const auto i = static_cast<std::size_t>(y * W + x);
            if (count_at[i] == 0) first_face[i] = at.face;
            face_at[i] = at.face;
            if (count_at[i] < 255) ++count_at[i];
          }
      }
    }
    std::sort(entries.begin(), entries.end(), [](const Entry& p, const Entry& q) { return p.cell < q.cell; });
    cell_start.assign(static_cast<std::size_t>(ncx * ncy + 1), 0);
    for (const Entry& e : entries) ++cell_start[e.cell + 1];
    for (std::size_t i = 1; i < cell_start.size(); ++i) cell_start[i] += cell_start[i - 1];
    for (std::uint32_t k = smp_start[c]; k < smp_start[c + 1]; ++k) {
      const VertexSample& s = am.samples[smp_of[k]];
      if (!std::isfinite(s.uv.x) || !std::isfinite(s.uv.y)) continue;  // no texel to read: dropped
      // The block [bx - 1, bx + 3) × [by - 1, by + 3), chart texels.
      const long bx = static_cast<long>(std::floor(s.uv.x - 0.5)) - static_cast<long>(ch.x0);
      const long by = static_cast<long>(std::floor(s.uv.y - 0.5)) - static_cast<long>(ch.y0);
      const auto texel = [&](long dx, long dy) {
        long tx = bx + dx;
        const long ty = std::clamp<long>(by + dy, 0, H - 1);
        tx = ch.wraps_x ? ((tx % W) + W) % W : std::clamp<long>(tx, 0, W - 1);
        return static_cast<std::size_t>(ty * W + tx);
      };
      const auto around = [&](std::uint32_t f) {
        const Triangle& t = mesh.triangles[f];
        return t[0] == s.vertex || t[1] == s.vertex || t[2] == s.vertex;
      };
      // Most reads: every texel of the block drawn by faces around the vertex itself.
      bool covered = false, easy = true;
      for (long dy = -1; dy <= 2 && easy; ++dy)
        for (long dx = -1; dx <= 2 && easy; ++dx) {
          const std::size_t i = texel(dx, dy);
          if (count_at[i] == 0) continue;
          covered = true;
          easy = around(first_face[i]) && around(face_at[i]);
        }
      if (easy) {
        good[smp_of[k]] = covered;
        continue;
      }
      // Else the faces over the block, in pieces joined through their shared corners.
      ++stamp;
      const double rx0 = double(bx - 1), rx1 = double(bx + 3), ry0 = double(by - 1), ry1 = double(by + 3);
      near.clear();
      const long cx0 = std::max(0L, static_cast<long>(std::floor((rx0 - double(gx0)) / kCell)));
      const long cx1 = std::min(ncx - 1, static_cast<long>(std::floor((rx1 - double(gx0)) / kCell)));
      const long cy0 = std::max(0L, static_cast<long>(std::floor(ry0 / kCell))), cy1 = std::min(ncy - 1, static_cast<long>(std::floor(ry1 / kCell)));
      for (long cy = cy0; cy <= cy1; ++cy)
        for (long cx = cx0; cx <= cx1; ++cx) {
          const auto cell = static_cast<std::size_t>(cy * ncx + cx);
          for (std::uint32_t e = cell_start[cell]; e < cell_start[cell + 1]; ++e) {
            const Entry& en = entries[e];
            const AtlasTriangle& at = am.triangles[en.tri];
            if (face_mark[at.face] == stamp) continue;  // a face spans several cells
            const glm::dvec2 a = corner_of(at, 0, en.shift), b = corner_of(at, 1, en.shift), d = corner_of(at, 2, en.shift);
            const glm::dvec2 lo = glm::min(glm::min(a, b), d), hi = glm::max(glm::max(a, b), d);
            if (hi.x < rx0 || lo.x > rx1 || hi.y < ry0 || lo.y > ry1) continue;
            face_mark[at.face] = stamp;
            face_slot[at.face] = static_cast<std::uint32_t>(near.size());
            near.push_back({at.face, en.tri, en.shift});
          }
        }
      const auto n = static_cast<std::uint32_t>(near.size());
      parent.resize(n);
      std::iota(parent.begin(), parent.end(), 0u);
      const auto root = [&](std::uint32_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
      };
      for (std::uint32_t i = 0; i < n; ++i)
        for (std::uint32_t v : mesh.triangles[near[i].face]) {
          if (vertex_mark[v] != stamp) vertex_mark[v] = stamp, vertex_slot[v] = i;
          else parent[root(i)] = root(vertex_slot[v]);
        }
      // The vertex's piece: the faces of the block with the vertex as a corner, and those joined to them.
      const std::uint32_t own_root = vertex_mark[s.vertex] == stamp ? root(vertex_slot[s.vertex]) : kNone;
      bool fine = own_root != kNone;
      for (long dy = -1; dy <= 2 && fine; ++dy)
        for (long dx = -1; dx <= 2 && fine; ++dx) {
          const std::size_t i = texel(dx, dy);
          if (count_at[i] == 0) continue;
          for (const std::uint32_t f : {first_face[i], face_at[i]})
            fine = fine && face_mark[f] == stamp && root(face_slot[f]) == own_root;
        }
      good[smp_of[k]] = covered && fine;
    }
  }
  // Per vertex: its samples [first[v], first[v + 1]), and whether it has a good one.
  std::vector<std::uint32_t> first(V + 1, 0);
  for (const VertexSample& s : am.samples) ++first[s.vertex + 1];
  for (std::size_t v = 0; v < V; ++v) first[v + 1] += first[v];
  std::vector<std::uint8_t> has(V, 0);
  for (std::size_t i = 0; i < am.samples.size(); ++i) has[am.samples[i].vertex] |= good[i];
  std::vector<VertexSample> out;
  out.reserve(am.samples.size());
  std::size_t& borrowed = check.borrowed;
  std::vector<std::uint32_t> ring, next, seen, lenders;
  std::vector<std::uint8_t> mark(V, 0);
  for (std::uint32_t v = 0; v < V; ++v) {
    for (std::uint32_t i = first[v]; i < first[v + 1]; ++i) dropped_own += am.samples[i].chart == am.vertex_chart[v] && !good[i];
    if (has[v]) {
      for (std::uint32_t i = first[v]; i < first[v + 1]; ++i)
        if (good[i]) out.push_back(am.samples[i]);
      continue;
    }
    // Breadth first by edges to the first ring with a vertex that reads well.
    ring = {v};
    seen = {v};
    mark[v] = 1;
    lenders.clear();
    for (int r = 0; r < kBorrowRings && lenders.empty() && !ring.empty(); ++r) {
      next.clear();
      for (std::uint32_t a : ring)
        for (std::uint32_t k = adj_start[a]; k < adj_start[a + 1]; ++k) {
          const std::uint32_t b = adj[k];
          if (mark[b]) continue;
          mark[b] = 1;
          seen.push_back(b);
          next.push_back(b);
          if (has[b]) lenders.push_back(b);
        }
      ring.swap(next);
    }
    for (std::uint32_t a : seen) mark[a] = 0;
    if (lenders.empty()) {  // nothing near reads well: its own reads, as they are
      for (std::uint32_t i = first[v]; i < first[v + 1]; ++i) out.push_back(am.samples[i]);
      continue;
    }
    ++borrowed;
    std::sort(lenders.begin(), lenders.end());
    for (std::uint32_t a : lenders) {
      double sum = 0;
      for (std::uint32_t i = first[a]; i < first[a + 1]; ++i)
        if (good[i]) sum += am.samples[i].weight;
      for (std::uint32_t i = first[a]; i < first[a + 1]; ++i)
        if (good[i]) {
          VertexSample s = am.samples[i];
          s.vertex = v;
          s.weight = static_cast<float>(s.weight / sum / static_cast<double>(lenders.size()));
          out.push_back(s);
        }
    }
  }
  am.samples = std::move(out);
  return check;
}


}  // namespace sdfkit::diffusion
