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
// One invocation per job = one row (axis 0) or column (axis 1) of one chart, walked with a
// running sum over the integer window [lo, hi] whose ends move to i - f and i + f at each texel
// (one read per step of an end, so about two reads per texel however wide the window, as the
// fixed-width cascade), plus the two fractional end texels, kept beside the sum. Both channels
// (value · coverage, coverage) are blurred; outside the chart's rectangle there are zeros (rows of
// a wrapping chart wrap instead, the window never wider than the row), so nothing enters from
// another chart or the gutter.
#extension GL_GOOGLE_include_directive : require
#include "atlas_common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Jobs { uvec2 jobs[]; };  // chart, line within the chart
layout(std430, binding = 1) readonly buffer Charts { Chart charts[]; };
layout(std430, binding = 2) readonly buffer Src { vec2 src[]; };
layout(std430, binding = 3) writeonly buffer Dst { vec2 dst[]; };
layout(std430, binding = 4) readonly buffer HalfWidths { vec2 half_widths[]; };  // row-major, along x, y; -1: none drawn

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
  if (pc.axis == 0u) {
    g_origin = uvec2(c.rect.x, c.rect.y + job.y);
    g_step = uvec2(1u, 0u);
    g_n = int(c.rect.z);
    g_wrap = c.params.w != 0u;
  } else {
    g_origin = uvec2(c.rect.x + job.y, c.rect.y);
    g_step = uvec2(0u, 1u);
    g_n = int(c.rect.w);
    g_wrap = false;
  }
  g_fallback = max(stretch_half_width(c.metric.x, pc.variance), 0.0);
  g_cap = g_wrap ? (g_n - 1) / 2 : g_n;
  // The window [lo, hi], its sum, its end texels (xl, xh) and the texels just outside (xl1 at
  // lo - 1, xh1 at hi + 1): each step of an end reads one texel.
  int f;
  float a;
  half_width(0, f, a);
  int lo = -f, hi = f;
  vec2 s = vec2(0.0);
  for (int k = lo; k <= hi; ++k) s += fetch(k);
  vec2 xl = fetch(lo), xh = fetch(hi), xl1 = fetch(lo - 1), xh1 = fetch(hi + 1);
  for (int i = 0; i < g_n; ++i) {
    if (i > 0) {
      half_width(i, f, a);
      const int want_hi = i + f, want_lo = i - f;
      while (hi < want_hi) {
        s += xh1;
        ++hi;
        xh = xh1;
        xh1 = fetch(hi + 1);
      }
      while (hi > want_hi) {
        s -= xh;
        --hi;
        xh1 = xh;
        xh = fetch(hi);
      }
      while (lo > want_lo) {
        s += xl1;
        --lo;
        xl = xl1;
        xl1 = fetch(lo - 1);
      }
      while (lo < want_lo) {
        s -= xl;
        ++lo;
        xl1 = xl;
        xl = fetch(lo);
      }
    }
    const uvec2 p = g_origin + uint(i) * g_step;
    dst[tiled_index(p.x, p.y, pc.size)] = (s + a * (xl1 + xh1)) / (2.0 * float(f) + 1.0 + 2.0 * a);
  }
}
