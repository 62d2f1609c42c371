// sdfkit OpenCL kernels, part 3: the gather of sdfkit::gather on the device.
//
#pragma OPENCL FP_CONTRACT OFF

// Each point's n_rays keys (length bits << 32 | ray index; NO_HIT_KEY = dropped) are sorted in
// place, which orders them by length and ties by ray index exactly as the C++ definition does
// (positive floats order like their bit patterns). Then, in float and in sorted order: median =
// element k/2, population sigma, keep |d - median| <= sigma, weighted mean with the table's
// weights (w). Writes value and kept count (0 and 0 when no ray was accepted).
__kernel void gather_points(__global ulong* keys, int n_rays, uint n_points,
                            __global const float4* table, __global float* values,
                            __global uint* kept) {
  const uint p = get_global_id(0);
  if (p >= n_points) return;
  __global ulong* k = keys + (size_t)p * (size_t)n_rays;
  uint count = 0;
  for (int i = 0; i < n_rays; ++i) {
    const ulong key = k[i];
    if (key == NO_HIT_KEY) continue;
    uint j = count++;
    while (j > 0 && k[j - 1] > key) {
      k[j] = k[j - 1];
      --j;
    }
    k[j] = key;
  }
  if (count == 0) {
    values[p] = 0.0f;
    kept[p] = 0;
    return;
  }
  const float median = as_float((uint)(k[count / 2] >> 32));
  float sum = 0.0f;
  for (uint i = 0; i < count; ++i) sum += as_float((uint)(k[i] >> 32));
  const float mean = sum / (float)count;
  float var = 0.0f;
  for (uint i = 0; i < count; ++i) {
    const float dl = as_float((uint)(k[i] >> 32)) - mean;
    var += dl * dl;
  }
  const float sigma = sqrt(var / (float)count);
  float wsum = 0.0f, wdsum = 0.0f;
  uint n_kept = 0;
  for (uint i = 0; i < count; ++i) {
    const float len = as_float((uint)(k[i] >> 32));
    if (fabs(len - median) <= sigma) {
      const float w = table[(uint)(k[i] & 0xffffffffUL)].w;
      wsum += w;
      wdsum += w * len;
      ++n_kept;
    }
  }
  values[p] = wdsum / wsum;
  kept[p] = n_kept;
}
