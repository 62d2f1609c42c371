#version 450
// Atlas blur, stretch-compensated (texture-space diffusion's "stretch maps"): one box filter of
// the Gaussian's cascade along one axis per dispatch, like atlas_blur_box.comp, but the box's
// width is chosen per output texel from the local metric of the chart's map there: the raster
// pass turned each triangle's model units per texel m along x and y into the box half-widths
// h = f + a there (stretch_half_width in atlas_common.glsl: a third of variance / m² less the
// bilinear read-back's 1/6 texel² per box, fractional ends so the width changes smoothly), -1
// where no triangle drew (then the chart's mean scale's). So the blur is one width in model units
// wherever the chart's map stretches or shrinks the surface (a bone chart's angle direction
// scales with the radius around the bone, planar and cap charts stretch towards their rims),
// instead of one width in texels per chart. The three boxes share the widths.
//
// One invocation per job = one row (axis 0) or column (axis 1) of one chart, in two walks: the
// line's prefix sums S (compensated summation, so each is the sum rounded once) into the prefix
// buffer, then per texel S(i + f) - S(i - f - 1) plus a times the two texels just outside: a fixed
// number of reads per texel whatever the widths and however they jump from texel to texel (a
// window walked with moving ends costs the jumps, which grow with the radius: every triangle
// border in a chart carries a different stretch). Each S is kept as two floats, the compensated
// sum and its compensation (hi + lo), and a window is (hi_b - hi_a) + (lo_b - lo_a): a plain float
// prefix would lose about n · 2^-24 of the line's total in every window's sum (a constant 2.5
// through the camel's atlas read back 1e-5 off), this the window's own rounding. Both channels
// (value · coverage, coverage) are blurred; outside the chart's rectangle there are zeros (rows of
// a wrapping chart wrap instead, the window never wider than the row, S continued by the row's
// total per period), so nothing enters from another chart or the gutter.
#extension GL_GOOGLE_include_directive : require
#include "atlas_common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Jobs { uvec2 jobs[]; };  // chart, line within the chart
layout(std430, binding = 1) readonly buffer Charts { Chart charts[]; };
layout(std430, binding = 2) readonly buffer Src { vec2 src[]; };
layout(std430, binding = 3) writeonly buffer Dst { vec2 dst[]; };
layout(std430, binding = 4) readonly buffer HalfWidths { vec2 half_widths[]; };  // row-major, along x, y; -1: none drawn
layout(std430, binding = 5) buffer Prefix { vec4 prefix[]; };  // tiled like dst: the line's prefix sums, (hi, lo)

layout(push_constant) uniform Push {
  uint job_offset;
  uint job_count;
  uint size;   // atlas side, texels
  uint axis;   // 0: along x (rows), 1: along y (columns)
  uint box;    // which box of the cascade (all three have the same width law)
  uint src_tiled;  // 0: the source is the row-major raster copy (the first pass)
  float variance;  // the Gaussian's variance per axis left for the blur, model units²
} pc;

uvec2 g_origin;  // the line's first texel
uvec2 g_step;    // (1, 0) along a row, (0, 1) along a column
int g_n;
bool g_wrap;
vec4 g_total;     // the line's sum, (hi, lo) (S continues by it per period of a wrapping row)
float g_fallback;  // the half-width at the chart's mean scale, where no triangle drew one
int g_cap;        // the largest integer half-width: the line (a wrapping row: half of it)

uint src_index(uvec2 p) { return pc.src_tiled != 0u ? tiled_index(p.x, p.y, pc.size) : p.y * pc.size + p.x; }

// Texel k of the line: rows of wrapping charts wrap (the window and its fractional ends stay
// within one period of the line, so one shift suffices), elsewhere zeros outside.
vec2 fetch(int k) {
  if (g_wrap) {
    k = k < 0 ? k + g_n : (k >= g_n ? k - g_n : k);
  } else if (k < 0 || k >= g_n) {
    return vec2(0.0);
  }
  return src[src_index(g_origin + uint(k) * g_step)];
}

// S(k) as (hi, lo): the sum of the line's texels up to k; zeros outside a plain line, a wrapping
// row continued periodically (k within one period either side: the window never wider than the
// row).
vec4 prefix_sum(int k) {
  vec4 shift = vec4(0.0);
  if (g_wrap) {
    if (k < 0) {
      k += g_n;
      shift = -g_total;
    } else if (k >= g_n) {
      k -= g_n;
      shift = g_total;
    }
  } else {
    if (k < 0) return vec4(0.0);
    k = min(k, g_n - 1);
  }
  const uvec2 o = g_origin + uint(k) * g_step;
  return prefix[tiled_index(o.x, o.y, pc.size)] + shift;
}

// The box's half-width at texel i of the line: (f, a).
void half_width(int i, out int f, out float a) {
  const uvec2 p = g_origin + uint(i) * g_step;
  float h = half_widths[p.y * pc.size + p.x][pc.axis];
  if (h < 0.0) h = g_fallback;
  f = int(h);
  a = h - float(f);
  // A wrapping row: the window and its fractional ends stay within one period.
  if (f >= g_cap || (g_wrap && f + 1 > g_cap && a > 0.0)) {
    f = min(f, g_cap);
    a = 0.0;
  }
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
  g_fallback = max(stretch_half_width(c.metric.x, pc.variance), 0.0);
  g_cap = g_wrap ? (g_n - 1) / 2 : g_n;
  // Walk 1: S(k) = sum of the line's texels 0..k, compensated: sum - comp is the exact sum to
  // second order, stored as (sum, -comp).
  // `precise`: the compiler must not simplify (t - sum) - y to 0.
  precise vec2 sum = vec2(0.0), comp = vec2(0.0);
  for (int k = 0; k < g_n; ++k) {
    precise const vec2 y = src[src_index(g_origin + uint(k) * g_step)] - comp;
    precise const vec2 t = sum + y;
    comp = (t - sum) - y;
    sum = t;
    const uvec2 o = g_origin + uint(k) * g_step;
    prefix[tiled_index(o.x, o.y, pc.size)] = vec4(sum, -comp);
  }
  g_total = vec4(sum, -comp);
  // Walk 2: each texel's box from two prefix sums and the two fractional end texels.
  for (int i = 0; i < g_n; ++i) {
    int f;
    float a;
    half_width(i, f, a);
    precise const vec4 d = prefix_sum(i + f) - prefix_sum(i - f - 1);
    precise const vec2 window = d.xy + d.zw;
    const uvec2 p = g_origin + uint(i) * g_step;
    dst[tiled_index(p.x, p.y, pc.size)] = (window + a * (fetch(i - f - 1) + fetch(i + f + 1))) / (2.0 * float(f) + 1.0 + 2.0 * a);
  }
}
