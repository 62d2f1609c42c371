// sdfkit OpenCL kernels, part 2: tracing rays through the octree (engine's octree.hpp layout).
//
// Nodes: uint2 (first, mask); mask bit 31 = leaf, then mask & 0x7fffffff triangle records from
// record first; else bits 0..7 name the stored octants, child k at first + popcount(mask below
// k). Cells: float4 (min corner xyz, side w). Triangle records, in leaf order (a triangle in
// several leaves has a record in each, so a leaf's triangles are contiguous in memory): three
// float4 (v0, e1 = v1 - v0, e2 = v2 - v0) whose w components hold the outward unit normal.
//
// No contraction of a*b+c into fma anywhere in tracing: the triangle test must round the same
// way for the two triangles of a shared edge, or a ray through the edge slips between both
// (on NVIDIA's OpenCL, whose compiler contracts where allowed and whose dot() and cross() may
// fuse whatever the pragma says, rays through the edges of an axis-aligned face were lost), and
// the octree's cell planes must round the same from parent and child. The triangle test below
// writes its products out instead of calling dot() and cross() for the same reason.
#pragma OPENCL FP_CONTRACT OFF
//
// Traversal (after Laine & Karras 2010): the ray's octant mask mirrors the child order, so
// visiting octants j ^ mask for j = 0..7 is front to back for any ray; each internal node pushes
// the children its t-interval enters (slab tests against the parent's mid planes) in reverse,
// and the walk stops as soon as the next node starts beyond the closest hit found so far.

#define LEAF_BIT 0x80000000u

// Exact ties (a ray through an edge or vertex shared by triangles hit at the same t) go to the
// lexicographically smallest outward normal, whatever order the tree visits them in: the result
// of a ray is its distance and hit normal, so it does not depend on the tree's shape (a refit
// tree and a fresh build agree) and equal normals tie harmlessly.
inline bool sdfkit_normal_before(float3 a, float3 b) {
  return a.x < b.x || (a.x == b.x && (a.y < b.y || (a.y == b.y && a.z < b.z)));
}

inline float3 sdfkit_record_normal(__global const float4* tris, uint f) {
  return (float3)(tris[3 * f].w, tris[3 * f + 1].w, tris[3 * f + 2].w);
}

// Moller-Trumbore: updates (*best_t, *best_f) when record f is hit at 0 < t < *best_t, or at
// t == *best_t with a normal before the best's (sdfkit_normal_before).
inline void hit_triangle(__global const float4* tris, uint f, float3 o, float3 d,
                         float* best_t, uint* best_f) {
  const float3 v0 = tris[3 * f].xyz, e1 = tris[3 * f + 1].xyz, e2 = tris[3 * f + 2].xyz;
  // cross(d, e2), dot(e1, pv) ... written out, in the bundle test's order (trace_bundles).
  const float px = d.y * e2.z - d.z * e2.y, py = d.z * e2.x - d.x * e2.z, pz = d.x * e2.y - d.y * e2.x;
  const float det = e1.x * px + e1.y * py + e1.z * pz;
  if (det == 0.0f) return;
  const float inv_det = 1.0f / det;
  const float tx = o.x - v0.x, ty = o.y - v0.y, tz = o.z - v0.z;
  const float u = (tx * px + ty * py + tz * pz) * inv_det;
  if (u < 0.0f || u > 1.0f) return;
  const float qx = ty * e1.z - tz * e1.y, qy = tz * e1.x - tx * e1.z, qz = tx * e1.y - ty * e1.x;
  const float v = (d.x * qx + d.y * qy + d.z * qz) * inv_det;
  if (v < 0.0f || u + v > 1.0f) return;
  const float t = (e2.x * qx + e2.y * qy + e2.z * qz) * inv_det;
  if (t > 0.0f && (t < *best_t || (t == *best_t && *best_f != 0xffffffffu &&
                                   sdfkit_normal_before(sdfkit_record_normal(tris, f),
                                                        sdfkit_record_normal(tris, *best_f))))) {
    *best_t = t;
    *best_f = f;
  }
}

// Closest hit of the ray o + t d (t > 0): returns the triangle record or 0xffffffff, and t.
inline uint closest_hit(__global const uint2* nodes, __global const float4* cells,
                        __global const float4* tris, float3 o, float3 d, float* t_out) {
  const float tiny = 1e-20f;
  const float3 dd = (float3)(fabs(d.x) < tiny ? copysign(tiny, d.x) : d.x,
                             fabs(d.y) < tiny ? copysign(tiny, d.y) : d.y,
                             fabs(d.z) < tiny ? copysign(tiny, d.z) : d.z);
  const float3 inv = 1.0f / dd;
  // From dd, not d: a -0.0 component has become -1e-20, and the octant must agree with inv.
  const uint octant = (dd.x < 0.0f ? 1u : 0u) | (dd.y < 0.0f ? 2u : 0u) | (dd.z < 0.0f ? 4u : 0u);
  // Per axis, which side of a cell the ray enters through (0 = low plane, 1 = high plane).
  const float3 enter_side = (float3)(octant & 1u ? 1.0f : 0.0f, octant & 2u ? 1.0f : 0.0f,
                                     octant & 4u ? 1.0f : 0.0f);

  float best_t = INFINITY;
  uint best_f = 0xffffffffu;

  uint stack_node[STACK_SIZE];
  float stack_t[STACK_SIZE];
  int sp = 0;
  {
    const float4 c = cells[0];
    const float3 t0 = (c.xyz + enter_side * c.w - o) * inv;
    const float3 t1 = (c.xyz + (1.0f - enter_side) * c.w - o) * inv;
    const float tin = max(max(max(t0.x, t0.y), t0.z), 0.0f);
    const float tout = min(min(t1.x, t1.y), t1.z);
    if (tin <= tout) {
      stack_node[0] = 0;
      stack_t[0] = tin;
      sp = 1;
    }
  }
  while (sp > 0) {
    --sp;
    if (stack_t[sp] >= best_t) break;  // everything left starts beyond the closest hit
    const uint node = stack_node[sp];
    const uint2 nd = nodes[node];
    if (nd.y & LEAF_BIT) {
      const uint end = nd.x + (nd.y & ~LEAF_BIT);
      for (uint k = nd.x; k < end; ++k) hit_triangle(tris, k, o, d, &best_t, &best_f);
      continue;
    }
    const float4 c = cells[node];
    const float half_side = 0.5f * c.w;
    const float3 t0 = (c.xyz + enter_side * c.w - o) * inv;
    const float3 tm = (c.xyz + half_side - o) * inv;
    const float3 t1 = (c.xyz + (1.0f - enter_side) * c.w - o) * inv;
    // j: octant in the mirrored frame (bit set = the far half along that axis).
    for (int j = 7; j >= 0; --j) {
      const uint k = (uint)j ^ octant;
      if (!(nd.y & (1u << k))) continue;
      const float ex = (j & 1) ? tm.x : t0.x, ey = (j & 2) ? tm.y : t0.y,
                  ez = (j & 4) ? tm.z : t0.z;
      const float xx = (j & 1) ? t1.x : tm.x, xy = (j & 2) ? t1.y : tm.y,
                  xz = (j & 4) ? t1.z : tm.z;
      const float tin = max(max(max(ex, ey), ez), 0.0f);
      const float tout = min(min(min(xx, xy), xz), best_t);
      if (tin > tout || sp >= STACK_SIZE) continue;
      stack_node[sp] = nd.x + popcount(nd.y & ((1u << k) - 1u));
      stack_t[sp] = tin;
      ++sp;
    }
  }
  *t_out = best_t;
  return best_f;
}

// BVH (SDFKIT_BVH): nodes are two float4, (min xyz, word) and (max xyz, count word). Internal:
// the first child is the next node, the word names the second; leaf: count word = LEAF_BIT | n,
// word = first triangle record. Children are visited nearer first; the walk pops only nodes
// that start before the closest hit so far.
#ifndef BVH_STACK_SIZE
#define BVH_STACK_SIZE 96
#endif

// Slab test of a box against the ray within [0, t_max]: entry distance, or -1 on a miss.
inline float box_entry(float4 lo, float4 hi, float3 o, float3 inv, float t_max) {
  // min/max, not fmin/fmax: no NaN can occur (inv is finite, boxes are finite), and the
  // plain forms skip fmin's NaN handling in the hottest loop (1.5x faster on PoCL).
  const float3 t0 = (lo.xyz - o) * inv, t1 = (hi.xyz - o) * inv;
  const float3 tn = min(t0, t1), tf = max(t0, t1);
  const float tin = max(max(max(tn.x, tn.y), tn.z), 0.0f);
  const float tout = min(min(min(tf.x, tf.y), tf.z), t_max);
  return tin <= tout ? tin : -1.0f;
}

inline uint closest_hit_bvh(__global const float4* bvh, __global const float4* tris, float3 o,
                            float3 d, float* t_out) {
  const float tiny = 1e-20f;
  const float3 dd = (float3)(fabs(d.x) < tiny ? copysign(tiny, d.x) : d.x,
                             fabs(d.y) < tiny ? copysign(tiny, d.y) : d.y,
                             fabs(d.z) < tiny ? copysign(tiny, d.z) : d.z);
  const float3 inv = 1.0f / dd;
  float best_t = INFINITY;
  uint best_f = 0xffffffffu;
  *t_out = best_t;
  if (box_entry(bvh[0], bvh[1], o, inv, best_t) < 0.0f) return best_f;
  uint stack_node[BVH_STACK_SIZE];
  float stack_t[BVH_STACK_SIZE];
  int sp = 0;
  uint node = 0;
  for (;;) {
    const float4 lo = bvh[2 * node], hi = bvh[2 * node + 1];
    const uint word = as_uint(lo.w), count = as_uint(hi.w);
    bool descend = false;
    if (count & LEAF_BIT) {
      const uint end = word + (count & ~LEAF_BIT);
      for (uint k = word; k < end; ++k) hit_triangle(tris, k, o, d, &best_t, &best_f);
    } else {
      const uint a = node + 1, b = word;
      const float ta = box_entry(bvh[2 * a], bvh[2 * a + 1], o, inv, best_t);
      const float tb = box_entry(bvh[2 * b], bvh[2 * b + 1], o, inv, best_t);
      if (ta >= 0.0f && tb >= 0.0f) {
        const bool a_first = ta <= tb;
        node = a_first ? a : b;
        if (sp < BVH_STACK_SIZE) {
          stack_node[sp] = a_first ? b : a;
          stack_t[sp] = a_first ? tb : ta;
          ++sp;
        }
        descend = true;
      } else if (ta >= 0.0f) {
        node = a;
        descend = true;
      } else if (tb >= 0.0f) {
        node = b;
        descend = true;
      }
    }
    if (descend) continue;
    // Pop the nearest pending node that still starts before the closest hit.
    for (;;) {
      if (sp == 0) {
        *t_out = best_t;
        return best_f;
      }
      --sp;
      if (stack_t[sp] < best_t) {
        node = stack_node[sp];
        break;
      }
    }
  }
}

// One work item per ray, point-major (the rays of a point in neighbouring work items).
// Octree: nodes + cells; BVH (SDFKIT_BVH): cells holds the BVH's float4 pairs, nodes is unused.
// points: xyz = surface point, w = 1 when the point casts rays; normals: xyz = outward unit
// normal. Writes keys[g] = (bits of the accepted length << 32) | ray index, or NO_HIT_KEY.
__kernel void trace_rays(__global const uint2* nodes, __global const float4* cells,
                         __global const float4* tris, __global const float4* points, __global const float4* normals,
                         __global const float4* table, int n_rays, uint n_points,
                         float origin_offset, int rule, __global ulong* keys) {
  const uint g = get_global_id(0);
  if (g >= n_points * (uint)n_rays) return;
  const uint p = g / (uint)n_rays, r = g - p * (uint)n_rays;
  const float4 pt = points[p];
  ulong key = NO_HIT_KEY;
  if (pt.w != 0.0f) {
    const float3 n = normals[p].xyz;
    const float3 d = ray_direction(n, table[r].xyz);
    const float3 o = pt.xyz - origin_offset * n;
    float t;
#ifdef SDFKIT_BVH
    const uint f = closest_hit_bvh(cells, tris, o, d, &t);
#else
    const uint f = closest_hit(nodes, cells, tris, o, d, &t);
#endif
    if (f != 0xffffffffu) {
      const float3 hn = (float3)(tris[3 * f].w, tris[3 * f + 1].w, tris[3 * f + 2].w);
      if (sdfkit_accept_hit((uint)rule, n, d, hn)) key = ((ulong)as_uint(t) << 32) | (ulong)r;
    }
  }
  keys[g] = key;
}

#ifdef SDFKIT_BVH
// Bundles: one work item traces ray r of BUNDLE consecutive points (the host sorts the points
// in Morton order, so these are neighbours on the surface) as float8 lanes, so a CPU device
// runs each box and triangle test for all of them in one SIMD instruction stream: nearly
// parallel rays from nearby origins, every lane busy whatever the ray count. Lanes past the
// last point or of points that cast no rays are inactive (best distance -1: nothing can be
// entered or hit). A node is entered when any active ray enters it; pending nodes keep the
// smallest entry distance of their rays and are dropped once every ray has a closer hit.
// Eight lanes, not sixteen: the far-side hits of sixteen neighbours' rays spread over many
// leaves (on armadillo subdivided to 3.3M and 13.3M triangles, a visited leaf was entered by
// 1.7-1.8 of 16 lanes), so half-width bundles visit far fewer nodes per ray, and a float8
// operation costs half a float16 one on the 2-core EPYC (Zen 4 runs 512-bit operations as two
// 256-bit halves). Measured in bench/RESULTS.md.
#define BUNDLE SDFKIT_BUNDLE_WIDTH  // from the host (opencl_backend.cpp's kBundle)
#if BUNDLE != 8
#error "trace_bundles is written for bundles of 8 (float8)"
#endif
// The bundle's triangle test rounds like the scalar one (hit_triangle) and the C++ definition's
// tests: the same products in the same order, no contraction (the pragma at the top).

// (min over a's lanes, min over b's lanes), folded pairwise. Also the "does any lane enter"
// test (a minimum below INFINITY): any() over a vector comparison compiled to a lane-by-lane
// chain on PoCL 3.1 / LLVM 15 and made the traversal 30 % slower.
inline float2 pair_min(float8 a, float8 b) {
  const float8 m8 = min((float8)(a.lo, b.lo), (float8)(a.hi, b.hi));
  const float4 m4 = min(m8.s0145, m8.s2367);
  return (float2)(min(m4.x, m4.y), min(m4.z, m4.w));
}

inline float lane_max(float8 t) {
  const float4 m4 = max(t.lo, t.hi);
  return max(max(m4.x, m4.y), max(m4.z, m4.w));
}

// The 4-wide BVH the bundles walk (built on the host from the binary BVH, opencl_backend.cpp's
// WideNode): a node is eight float4, the four children's boxes as min x, min y, min z, max x,
// max y, max z (one float per child), then the children's words and count words as uint4. A
// child is an inner node (count word 0, word = its wide node) or a leaf (count word LEAF_BIT |
// n, word = first triangle record); an unused slot is a leaf without triangles. The root is
// wide node 0. Four children per node: the loads of a node are two neighbouring cache lines
// issued together, instead of two binary levels loaded one after the other (the traversal
// waits on memory: the two hottest instructions of a perf profile of the binary traversal were
// the first uses of a far child's box and of a leaf's first triangle).

// A hint to the cache (clang's __builtin_prefetch, a prefetch instruction on CPUs; the host
// defines SDFKIT_PREFETCH for CPU devices only) for what visiting a pushed child reads first:
// an inner node's two cache lines, a leaf's first triangle records.
inline void sdfkit_prefetch_child(__global const float4* wide, __global const float4* tris,
                                  uint word, uint count) {
#if defined(__clang__) && defined(SDFKIT_PREFETCH)
  if (count & LEAF_BIT) {
    __builtin_prefetch(tris + 3 * word);
    __builtin_prefetch(tris + 3 * word + 4);
  } else {
    __builtin_prefetch(wide + 8 * word);
    __builtin_prefetch(wide + 8 * word + 4);
  }
#endif
}

// Per ray of a bundle (origins per lane), the entry distance into the box (lo, hi) or INFINITY.
inline float8 bundle_entry(float lx, float ly, float lz, float hx, float hy, float hz,
                           float8 ox, float8 oy, float8 oz, float8 ix, float8 iy, float8 iz,
                           float8 best_t) {
  const float8 ax = (lx - ox) * ix, bx = (hx - ox) * ix;
  const float8 ay = (ly - oy) * iy, by = (hy - oy) * iy;
  const float8 az = (lz - oz) * iz, bz = (hz - oz) * iz;
  const float8 tin = max(max(max(min(ax, bx), min(ay, by)), min(az, bz)), (float8)0.0f);
  const float8 tout = min(min(min(max(ax, bx), max(ay, by)), max(az, bz)), best_t);
  return select((float8)INFINITY, tin, tin <= tout);
}

// Orders (ta, ia) and (tb, ib) so that ta <= tb (a comparator of a sorting network).
#define SDFKIT_ORDER(ta, ia, tb, ib)             \
  {                                              \
    const bool swap = tb < ta;                   \
    const float t_lo = swap ? tb : ta;           \
    tb = swap ? ta : tb;                         \
    ta = t_lo;                                   \
    const uint i_lo = swap ? ib : ia;            \
    ib = swap ? ia : ib;                         \
    ia = i_lo;                                   \
  }

// The traversal state of one bundle: its rays (origins, directions, inverse directions per
// lane), per lane the closest hit so far (distance, record; an inactive lane has distance -1),
// the node to visit next and the pending nodes.
// A wide node pushes at most three children and the binary tree is under 72 levels deep (bvh.hpp),
// so the wide walk's stack never holds more than 3 * 71 + 1 entries.
#define WIDE_STACK_SIZE 216
typedef struct {
  float8 ox, oy, oz, dx, dy, dz, ix, iy, iz, best_t;
  uint8 best_f;
  uint word, count;  // the node to visit next
  int sp;
  uint stack_word[WIDE_STACK_SIZE], stack_count[WIDE_STACK_SIZE];
  float stack_t[WIDE_STACK_SIZE];
} sdfkit_bundle;

// Starts the walk of the rays o + t d (t > 0) of the active lanes at the root.
__attribute__((always_inline)) inline void bundle_start(sdfkit_bundle* b, float8 ox, float8 oy,
                                                        float8 oz, float8 dx, float8 dy,
                                                        float8 dz, int8 active) {
  const float tiny = 1e-20f;
  b->ox = ox;
  b->oy = oy;
  b->oz = oz;
  b->dx = dx;
  b->dy = dy;
  b->dz = dz;
  b->ix = 1.0f / select(dx, copysign((float8)tiny, dx), fabs(dx) < tiny);
  b->iy = 1.0f / select(dy, copysign((float8)tiny, dy), fabs(dy) < tiny);
  b->iz = 1.0f / select(dz, copysign((float8)tiny, dz), fabs(dz) < tiny);
  b->best_t = select((float8)(-1.0f), (float8)INFINITY, active);
  b->best_f = (uint8)0xffffffffu;
  b->word = 0;  // the root, an inner node
  b->count = 0;
  b->sp = 0;
}

// One step of the closest-hit walk: visits the node b->word / b->count and chooses the next.
// At an inner node all four children are tested; the entered ones (by any lane) are visited
// nearest first (by their smallest entry distance), the others wait on the stack. Returns false
// when no node is left (b->best_f / b->best_t are then the closest hits, 0xffffffff = none).
// The node chosen next is prefetched, so a caller that interleaves two bundles' steps (see
// trace_bundles) has its load under way while the other bundle's step runs.
__attribute__((always_inline)) inline bool bundle_step(__global const float4* wide,
                                                       __global const float4* tris,
                                                       sdfkit_bundle* b) {
  const float8 ox = b->ox, oy = b->oy, oz = b->oz, dx = b->dx, dy = b->dy, dz = b->dz;
  const uint word = b->word, count = b->count;
  if (count & LEAF_BIT) {
    float8 best_t = b->best_t;
    uint8 best_f = b->best_f;
    const uint end = word + (count & ~LEAF_BIT);
    for (uint k = word; k < end; ++k) {
      const float4 v0 = tris[3 * k], e1 = tris[3 * k + 1], e2 = tris[3 * k + 2];
      const float8 px = dy * e2.z - dz * e2.y, py = dz * e2.x - dx * e2.z,
                   pz = dx * e2.y - dy * e2.x;
      const float8 det = e1.x * px + e1.y * py + e1.z * pz;
      const float8 inv_det = 1.0f / det;
      const float8 tx = ox - v0.x, ty = oy - v0.y, tz = oz - v0.z;
      const float8 u = (tx * px + ty * py + tz * pz) * inv_det;
      const float8 qx = ty * e1.z - tz * e1.y, qy = tz * e1.x - tx * e1.z,
                   qz = tx * e1.y - ty * e1.x;
      const float8 v = (dx * qx + dy * qy + dz * qz) * inv_det;
      const float8 t = (e2.x * qx + e2.y * qy + e2.z * qz) * inv_det;
      const int8 on = (det != 0.0f) & (u >= 0.0f) & (u <= 1.0f) & (v >= 0.0f) &
                      (u + v <= 1.0f) & (t > 0.0f);
      int8 hit = on & (t < best_t);
      // Exact ties, rare: per lane, the smaller normal wins (sdfkit_normal_before).
      const uint8 tie = as_uint8(on & (t == best_t) & (best_f != (uint8)0xffffffffu));
      const uint4 tie4 = tie.lo | tie.hi;
      const uint2 tie2 = tie4.lo | tie4.hi;
      if (tie2.x | tie2.y) {
        const float3 nk = (float3)(v0.w, e1.w, e2.w);
        int hs[BUNDLE];
        uint ties[BUNDLE], bfs[BUNDLE];
        vstore8(hit, 0, hs);
        vstore8(tie, 0, ties);
        vstore8(best_f, 0, bfs);
        for (int l = 0; l < BUNDLE; ++l)
          if (ties[l] && sdfkit_normal_before(nk, sdfkit_record_normal(tris, bfs[l]))) hs[l] = -1;
        hit = vload8(0, hs);
      }
      best_t = select(best_t, t, hit);
      best_f = select(best_f, (uint8)k, as_uint8(hit));
    }
    b->best_t = best_t;
    b->best_f = best_f;
  } else {
    const float8 ix = b->ix, iy = b->iy, iz = b->iz, best_t = b->best_t;
    __global const float4* node = wide + 8 * word;
    const float4 lx = node[0], ly = node[1], lz = node[2], hx = node[3], hy = node[4],
                 hz = node[5];
    const uint4 words = as_uint4(node[6]), counts = as_uint4(node[7]);
    const float8 e0 = bundle_entry(lx.x, ly.x, lz.x, hx.x, hy.x, hz.x, ox, oy, oz, ix, iy, iz, best_t);
    const float8 e1 = bundle_entry(lx.y, ly.y, lz.y, hx.y, hy.y, hz.y, ox, oy, oz, ix, iy, iz, best_t);
    const float8 e2 = bundle_entry(lx.z, ly.z, lz.z, hx.z, hy.z, hz.z, ox, oy, oz, ix, iy, iz, best_t);
    const float8 e3 = bundle_entry(lx.w, ly.w, lz.w, hx.w, hy.w, hz.w, ox, oy, oz, ix, iy, iz, best_t);
    const float2 m01 = pair_min(e0, e1), m23 = pair_min(e2, e3);
    // Nearest entry per child (INFINITY: no lane enters it, or an unused slot).
    float t0 = counts.x == LEAF_BIT ? INFINITY : m01.x, t1 = counts.y == LEAF_BIT ? INFINITY : m01.y;
    float t2 = counts.z == LEAF_BIT ? INFINITY : m23.x, t3 = counts.w == LEAF_BIT ? INFINITY : m23.y;
    uint i0 = 0, i1 = 1, i2 = 2, i3 = 3;
    SDFKIT_ORDER(t0, i0, t1, i1);
    SDFKIT_ORDER(t2, i2, t3, i3);
    SDFKIT_ORDER(t0, i0, t2, i2);
    SDFKIT_ORDER(t1, i1, t3, i3);
    SDFKIT_ORDER(t1, i1, t2, i2);
    if (t0 < INFINITY) {
      const uint ws[4] = {words.x, words.y, words.z, words.w};
      const uint cs[4] = {counts.x, counts.y, counts.z, counts.w};
      int sp = b->sp;
      // Farthest first, so the nearer ones are popped first.
      if (t3 < INFINITY && sp < WIDE_STACK_SIZE) {
        b->stack_word[sp] = ws[i3];
        b->stack_count[sp] = cs[i3];
        b->stack_t[sp++] = t3;
        sdfkit_prefetch_child(wide, tris, ws[i3], cs[i3]);
      }
      if (t2 < INFINITY && sp < WIDE_STACK_SIZE) {
        b->stack_word[sp] = ws[i2];
        b->stack_count[sp] = cs[i2];
        b->stack_t[sp++] = t2;
        sdfkit_prefetch_child(wide, tris, ws[i2], cs[i2]);
      }
      if (t1 < INFINITY && sp < WIDE_STACK_SIZE) {
        b->stack_word[sp] = ws[i1];
        b->stack_count[sp] = cs[i1];
        b->stack_t[sp++] = t1;
        sdfkit_prefetch_child(wide, tris, ws[i1], cs[i1]);
      }
      b->sp = sp;
      b->word = ws[i0];
      b->count = cs[i0];
      sdfkit_prefetch_child(wide, tris, ws[i0], cs[i0]);
      return true;
    }
  }
  // A pending node is kept while some ray may still enter it before its closest hit.
  const float far_t = lane_max(b->best_t);
  for (int sp = b->sp; sp > 0;) {
    --sp;
    if (b->stack_t[sp] <= far_t) {
      b->sp = sp;
      b->word = b->stack_word[sp];
      b->count = b->stack_count[sp];
      sdfkit_prefetch_child(wide, tris, b->word, b->count);
      return true;
    }
  }
  b->sp = 0;
  return false;
}
#undef SDFKIT_ORDER

// Loads ray r of bundle `bundle` (lanes past the last point repeat it, inactive) into b.
__attribute__((always_inline)) inline void bundle_load(sdfkit_bundle* b, __global const float4* points,
                                                       __global const float4* normals,
                                                       float3 cone_dir, uint bundle, uint n_points,
                                                       float origin_offset) {
  const uint first = bundle * BUNDLE, lanes = min((uint)BUNDLE, n_points - first);
  float oxs[BUNDLE], oys[BUNDLE], ozs[BUNDLE], dxs[BUNDLE], dys[BUNDLE], dzs[BUNDLE];
  int act[BUNDLE];
  for (uint l = 0; l < BUNDLE; ++l) {
    const uint p = first + min(l, lanes - 1);
    const float4 pt = points[p];
    const float3 n = normals[p].xyz;
    const float3 d = ray_direction(n, cone_dir);
    const float3 o = pt.xyz - origin_offset * n;
    oxs[l] = o.x; oys[l] = o.y; ozs[l] = o.z;
    dxs[l] = d.x; dys[l] = d.y; dzs[l] = d.z;
    act[l] = (l < lanes && pt.w != 0.0f) ? -1 : 0;
  }
  bundle_start(b, vload8(0, oxs), vload8(0, oys), vload8(0, ozs), vload8(0, dxs), vload8(0, dys),
               vload8(0, dzs), vload8(0, act));
}

// Writes the keys of the walked bundle's lanes like trace_rays (an inactive lane has no hit).
__attribute__((always_inline)) inline void bundle_store(const sdfkit_bundle* b,
                                                        __global const float4* tris,
                                                        __global const float4* normals,
                                                        int n_rays, uint r, uint bundle,
                                                        uint n_points, int rule,
                                                        __global ulong* keys) {
  const uint first = bundle * BUNDLE, lanes = min((uint)BUNDLE, n_points - first);
  uint fs[BUNDLE];
  float ts[BUNDLE], dxs[BUNDLE], dys[BUNDLE], dzs[BUNDLE];
  vstore8(b->best_f, 0, fs);
  vstore8(b->best_t, 0, ts);
  vstore8(b->dx, 0, dxs);
  vstore8(b->dy, 0, dys);
  vstore8(b->dz, 0, dzs);
  for (uint l = 0; l < lanes; ++l) {
    const uint p = first + l;
    ulong key = NO_HIT_KEY;
    const uint f = fs[l];
    if (f != 0xffffffffu) {
      const float3 n = normals[p].xyz;
      const float3 hn = (float3)(tris[3 * f].w, tris[3 * f + 1].w, tris[3 * f + 2].w);
      const float3 d = (float3)(dxs[l], dys[l], dzs[l]);
      if (sdfkit_accept_hit((uint)rule, n, d, hn)) key = ((ulong)as_uint(ts[l]) << 32) | (ulong)r;
    }
    keys[(size_t)p * n_rays + r] = key;
  }
}

// One work item per (bundle, ray), ray-major: neighbouring work items trace the same cone
// direction from neighbouring bundles, so they meet the same nodes and triangles while these
// are in cache (bundle-major order gave neighbouring work items the other rays of one bundle,
// whose hits lie all over the far side). Writes the keys of its lanes like trace_rays.
// SDFKIT_BUNDLES_PER_ITEM (2 or 4 on CPU devices, from the host): a work item walks ray r of
// that many neighbouring bundles, alternating their steps, so the load of the node one bundle
// visits next (prefetched when it is chosen) is under way while the other bundles' nodes are
// tested: a CPU runs a work item as one thread, and the walk otherwise waits on the first load
// of every node it enters. Each bundle visits its nodes in the same order as alone, so its hits
// are the same.
#ifndef SDFKIT_BUNDLES_PER_ITEM
#define SDFKIT_BUNDLES_PER_ITEM 1
#endif
#if SDFKIT_BUNDLES_PER_ITEM != 1 && SDFKIT_BUNDLES_PER_ITEM != 2 && SDFKIT_BUNDLES_PER_ITEM != 4
#error "trace_bundles walks 1, 2 or 4 bundles per work item"
#endif
#define SDFKIT_BUNDLE_START(k)                                                                  \
  sdfkit_bundle s##k;                                                                           \
  const bool has##k = bundle + k < bundles;                                                     \
  bool on##k = has##k;                                                                          \
  if (has##k) bundle_load(&s##k, points, normals, cone_dir, bundle + k, n_points, origin_offset);
#define SDFKIT_BUNDLE_STEP(k) \
  if (on##k) on##k = bundle_step(wide, tris, &s##k);
#define SDFKIT_BUNDLE_END(k) \
  if (has##k) bundle_store(&s##k, tris, normals, n_rays, r, bundle + k, n_points, rule, keys);
__kernel void trace_bundles(__global const float4* wide, __global const float4* tris,
                            __global const float4* points, __global const float4* normals,
                            __global const float4* table, int n_rays, uint n_points,
                            float origin_offset, int rule, __global ulong* keys) {
  const uint per_item = SDFKIT_BUNDLES_PER_ITEM;
  const uint bundles = (n_points + BUNDLE - 1) / BUNDLE;
  const uint items = (bundles + per_item - 1) / per_item;
  const uint g = get_global_id(0);
  if (g >= items * (uint)n_rays) return;
  const uint r = g / items, bundle = (g - r * items) * per_item;
  const float3 cone_dir = table[r].xyz;
#if SDFKIT_BUNDLES_PER_ITEM == 1
  SDFKIT_BUNDLE_START(0)
  while (on0) SDFKIT_BUNDLE_STEP(0)
  SDFKIT_BUNDLE_END(0)
#elif SDFKIT_BUNDLES_PER_ITEM == 2
  SDFKIT_BUNDLE_START(0)
  SDFKIT_BUNDLE_START(1)
  while (on0 || on1) {
    SDFKIT_BUNDLE_STEP(0)
    SDFKIT_BUNDLE_STEP(1)
  }
  SDFKIT_BUNDLE_END(0)
  SDFKIT_BUNDLE_END(1)
#else
  SDFKIT_BUNDLE_START(0)
  SDFKIT_BUNDLE_START(1)
  SDFKIT_BUNDLE_START(2)
  SDFKIT_BUNDLE_START(3)
  while (on0 || on1 || on2 || on3) {
    SDFKIT_BUNDLE_STEP(0)
    SDFKIT_BUNDLE_STEP(1)
    SDFKIT_BUNDLE_STEP(2)
    SDFKIT_BUNDLE_STEP(3)
  }
  SDFKIT_BUNDLE_END(0)
  SDFKIT_BUNDLE_END(1)
  SDFKIT_BUNDLE_END(2)
  SDFKIT_BUNDLE_END(3)
#endif
}
#undef SDFKIT_BUNDLE_START
#undef SDFKIT_BUNDLE_STEP
#undef SDFKIT_BUNDLE_END
#endif

