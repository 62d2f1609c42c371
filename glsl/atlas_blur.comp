#version 450
// Atlas blur: the Gaussian's three box filters along one axis in one dispatch. One invocation
// per job = one row (axis 0) or column (axis 1) of one chart, read once and written once:
// lavapipe turns every storage-buffer access into a per-lane loop, and the one-dispatch-per-box
// cascade (atlas_blur_box.comp) made six such accesses per texel and box where this makes two per
// axis. A line of up to kRing texels is read into private memory and the three boxes run there
// (BOX). A longer line is walked once with three running sums (box 0 over the source, boxes 1 and
// 2 over the previous box's output); what leaves a window (the source texel, box 0's and box 1's
// output 2r + 1 steps back) comes from private ring buffers. Every box sees zeros outside the
// chart's rectangle (the previous box's output is not extended past it), rows of a wrapping chart
// wrap instead, so nothing enters from another chart or the gutter. Both channels (value ·
// coverage, coverage) are blurred (normalized convolution). The sums are the cascade's term for
// term except on streamed wrapping rows, which start their walk r1 + r2 texels early and agree to
// float rounding. plan_blur sends a long line here whenever its radii fit the rings (whatever
// the walk's overrun past the line), so the blur's dispatches do not change with the radius.
#extension GL_GOOGLE_include_directive : require
#include "atlas_common.glsl"

layout(local_size_x = 64) in;

// Lines up to kRing texels run in private memory whatever the radii; longer lines stream, with
// radii at most kRing / 2 - 1 (passes/atlas_passes.hpp kFusedMaxRadius, kShortLine).
const int kRing = 256;

layout(std430, binding = 0) readonly buffer Jobs { uvec2 jobs[]; };  // chart, line within the chart
layout(std430, binding = 1) readonly buffer Charts { Chart charts[]; };
layout(std430, binding = 2) readonly buffer Src { vec2 src[]; };
layout(std430, binding = 3) writeonly buffer Dst { vec2 dst[]; };

layout(push_constant) uniform Push {
  uint job_offset;
  uint job_count;
  uint size;   // atlas side, texels
  uint axis;   // 0: along x (rows), 1: along y (columns)
  uint box;    // unused (0): all three boxes run in this dispatch
  uint src_tiled;  // 0: the source is the row-major raster copy (the first pass)
} pc;

uvec2 g_origin;  // the line's first texel
uvec2 g_step;    // (1, 0) along a row, (0, 1) along a column
int g_n;
bool g_wrap;
int g_period_shift;  // a multiple of g_n that makes every wrapped index of the walk positive

vec2 ring0[kRing];  // the source line, by position mod kRing
vec2 ring1[kRing];  // box 0's output
vec2 ring2[kRing];  // box 1's output

uint src_index(uvec2 p) { return pc.src_tiled != 0u ? tiled_index(p.x, p.y, pc.size) : p.y * pc.size + p.x; }

// Source texel k of the line: rows of wrapping charts wrap (the walk of a wrapping row reaches
// r0 + r1 + r2 texels past either end, possibly more than one period), elsewhere zeros outside.
vec2 fetch(int k) {
  if (g_wrap) {
    k = int(uint(k + g_period_shift) % uint(g_n));
  } else if (k < 0 || k >= g_n) {
    return vec2(0.0);
  }
  return src[src_index(g_origin + uint(k) * g_step)];
}

// One box of radius R over the short line SRC[0, g_n) into DST, as the cascade's pass does it:
// zeros outside a plain line, periodic on a wrapping row (R <= (g_n - 1) / 2 there, plan_blur).
#define BOX(SRC, DST, R, NORM)                                                  \
  {                                                                             \
    vec2 s = vec2(0.0);                                                         \
    if (g_wrap) {                                                               \
      for (int k = -(R); k <= (R); ++k) s += SRC[k < 0 ? k + g_n : k];          \
    } else {                                                                    \
      for (int k = 0; k <= min(R, g_n - 1); ++k) s += SRC[k];                   \
    }                                                                           \
    for (int i = 0; i < g_n; ++i) {                                             \
      DST[i] = s * (NORM);                                                      \
      int a = i + (R) + 1, b = i - (R);                                         \
      vec2 add = vec2(0.0), sub = vec2(0.0);                                    \
      if (g_wrap) {                                                             \
        add = SRC[a >= g_n ? a - g_n : a];                                      \
        sub = SRC[b < 0 ? b + g_n : b];                                         \
      } else {                                                                  \
        if (a < g_n) add = SRC[a];                                              \
        if (b >= 0) sub = SRC[b];                                               \
      }                                                                         \
      s += add - sub;                                                           \
    }                                                                           \
  }

void main() {
  const uint j = gl_GlobalInvocationID.x;
  if (j >= pc.job_count) return;
  const uvec2 job = jobs[pc.job_offset + j];
  const Chart c = charts[job.x];
  const ChartLine line = chart_line(c, job.y, pc.axis);
  g_origin = line.origin;
  g_step = line.step;
  g_n = line.n;
  g_wrap = line.wrap;
  const int r0 = int(c.params.x), r1 = int(c.params.y), r2 = int(c.params.z);
  const float norm0 = 1.0 / float(2 * r0 + 1), norm1 = 1.0 / float(2 * r1 + 1), norm2 = 1.0 / float(2 * r2 + 1);
  g_period_shift = g_n * ((r0 + r1 + r2 + 1) / g_n + 1);
  if (g_n <= kRing) {
    // A short line: read it once into ring0, run the three boxes in private memory (ring0 ->
    // ring1 -> ring2 -> ring0), write it once. No walk past the line, whatever the radii.
    for (int k = 0; k < g_n; ++k) ring0[k] = src[src_index(g_origin + uint(k) * g_step)];
    BOX(ring0, ring1, r0, norm0);
    BOX(ring1, ring2, r1, norm1);
    BOX(ring2, ring0, r2, norm2);
    for (int k = 0; k < g_n; ++k) {
      const uvec2 o = g_origin + uint(k) * g_step;
      dst[tiled_index(o.x, o.y, pc.size)] = ring0[k];
    }
    return;
  }
  const int w1 = 2 * r1 + 1, w2 = 2 * r2 + 1;
  // t: the position of box 0's output; box 1's is p = t - r1, box 2's q = p - r2. A wrapping row
  // starts r1 + r2 early so that boxes 1 and 2 see the periodic continuation; a plain line starts
  // at 0 (box 0's output is zero before it).
  const int start = g_wrap ? -(r1 + r2) : 0;
  const int end = g_n + r1 + r2;  // exclusive
  // Box 1's first output: on a plain line at 0 (box 0 is zero before it), on a wrapping row where
  // its window first lies inside the walk, -r2, which is what box 2 needs for its output at 0.
  const int p_first = g_wrap ? start + r1 : 0;
  vec2 s0 = vec2(0.0), s1 = vec2(0.0), s2 = vec2(0.0);
  for (int k = start - r0; k <= start + r0; ++k) {
    const vec2 x = fetch(k);
    ring0[k & (kRing - 1)] = x;
    s0 += x;
  }
  for (int t = start; t < end; ++t) {
    // Box 0 at t (zero outside a plain line); the texel leaving its window comes from ring0.
    const vec2 y0 = (g_wrap || t < g_n) ? s0 * norm0 : vec2(0.0);
    const vec2 x = fetch(t + r0 + 1);
    s0 += x - ring0[(t - r0) & (kRing - 1)];
    ring0[(t + r0 + 1) & (kRing - 1)] = x;
    // Box 1 at p = t - r1: adds box 0 at t, drops box 0 at t - w1 (zero before the walk).
    const int p = t - r1;
    const vec2 old0 = t - w1 >= start ? ring1[(t - w1) & (kRing - 1)] : vec2(0.0);
    ring1[t & (kRing - 1)] = y0;
    s1 += y0 - old0;
    if (p < p_first) continue;
    const vec2 y1 = (g_wrap || p < g_n) ? s1 * norm1 : vec2(0.0);
    // Box 2 at q = p - r2.
    const int q = p - r2;
    const vec2 old1 = p - w2 >= p_first ? ring2[(p - w2) & (kRing - 1)] : vec2(0.0);
    ring2[p & (kRing - 1)] = y1;
    s2 += y1 - old1;
    if (q < 0) continue;
    const uvec2 o = g_origin + uint(q) * g_step;
    dst[tiled_index(o.x, o.y, pc.size)] = s2 * norm2;
  }
}
