#version 450
// Atlas blur, one box per dispatch: the fallback of atlas_blur.comp for box radii beyond its
// ring buffers (passes/atlas_passes.hpp kFusedMaxRadius), six dispatches instead of two.
// One box filter of the Gaussian's cascade along one axis. One invocation per job =
// one row (axis 0) or column (axis 1) of one chart, walked with a running sum: two reads and
// one write per texel whatever the radius, plus the window's warm-up. Both channels (value ·
// coverage, coverage) are blurred; outside the chart's rectangle there are zeros (rows of a
// wrapping chart wrap instead), so nothing enters from another chart or the gutter.
#extension GL_GOOGLE_include_directive : require
#include "atlas_common.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Jobs { uvec2 jobs[]; };  // chart, line within the chart
layout(std430, binding = 1) readonly buffer Charts { Chart charts[]; };
layout(std430, binding = 2) readonly buffer Src { vec2 src[]; };
layout(std430, binding = 3) writeonly buffer Dst { vec2 dst[]; };

layout(push_constant) uniform Push {
  uint job_offset;
  uint job_count;
  uint size;   // atlas side, texels
  uint axis;   // 0: along x (rows), 1: along y (columns)
  uint box;    // which radius of the chart's cascade
  uint src_tiled;  // 0: the source is the row-major raster copy (the first pass)
} pc;

uvec2 g_origin;  // the line's first texel
uvec2 g_step;    // (1, 0) along a row, (0, 1) along a column
int g_n;
bool g_wrap;

uint src_index(uvec2 p) { return pc.src_tiled != 0u ? tiled_index(p.x, p.y, pc.size) : p.y * pc.size + p.x; }

// Texel k of the line: rows of wrapping charts wrap (the radius is below the row's length, see
// plan_blur), elsewhere zeros outside.
vec2 fetch(int k) {
  if (g_wrap) {
    k = k < 0 ? k + g_n : (k >= g_n ? k - g_n : k);
  } else if (k < 0 || k >= g_n) {
    return vec2(0.0);
  }
  return src[src_index(g_origin + uint(k) * g_step)];
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
  const int r = int(c.params[pc.box]);
  const float norm = 1.0 / float(2 * r + 1);
  vec2 sum = vec2(0.0);
  for (int k = -r; k <= r; ++k) sum += fetch(k);
  for (int i = 0; i < g_n; ++i) {
    const uvec2 p = g_origin + uint(i) * g_step;
    dst[tiled_index(p.x, p.y, pc.size)] = sum * norm;
    sum += fetch(i + r + 1) - fetch(i - r);
  }
}
