#include "sdfkit/opencl/opencl_backend.hpp"

#include "cl_api.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/parallel.hpp"
#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/sdf_definition.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <thread>
#include <vector>

namespace sdfkit::cl {

namespace detail {
extern const char* const kProgramSource;  // cl/*.cl, embedded at build time
}

using detail::check;

namespace {

constexpr std::uint64_t kNoHitKey = ~std::uint64_t{0};

const char* const kNoPlatform =
    "no OpenCL platform found; install an OpenCL driver, e.g. Debian packages "
    "ocl-icd-libopencl1 and pocl-opencl-icd (CPU) or your GPU vendor's OpenCL ICD";

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

DeviceInfo to_info(const detail::FoundDevice& d, int index) {
  return DeviceInfo{d.platform_name, d.name, d.vendor, d.version, d.type, d.global_memory, index};
}

std::string describe(const std::vector<detail::FoundDevice>& devices) {
  std::string s;
  for (std::size_t i = 0; i < devices.size(); ++i)
    s += (i ? "; " : "") + std::to_string(i) + ": " + devices[i].name + " (" +
         devices[i].platform_name + ", " + devices[i].type + ")";
  return s;
}

// The device the selector names (see OpenClConfig::device). Throws DeviceError with the list of
// devices when nothing matches.
std::size_t select_device(const std::vector<detail::FoundDevice>& devices, std::string selector) {
  if (devices.empty()) throw DeviceError(kNoPlatform);
  if (selector.empty())
    if (const char* env = std::getenv("SDFKIT_CL_DEVICE")) selector = env;
  if (selector.empty()) {
    for (std::size_t i = 0; i < devices.size(); ++i)
      if (devices[i].type == "GPU") return i;
    return 0;
  }
  const bool numeric = std::all_of(selector.begin(), selector.end(),
                                   [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
  if (numeric) {
    const unsigned long index = std::stoul(selector);
    if (index < devices.size()) return index;
  } else {
    for (std::size_t i = 0; i < devices.size(); ++i)
      if (lower(devices[i].name).find(lower(selector)) != std::string::npos) return i;
  }
  throw DeviceError("no OpenCL device matches \"" + selector + "\" (set by --device or " +
                    "SDFKIT_CL_DEVICE); available devices: " + describe(devices));
}

// OpenCL major.minor from a CL_DEVICE_VERSION string ("OpenCL 3.0 PoCL ..."), as 10*major+minor.
int parse_version(const std::string& v) {
  int major = 0, minor = 0;
  if (std::sscanf(v.c_str(), "OpenCL %d.%d", &major, &minor) != 2) return 0;
  return major * 10 + minor;
}

template <typename T>
void set_arg(cl_kernel kernel, cl_uint index, const T& value, const char* kernel_name) {
  check(clSetKernelArg(kernel, index, sizeof(T), &value),
        std::string("setting argument ") + std::to_string(index) + " of kernel " + kernel_name);
}

template <typename... Args>
void set_args(cl_kernel kernel, const char* kernel_name, const Args&... args) {
  cl_uint i = 0;
  (set_arg(kernel, i++, args, kernel_name), ...);
}

// Work-group size on CPU devices when the configuration leaves it open: PoCL's own choice left
// one of two cores idle at the end of small launches (elephant, 2775 points x 25 rays: 20-23 ms
// of trace and gather against 14-15 ms with 16-64, then with one point's packet per work item).
// A bundle work item traced 16 rays (now 8), so groups of 8: CGAL's hand at 4 rays (the skeleton's
// contraction calls) 1.5 -> 0.8 ms, elephant 3.6 -> 1.9 ms; at 30 rays no change.
constexpr std::size_t kCpuWorkGroup = 8;
// Points per work item of trace_bundles (cl/sdf_trace.cl, given as SDFKIT_BUNDLE_WIDTH).
constexpr std::size_t kBundle = 8;
// Bundles a trace_bundles work item walks on CPU devices, their steps alternated so that one
// bundle's next node loads while the others' are tested (cl/sdf_trace.cl). Level 3 of the huge
// bench, user CPU of the whole process: 4 bundles -11 %, 2 bundles -5 % (bench/RESULTS.md).
constexpr std::size_t kCpuBundlesPerItem = 4;
// Most points per batch on CPU devices, whose buffers are host memory beside the process's own:
// 2^16 points at 30 rays are 17.5 MiB of batch buffers instead of the 512 MiB cap (2^18 and
// 2^17 held 35 and 17.5 MiB more at the 13M-triangle run's peak, which is the trace's), and a
// batch still traces for about half a second on a 2-core CPU at that size, so the launches
// (~100 batches there) cost nothing. A multiple of kBundle: the bundles are the same as in one
// batch.
constexpr std::size_t kCpuBatchPoints = std::size_t{1} << 16;

std::size_t round_up(std::size_t n, std::size_t m) { return m == 0 ? n : (n + m - 1) / m * m; }

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// 30-bit Morton code of a point quantized to 1024 cells per axis of [lo, lo + extent].
std::uint32_t morton3(const glm::vec3& p, const glm::vec3& lo, const glm::vec3& inv_extent) {
  const auto spread = [](std::uint32_t x) {  // bit i of x -> bit 3i
    x &= 0x3ffu;
    x = (x | (x << 16)) & 0x030000ffu;
    x = (x | (x << 8)) & 0x0300f00fu;
    x = (x | (x << 4)) & 0x030c30c3u;
    return (x | (x << 2)) & 0x09249249u;
  };
  const glm::vec3 q = glm::clamp((p - lo) * inv_extent, 0.0f, 1.0f) * 1023.0f;
  return spread(static_cast<std::uint32_t>(q.x)) | (spread(static_cast<std::uint32_t>(q.y)) << 1) |
         (spread(static_cast<std::uint32_t>(q.z)) << 2);
}

// The query's point indices sorted along a Morton curve of their positions (ties by index).
std::vector<std::uint32_t> spatial_order(std::span<const glm::vec3> points) {
  const Aabb box = bounding_box(points);
  const glm::vec3 inv = 1.0f / glm::max(box.extent(), glm::vec3(std::numeric_limits<float>::min()));
  const std::size_t n = points.size();
  std::vector<std::uint64_t> keyed(n);
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) keyed[i] = (std::uint64_t{morton3(points[i], box.min, inv)} << 32) | i;
  }, 1 << 16);
  // The keys are distinct (the index is in them): the halves sorted on two threads and merged
  // give the order of one sort.
  const auto half = keyed.begin() + static_cast<std::ptrdiff_t>(n / 2);
  if (n >= (std::size_t{1} << 16)) {
    std::thread other([&] { std::sort(keyed.begin(), half); });
    std::sort(half, keyed.end());
    other.join();
    std::inplace_merge(keyed.begin(), half, keyed.end());
  } else {
    std::sort(keyed.begin(), keyed.end());
  }
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(keyed[i]);
  return order;
}


// A node of the 4-wide BVH that trace_bundles walks (cl/sdf_trace.cl): the four children's
// boxes, one float per child and coordinate, then per child its word and count word as in
// BvhNode (a leaf: first triangle record and kLeafBit | n; an inner node: its wide node and 0).
// Unused slots are leaves without triangles and empty boxes.
struct WideNode {
  float lo[3][4];
  float hi[3][4];
  std::uint32_t word[4];
  std::uint32_t count[4];
};
static_assert(sizeof(WideNode) == 128);

// One wide node for the binary node `node`: its children are the binary node's children, the
// inner one with the largest surface replaced by its own two children while fewer than four.
// Fills `w` (an inner child's word left 0) and the `n` binary nodes it holds, slot by slot.
void collapse_one(const Bvh& bvh, std::uint32_t node, WideNode& w, std::uint32_t (&kids)[4], int& n) {
  n = 0;
  if (bvh.nodes[node].is_leaf()) {
    kids[n++] = node;  // a root that is a leaf
  } else {
    kids[n++] = node + 1;
    kids[n++] = bvh.nodes[node].first_or_second;
  }
  const auto area = [&](std::uint32_t k) {
    const glm::vec3 e = bvh.nodes[k].max - bvh.nodes[k].min;
    return e.x * e.y + e.y * e.z + e.z * e.x;
  };
  while (n < 4) {
    int widest = -1;
    float widest_area = -1.0f;
    for (int i = 0; i < n; ++i)
      if (!bvh.nodes[kids[i]].is_leaf() && area(kids[i]) > widest_area) {
        widest = i;
        widest_area = area(kids[i]);
      }
    if (widest < 0) break;
    const std::uint32_t k = kids[widest];
    kids[widest] = k + 1;
    kids[n++] = bvh.nodes[k].first_or_second;
  }
  for (int i = 0; i < 4; ++i) {
    for (int a = 0; a < 3; ++a) {
      w.lo[a][i] = std::numeric_limits<float>::infinity();
      w.hi[a][i] = -std::numeric_limits<float>::infinity();
    }
    w.word[i] = 0;
    w.count[i] = BvhNode::kLeafBit;
  }
  for (int i = 0; i < n; ++i) {
    const BvhNode& c = bvh.nodes[kids[i]];
    for (int a = 0; a < 3; ++a) {
      w.lo[a][i] = c.min[a];
      w.hi[a][i] = c.max[a];
    }
    w.word[i] = c.is_leaf() ? c.first_or_second : 0;
    w.count[i] = c.is_leaf() ? c.count : 0;
  }
}

// Collapses the binary subtree under `node` into wide nodes appended to `out` (depth-first, a
// node before its children; indices relative to out's start) and returns its index. The same
// leaves and boxes as the binary tree, so the same triangles are tested for every ray that
// reaches them.
std::uint32_t collapse_wide(const Bvh& bvh, std::uint32_t node, std::vector<WideNode>& out) {
  const auto index = static_cast<std::uint32_t>(out.size());
  out.emplace_back();
  std::uint32_t kids[4];
  int n = 0;
  WideNode w;
  collapse_one(bvh, node, w, kids, n);
  out[index] = w;
  for (int i = 0; i < n; ++i)
    if (!bvh.nodes[kids[i]].is_leaf()) {
      const std::uint32_t child = collapse_wide(bvh, kids[i], out);
      out[index].word[i] = child;
    }
  return index;
}

// collapse_wide(bvh, 0, ...) on all threads (a small tree on the calling one): the wide nodes near the root made
// here, the binary subtrees below them of at most `grain` nodes collapsed as tasks into blocks
// of their own, then placed where the depth-first layout puts them. Size it, then write it.
class WideLayout {
 public:
  explicit WideLayout(const Bvh& bvh) : bvh_(bvh) {
    // Small trees (below 2^16 nodes, ~1 ms) on the calling thread: a thread costs ~0.1 ms.
    threads_ = bvh.nodes.size() < (std::size_t{1} << 16) ? 1u : hardware_threads();
    const unsigned threads = threads_;
    grain_ = std::max<std::size_t>(bvh.nodes.size() / (16 * threads), 1);
    top_.reserve(64);
    make_top(0);
    // Tasks differ in size: each thread takes the next one left.
    std::atomic<std::size_t> next{0};
    parallel_for(tasks_.size(), [&](std::size_t, std::size_t) {
      for (std::size_t k; (k = next++) < tasks_.size();) {
        Task& t = tasks_[k];
        t.nodes.reserve(t.binary_nodes / 2 + 1);  // at most one wide node per inner binary node
        collapse_wide(bvh_, t.node, t.nodes);
      }
    }, 1, threads);
    place(0);
  }
  std::size_t size() const { return size_; }
  // Writes the size() wide nodes to `out`, the blocks on all threads; frees the blocks.
  void write(WideNode* out) {
    for (const Top& t : top_) out[t.at] = t.w;
    std::atomic<std::size_t> next{0};
    parallel_for(tasks_.size(), [&](std::size_t, std::size_t) {
      for (std::size_t k; (k = next++) < tasks_.size();) {
        Task& t = tasks_[k];
        const auto offset = static_cast<std::uint32_t>(t.at);
        WideNode* dst = out + t.at;
        for (std::size_t i = 0; i < t.nodes.size(); ++i) {
          WideNode w = t.nodes[i];
          for (int c = 0; c < 4; ++c)
            if (w.count[c] == 0) w.word[c] += offset;  // an inner child: a wide node of the block
          dst[i] = w;
        }
        t.nodes = std::vector<WideNode>();
      }
    }, 1, threads_);
  }

 private:
  struct Top {
    WideNode w;
    int child[4] = {-1, -1, -1, -1};  // per slot: a Top (>= 0), a task (-2 - task) or none (-1)
    std::size_t at = 0;
  };
  struct Task {
    std::uint32_t node = 0;
    std::size_t binary_nodes = 0;
    std::vector<WideNode> nodes;
    std::size_t at = 0;
  };
  // Nodes of the binary subtree under `node`: it ends after its rightmost leaf.
  std::size_t binary_size(std::uint32_t node) const {
    std::uint32_t k = node;
    while (!bvh_.nodes[k].is_leaf()) k = bvh_.nodes[k].first_or_second;
    return std::size_t{k} + 1 - node;
  }
  int make_top(std::uint32_t node) {
    const int index = static_cast<int>(top_.size());
    top_.emplace_back();
    std::uint32_t kids[4];
    int n = 0;
    WideNode w;
    collapse_one(bvh_, node, w, kids, n);
    top_[static_cast<std::size_t>(index)].w = w;
    for (int i = 0; i < n; ++i) {
      if (bvh_.nodes[kids[i]].is_leaf()) continue;
      const std::size_t size = binary_size(kids[i]);
      int child = 0;
      if (size > grain_) {
        child = make_top(kids[i]);
      } else {
        child = -2 - static_cast<int>(tasks_.size());
        tasks_.push_back(Task{kids[i], size, {}, 0});
      }
      top_[static_cast<std::size_t>(index)].child[i] = child;
    }
    return index;
  }
  // Depth-first positions, as collapse_wide appends them: a node, then each slot's subtree.
  void place(int index) {
    Top& t = top_[static_cast<std::size_t>(index)];
    t.at = size_++;
    for (int i = 0; i < 4; ++i) {
      const int c = t.child[i];
      if (c == -1) continue;
      if (c >= 0) {
        t.w.word[i] = static_cast<std::uint32_t>(size_);
        place(c);
      } else {
        Task& task = tasks_[static_cast<std::size_t>(-2 - c)];
        t.w.word[i] = static_cast<std::uint32_t>(size_);
        task.at = size_;
        size_ += task.nodes.size();
      }
    }
  }
  const Bvh& bvh_;
  unsigned threads_ = 1;
  std::size_t grain_ = 1;
  std::vector<Top> top_;
  std::vector<Task> tasks_;
  std::size_t size_ = 0;
};

// Meshes whose binary BVH has at most this many nodes (16 MiB) keep it on the host beside the
// device's wide copy, for update_positions' refit and bvh(); larger ones rebuild on
// update_positions (the skeleton's contraction, the refit's user, runs on far smaller meshes)
// and do not hold a second tree (13.3M triangles: 6M nodes, 194 MB). The same bound decides
// whether update_positions leaves its upload running (it then keeps the records on the host too).
constexpr std::size_t kKeepBinaryNodes = std::size_t{1} << 19;

}  // namespace

std::vector<DeviceInfo> list_devices() {
  const auto found = detail::enumerate_devices();
  std::vector<DeviceInfo> out;
  for (std::size_t i = 0; i < found.size(); ++i) out.push_back(to_info(found[i], static_cast<int>(i)));
  return out;
}

struct OpenClBackend::Impl {
  OpenClConfig config;
  DeviceInfo info;
  cl_device_id device = nullptr;
  std::size_t max_alloc = 0;
  detail::Context context;
  detail::Queue queue;
  detail::Program program;
  detail::Kernel k_trace, k_bundles, k_gather, k_dirs;
  bool bundles = false;  // BVH traced by trace_bundles, over the 4-wide copy (WideNode)
  std::size_t local_size = 0;  // work-group size of the trace and gather kernels (0 = driver's)
  std::size_t bundles_per_item = 1;  // bundles a trace_bundles work item walks (kCpuBundlesPerItem on CPUs)

  // Geometry (resident between computes). The host keeps no positions (update_positions brings
  // all of them again), only the triangles a rebuild needs: the caller's shared mesh
  // (set_shared_mesh) or a copy of its triangles (set_mesh).
  std::shared_ptr<const Mesh> shape;
  std::size_t vertex_count = 0, face_count = 0;
  bool has_mesh = false;
  Octree octree;
  // Nodes empty between a build and the next refit (see read_back_nodes); with bundles, the
  // device holds the wide copy and the host keeps these nodes for small meshes only.
  Bvh bvh;
  // A deferred upload (update_positions on a mesh whose tree the host keeps) reads these and
  // `bvh.nodes` until the queue is drained: the wide nodes and the triangle records.
  std::vector<WideNode> wide;
  std::vector<glm::vec4> staging;
  bool upload_pending = false;
  std::size_t bvh_node_count = 0;
  double built_sah = 0.0;  // sah_cost of the last full build
  bool refitted = false;   // the last geometry update refit the BVH instead of building it
  detail::Buffer nodes, cells, tris;
  std::size_t geometry_bytes = 0;

  // The cone table of the last (rays, cone) and the per-batch buffers.
  detail::Buffer table;
  int table_rays = 0;
  float table_cone = 0.0f;
  detail::Buffer points, normals, keys, values, kept;
  std::size_t batch_bytes = 0;

  double octree_ms = 0.0, upload_ms = 0.0, trace_ms = 0.0;

  // A deferred upload reads host memory of this object: it must end before that memory does.
  ~Impl() {
    if (upload_pending) clFinish(queue.get());
  }
  void create(const OpenClConfig& cfg);
  void build_program();
  detail::Kernel make_kernel(const char* name);
  void rebuild_geometry(const Mesh& mesh, bool positions_moved);
  void set_geometry(const Mesh& mesh, std::shared_ptr<const Mesh> keep);
  // The BVH's nodes live in the device buffer only (no host copy beside it): read back for a
  // refit or for bvh().
  void read_back_nodes();
  void ensure_table(int rays, float cone_degrees);
  void write(cl_mem buffer, std::size_t bytes, const void* data, const char* what);
  // Fills the first `bytes` of `buffer` in place, `fill(mapped)` through a blocking map (no host
  // copy beside the device's); nothing for 0 bytes.
  template <class Fill>
  void write_mapped(cl_mem buffer, std::size_t bytes, const char* what, Fill&& fill) {
    if (bytes == 0) return;
    cl_int err = CL_SUCCESS;
    void* mapped = clEnqueueMapBuffer(queue.get(), buffer, CL_TRUE, CL_MAP_WRITE_INVALIDATE_REGION, 0, bytes, 0,
                                      nullptr, nullptr, &err);
    check(err, std::string("mapping the ") + what + " buffer");
    fill(mapped);
    check(clEnqueueUnmapMemObject(queue.get(), buffer, mapped, 0, nullptr, nullptr),
          std::string("unmapping the ") + what + " buffer");
  }
  void run(cl_kernel kernel, std::size_t items, std::size_t local, const char* name);
  void finish(const char* what) { check(clFinish(queue.get()), what); }
};

void OpenClBackend::Impl::create(const OpenClConfig& cfg) {
  config = cfg;
  if (cfg.memory_cap == 0) throw InputError("the OpenCL memory cap must be positive");
  if (cfg.bvh_leaf_size < 0 || !(cfg.bvh_traversal_cost >= 0.0f) || !std::isfinite(cfg.bvh_traversal_cost))
    throw InputError("the BVH leaf size and traversal cost must be >= 0 (0 = the tracer's default)");
  if (!(cfg.bvh_refit_limit >= 0.0) || !std::isfinite(cfg.bvh_refit_limit))
    throw InputError("the BVH refit limit must be a finite number >= 0");
  if (cfg.bvh_bundles_per_item != 0 && cfg.bvh_bundles_per_item != 1 && cfg.bvh_bundles_per_item != 2 &&
      cfg.bvh_bundles_per_item != 4)
    throw InputError("the BVH bundles per work item must be 1, 2 or 4 (0 = the device's default)");
  const auto devices = detail::enumerate_devices();
  const std::size_t index = select_device(devices, cfg.device);
  const detail::FoundDevice& d = devices[index];
  info = to_info(d, static_cast<int>(index));
  device = d.device;
  if (parse_version(d.version) < 12)
    throw DeviceError("the OpenCL device " + d.name + " reports \"" + d.version +
                      "\"; sdfkit needs OpenCL 1.2 or later");
  cl_ulong alloc = 0;
  check(clGetDeviceInfo(device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof(alloc), &alloc, nullptr),
        "querying the device's largest allocation");
  max_alloc = static_cast<std::size_t>(alloc);

  cl_int status = CL_SUCCESS;
  const cl_context_properties props[] = {
      CL_CONTEXT_PLATFORM, reinterpret_cast<cl_context_properties>(d.platform), 0};
  context = detail::Context(clCreateContext(props, 1, &device, nullptr, nullptr, &status));
  check(status, "creating a context on " + d.name);
  queue = detail::Queue(clCreateCommandQueue(context.get(), device, 0, &status));
  check(status, "creating a command queue on " + d.name);
  build_program();
  k_trace = make_kernel("trace_rays");
  bundles = cfg.accel == Accel::Bvh && cfg.bvh_bundles.value_or(info.type == "CPU");
  local_size = cfg.work_group_size > 0 ? cfg.work_group_size : (info.type == "CPU" ? kCpuWorkGroup : 0);
  if (bundles) k_bundles = make_kernel("trace_bundles");
  k_gather = make_kernel("gather_points");
  k_dirs = make_kernel("ray_directions");
}

void OpenClBackend::Impl::build_program() {
  const char* source = detail::kProgramSource;
  cl_int status = CL_SUCCESS;
  program = detail::Program(clCreateProgramWithSource(context.get(), 1, &source, nullptr, &status));
  check(status, "loading the OpenCL program source");
  // A node pops one entry and pushes at most 8 children: 7 per level plus the root.
  const int stack = 7 * std::max(config.octree_max_depth, 1) + 2;
  std::string options = "-cl-std=CL1.2 -DSTACK_SIZE=" + std::to_string(stack);
  if (config.accel == Accel::Bvh) options += " -DSDFKIT_BVH=1 -DSDFKIT_BUNDLE_WIDTH=" + std::to_string(kBundle);
  // CPU devices: software prefetches in the bundle traversal, kCpuBundlesPerItem bundles per
  // work item (cl/sdf_trace.cl's trace_bundles).
  bundles_per_item = config.bvh_bundles_per_item != 0 ? config.bvh_bundles_per_item
                                                      : (info.type == "CPU" ? kCpuBundlesPerItem : 1);
  if (info.type == "CPU") options += " -DSDFKIT_PREFETCH=1";
  options += " -DSDFKIT_BUNDLES_PER_ITEM=" + std::to_string(bundles_per_item);
  cl_device_fp_config fp = 0;
  check(clGetDeviceInfo(device, CL_DEVICE_SINGLE_FP_CONFIG, sizeof(fp), &fp, nullptr),
        "querying the device's float support");
  // The gather divides and takes a square root like the C++ definition only when both are
  // correctly rounded; devices that cannot do it stay within the spec's few ulps.
  if (fp & CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT) options += " -cl-fp32-correctly-rounded-divide-sqrt";
  status = clBuildProgram(program.get(), 1, &device, options.c_str(), nullptr, nullptr);
  if (status != CL_SUCCESS) {
    std::size_t size = 0;
    clGetProgramBuildInfo(program.get(), device, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size);
    std::string log(size, '\0');
    clGetProgramBuildInfo(program.get(), device, CL_PROGRAM_BUILD_LOG, size, log.data(), nullptr);
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    throw DeviceError("the OpenCL kernels failed to build for " + info.name + " (" +
                      detail::status_name(status) + "); build log:\n" + log);
  }
}

detail::Kernel OpenClBackend::Impl::make_kernel(const char* name) {
  cl_int status = CL_SUCCESS;
  detail::Kernel k(clCreateKernel(program.get(), name, &status));
  check(status, std::string("creating kernel ") + name);
  return k;
}

void OpenClBackend::Impl::write(cl_mem buffer, std::size_t bytes, const void* data,
                                const char* what) {
  if (bytes == 0) return;
  check(clEnqueueWriteBuffer(queue.get(), buffer, CL_FALSE, 0, bytes, data, 0, nullptr, nullptr),
        std::string("uploading ") + what);
}

void OpenClBackend::Impl::run(cl_kernel kernel, std::size_t items, std::size_t local,
                              const char* name) {
  if (items == 0) return;
  const std::size_t global = round_up(items, local);
  check(clEnqueueNDRangeKernel(queue.get(), kernel, 1, nullptr, &global,
                               local ? &local : nullptr, 0, nullptr, nullptr),
        std::string("running kernel ") + name);
}

// Host: builds the octree and the per-face records; device: uploads them into buffers that
// only grow, so moving vertices reuses the allocations.
void OpenClBackend::Impl::rebuild_geometry(const Mesh& mesh, bool positions_moved) {
  // The host copies the last deferred upload reads (BVH nodes, `staging`) are rewritten below.
  if (upload_pending) finish("uploading the moved mesh");
  upload_pending = false;
  auto start = std::chrono::steady_clock::now();
  // The triangle list of the leaves, leaf by leaf (octree: a triangle once per leaf it touches).
  const std::vector<std::uint32_t>* order = nullptr;
  refitted = false;
  if (config.accel == Accel::Bvh) {
    // After update_positions: refit while the tree stays nearly as good as a fresh build (a
    // refused or too costly refit is replaced by the build below).
    if (positions_moved && config.bvh_refit_limit > 0.0) read_back_nodes();
    refitted = positions_moved && config.bvh_refit_limit > 0.0 && !bvh.nodes.empty() &&
               refit_bvh(bvh, mesh) && sah_cost(bvh) <= config.bvh_refit_limit * built_sah;
    if (!refitted) {
      BvhParams params;
      params.leaf_size = config.bvh_leaf_size > 0 ? config.bvh_leaf_size : (bundles ? 16 : 4);
      params.traversal_cost = config.bvh_traversal_cost > 0.0f ? config.bvh_traversal_cost : (bundles ? 3.0f : 1.0f);
      bvh = build_bvh(mesh, params);
      built_sah = sah_cost(bvh);
    }
    order = &bvh.order;
  } else {
    octree = build_octree(mesh, OctreeParams{config.octree_max_depth, config.octree_leaf_size});
    order = &octree.refs;
  }
  octree_ms = ms_since(start);

  // update_positions on a mesh whose tree the host keeps (the skeleton's contraction: small
  // meshes, one update per iteration) keeps the nodes and records on the host and does not wait
  // for their upload; a larger mesh's update uploads and drops them as set_mesh does.
  const bool deferred =
      positions_moved && config.accel == Accel::Bvh && bvh.nodes.size() <= kKeepBinaryNodes;
  start = std::chrono::steady_clock::now();
  const auto bytes_of = [](const auto& v) { return v.size() * sizeof(v[0]); };
  const cl_context ctx = context.get();
  if (config.accel == Accel::Bvh) {
    // The BVH's nodes travel in `cells` (float4 pairs); `nodes` is a placeholder argument.
    nodes.reserve(ctx, 16, CL_MEM_READ_ONLY, "unused octree nodes");
    bvh_node_count = bvh.nodes.size();
    if (bundles) {
      wide.clear();
      WideLayout layout(bvh);
      const std::size_t bytes = layout.size() * sizeof(WideNode);
      cells.reserve(ctx, bytes, CL_MEM_READ_ONLY, "BVH nodes");
      if (deferred) {
        wide.resize(layout.size());
        layout.write(wide.data());
        write(cells.get(), bytes, wide.data(), "BVH nodes");
      } else {
        // set_mesh: written straight into the mapped device buffer (no host copy of the wide
        // nodes beside it).
        write_mapped(cells.get(), bytes, "BVH node",
                     [&](void* mapped) { layout.write(static_cast<WideNode*>(mapped)); });
        finish("uploading the BVH nodes");
        wide = std::vector<WideNode>();
        if (bvh.nodes.size() > kKeepBinaryNodes) bvh.nodes = std::vector<BvhNode>();
      }
    } else {
      cells.reserve(ctx, bytes_of(bvh.nodes), CL_MEM_READ_ONLY, "BVH nodes");
      write(cells.get(), bytes_of(bvh.nodes), bvh.nodes.data(), "BVH nodes");
      if (!deferred) {
        // The device has the nodes: the host copy goes before the triangle records are mapped
        // (read_back_nodes brings it back for a refit).
        finish("uploading the BVH nodes");
        bvh.nodes = std::vector<BvhNode>();
      }
    }
  } else {
    nodes.reserve(ctx, bytes_of(octree.nodes), CL_MEM_READ_ONLY, "octree nodes");
    cells.reserve(ctx, bytes_of(octree.cells), CL_MEM_READ_ONLY, "octree cells");
    write(nodes.get(), bytes_of(octree.nodes), octree.nodes.data(), "octree nodes");
    write(cells.get(), bytes_of(octree.cells), octree.cells.data(), "octree cells");
  }
  // One record per leaf reference, in leaf order: v0, e1, e2 with the normal in w.
  const std::size_t record_bytes = 3 * order->size() * sizeof(glm::vec4);
  tris.reserve(ctx, std::max<std::size_t>(record_bytes, 16), CL_MEM_READ_ONLY, "triangles");
  const auto fill_records = [&](glm::vec4* records) {
    parallel_for(order->size(), [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) {
        const std::uint32_t f = (*order)[k];
        const auto& t = mesh.triangles[f];
        const glm::vec3 a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
        // face_normals' normal, computed here instead of in an array of all faces beside the records.
        const glm::vec3 nf = triangle_is_degenerate(a, b, c) ? glm::vec3(0.0f) : glm::normalize(glm::cross(b - a, c - a));
        records[3 * k] = glm::vec4(a, nf.x);
        records[3 * k + 1] = glm::vec4(b - a, nf.y);
        records[3 * k + 2] = glm::vec4(c - a, nf.z);
      }
    }, 1 << 16);
  };
  if (deferred) {
    // update_positions with a BVH: the records go through a host copy kept with the nodes, and
    // nothing waits here; the next compute's blocking read (or the next update) finds them done.
    staging.resize(3 * order->size());
    fill_records(staging.data());
    write(tris.get(), record_bytes, staging.data(), "triangles");
    upload_pending = true;
  } else {
    // set_mesh: written straight into the mapped device buffer (no host copy of 48 bytes per
    // triangle beside it).
    staging = std::vector<glm::vec4>();
    write_mapped(tris.get(), record_bytes, "triangle",
                 [&](void* mapped) { fill_records(static_cast<glm::vec4*>(mapped)); });
    finish("uploading the mesh");
  }
  upload_ms = ms_since(start);
  geometry_bytes = nodes.size() + cells.size() + tris.size();
}

void OpenClBackend::Impl::read_back_nodes() {
  // With bundles the device holds the wide copy: nothing to read back.
  if (config.accel != Accel::Bvh || bundles || !bvh.nodes.empty() || bvh_node_count == 0) return;
  bvh.nodes.resize(bvh_node_count);
  check(clEnqueueReadBuffer(queue.get(), cells.get(), CL_TRUE, 0, bvh_node_count * sizeof(BvhNode),
                            bvh.nodes.data(), 0, nullptr, nullptr),
        "reading the BVH nodes back");
}

void OpenClBackend::Impl::set_geometry(const Mesh& mesh, std::shared_ptr<const Mesh> keep) {
  validate_mesh(mesh, "the mesh given to the OpenCL backend");
  has_mesh = false;
  shape.reset();
  vertex_count = mesh.positions.size();
  face_count = mesh.triangles.size();
  rebuild_geometry(mesh, false);
  shape = std::move(keep);
  has_mesh = true;
}

void OpenClBackend::Impl::ensure_table(int rays, float cone_degrees) {
  if (table.get() && table_rays == rays && table_cone == cone_degrees) return;
  // The rays of the C++ definition itself (local direction xyz, weight w), not a device copy of
  // its formulas.
  const std::vector<ConeRay> cone = cone_rays(rays, cone_degrees);
  std::vector<cl_float4> rows(cone.size());
  for (std::size_t i = 0; i < cone.size(); ++i)
    rows[i] = {{cone[i].local_dir.x, cone[i].local_dir.y, cone[i].local_dir.z, cone[i].weight}};
  const std::size_t bytes = rows.size() * sizeof(cl_float4);
  table.reserve(context.get(), bytes, CL_MEM_READ_ONLY, "the cone's rays");
  write(table.get(), bytes, rows.data(), "the cone's rays");
  finish("uploading the cone's rays");  // `rows` goes out of scope
  table_rays = rays;
  table_cone = cone_degrees;
}

OpenClBackend::OpenClBackend(const OpenClConfig& config) : impl_(std::make_unique<Impl>()) {
  impl_->create(config);
}

OpenClBackend::~OpenClBackend() = default;

std::string OpenClBackend::device_name() const {
  return impl_->info.name + " (" + impl_->info.platform + ", OpenCL)";
}

const DeviceInfo& OpenClBackend::device() const { return impl_->info; }
const Octree& OpenClBackend::octree() const { return impl_->octree; }
const Bvh& OpenClBackend::bvh() const {
  impl_->read_back_nodes();
  return impl_->bvh;
}

void OpenClBackend::set_mesh(const Mesh& mesh) {
  // Built from the caller's mesh as it is; only the triangles are kept, for update_positions.
  impl_->set_geometry(mesh, nullptr);
  auto triangles = std::make_shared<Mesh>();
  triangles->triangles = mesh.triangles;
  impl_->shape = std::move(triangles);
}

void OpenClBackend::set_shared_mesh(std::shared_ptr<const Mesh> mesh) {
  if (!mesh) throw Error("set_shared_mesh got no mesh");
  const Mesh& m = *mesh;
  impl_->set_geometry(m, std::move(mesh));
}

// update_positions needs a set_mesh after this, so the host's triangle order of the BVH (4 bytes
// per triangle, what a refit reads) goes too: the device's records keep the geometry, and bvh()
// then has nodes but an empty order. The wide nodes and records a deferred upload kept go too.
void OpenClBackend::release_mesh() {
  Impl& m = *impl_;
  if (m.upload_pending) m.finish("uploading the moved mesh");
  m.upload_pending = false;
  m.wide = std::vector<WideNode>();
  m.staging = std::vector<glm::vec4>();
  m.shape.reset();
  m.bvh.order = std::vector<std::uint32_t>();
}

void OpenClBackend::update_positions(std::span<const glm::vec3> positions) {
  if (!impl_->has_mesh) throw Error("update_positions was called before set_mesh");
  if (!impl_->shape || impl_->shape->triangles.size() != impl_->face_count)
    throw Error("update_positions: the mesh was released (release_mesh); call set_mesh again");
  if (positions.size() != impl_->vertex_count)
    throw Error("update_positions got " + std::to_string(positions.size()) +
                " positions for a mesh of " + std::to_string(impl_->vertex_count) +
                " vertices");
  for (const glm::vec3& p : positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError("update_positions got a non-finite coordinate");
  // The rebuild reads positions and triangles as one Mesh: the triangles are copied for it and
  // freed with it (update_positions is the skeleton's path, on small meshes).
  Mesh moved;
  moved.positions.assign(positions.begin(), positions.end());
  moved.triangles = impl_->shape->triangles;
  impl_->rebuild_geometry(moved, true);
}

std::size_t OpenClBackend::batch_points(int rays) const {
  const std::size_t per_point = 2 * sizeof(cl_float4) + sizeof(cl_ulong) * static_cast<std::size_t>(rays) +
                                sizeof(cl_float) + sizeof(cl_uint);
  std::size_t n = impl_->config.memory_cap / per_point;
  // No single buffer may exceed the device's largest allocation; global sizes stay in 32 bits.
  n = std::min(n, impl_->max_alloc / (sizeof(cl_ulong) * static_cast<std::size_t>(rays)));
  n = std::min(n, static_cast<std::size_t>(std::numeric_limits<std::uint32_t>::max()) /
                      static_cast<std::size_t>(rays));
  if (impl_->info.type == "CPU") n = std::min(n, kCpuBatchPoints);
  if (n == 0)
    throw InputError("the OpenCL memory cap of " + std::to_string(impl_->config.memory_cap) +
                     " bytes is too small for one point with " + std::to_string(rays) + " rays");
  return n;
}

RawSdf OpenClBackend::compute(const SdfQuery& query, const SdfOptions& options) {
  validate_options(options);
  Impl& m = *impl_;
  if (!m.has_mesh) throw Error("compute was called before set_mesh");
  const std::size_t n = query.size();
  if (query.normals.size() != n || query.valid.size() != n)
    throw Error("the query's origins, normals and valid flags differ in length");
  const auto start = std::chrono::steady_clock::now();
  RawSdf raw;
  if (n == 0) {
    m.trace_ms = ms_since(start);
    return raw;
  }
  const int rays = options.rays;
  const auto nr = static_cast<std::size_t>(rays);
  m.ensure_table(rays, options.cone_degrees);

  const std::size_t batch = std::min(batch_points(rays), n);
  const cl_context ctx = m.context.get();
  m.points.reserve(ctx, batch * sizeof(cl_float4), CL_MEM_READ_ONLY, "query points");
  m.normals.reserve(ctx, batch * sizeof(cl_float4), CL_MEM_READ_ONLY, "query normals");
  m.keys.reserve(ctx, batch * nr * sizeof(cl_ulong), CL_MEM_READ_WRITE, "ray lengths");
  m.values.reserve(ctx, batch * sizeof(cl_float), CL_MEM_WRITE_ONLY, "SDF values");
  m.kept.reserve(ctx, batch * sizeof(cl_uint), CL_MEM_WRITE_ONLY, "kept-ray counts");
  m.batch_bytes = m.points.size() + m.normals.size() + m.keys.size() + m.values.size() +
                  m.kept.size() + m.table.size();

  // Points are traced in Morton order of their origins (neighbouring work items meet the same
  // nodes and triangles, which keeps them in cache); the results go back to query order.
  const std::vector<std::uint32_t> order = spatial_order(query.origins);
  // One batch of points and normals at a time (not a second copy of the whole query): each
  // batch ends with a blocking read, so the next batch's writes find the buffers free.
  std::vector<glm::vec4> pts(batch), nrm(batch);
  // The results come back a batch at a time and go straight to their points (no second pair
  // of per-point arrays in Morton order).
  std::vector<float> values(batch);
  std::vector<std::uint32_t> kept(batch);
  // The per-point results after the Morton order: its sort's 12 bytes per point of scratch are
  // gone by then (8 per point of results beside them was the 13M-triangle run's peak).
  raw.values.assign(n, 0.0f);
  raw.kept_rays.assign(n, 0u);
  const cl_int rule = static_cast<cl_int>(options.false_hit);
  // The writes and the first read do not block: should a later call throw, the queue is drained
  // before the host arrays they use go away (declared after them, destroyed before them).
  struct Drain {
    cl_command_queue queue;
    ~Drain() { clFinish(queue); }
  } drain{m.queue.get()};
  for (std::size_t first = 0; first < n; first += batch) {
    const std::size_t count = std::min(batch, n - first);
    const auto count32 = static_cast<cl_uint>(count);
    parallel_for(count, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t q = order[first + i];
        pts[i] = glm::vec4(query.origins[q], query.valid[q] ? 1.0f : 0.0f);
        nrm[i] = glm::vec4(query.normals[q], 0.0f);
      }
    }, 1 << 16);
    // Non-blocking: the in-order queue runs them before the kernels, and the blocking read that
    // ends this batch returns only when they are done, before `pts` and `nrm` are refilled.
    check(clEnqueueWriteBuffer(m.queue.get(), m.points.get(), CL_FALSE, 0, count * sizeof(cl_float4), pts.data(), 0,
                               nullptr, nullptr),
          "uploading query points");
    check(clEnqueueWriteBuffer(m.queue.get(), m.normals.get(), CL_FALSE, 0, count * sizeof(cl_float4), nrm.data(), 0,
                               nullptr, nullptr),
          "uploading query normals");
    if (m.bundles) {
      // Ray r of kBundle Morton-neighbouring points per bundle, bundles_per_item neighbouring
      // bundles per work item (cl/sdf_trace.cl).
      set_args(m.k_bundles.get(), "trace_bundles", m.cells.get(), m.tris.get(), m.points.get(),
               m.normals.get(), m.table.get(), cl_int{rays}, count32, query.origin_offset, rule,
               m.keys.get());
      const std::size_t bundles = (count + kBundle - 1) / kBundle;
      m.run(m.k_bundles.get(), (bundles + m.bundles_per_item - 1) / m.bundles_per_item * nr, m.local_size,
            "trace_bundles");
    } else {
      set_args(m.k_trace.get(), "trace_rays", m.nodes.get(), m.cells.get(), m.tris.get(),
               m.points.get(), m.normals.get(), m.table.get(), cl_int{rays}, count32,
               query.origin_offset, rule, m.keys.get());
      m.run(m.k_trace.get(), count * nr, m.local_size, "trace_rays");
    }
    set_args(m.k_gather.get(), "gather_points", m.keys.get(), cl_int{rays}, count32,
             m.table.get(), m.values.get(), m.kept.get());
    m.run(m.k_gather.get(), count, m.local_size, "gather_points");
    check(clEnqueueReadBuffer(m.queue.get(), m.values.get(), CL_FALSE, 0, count * sizeof(float),
                              values.data(), 0, nullptr, nullptr),
          "reading SDF values back");
    check(clEnqueueReadBuffer(m.queue.get(), m.kept.get(), CL_TRUE, 0,
                              count * sizeof(std::uint32_t), kept.data(), 0, nullptr, nullptr),
          "reading kept-ray counts back");
    // The in-order queue has run this batch's kernels and the first read: both reads are done.
    for (std::size_t i = 0; i < count; ++i) {
      raw.values[order[first + i]] = values[i];
      raw.kept_rays[order[first + i]] = kept[i];
    }
  }
  m.finish("tracing rays");
  m.upload_pending = false;
  m.trace_ms = ms_since(start);
  return raw;
}

std::vector<StageTiming> OpenClBackend::last_timings() const {
  const char* build = impl_->config.accel == Accel::Octree ? "octree_build"
                      : impl_->refitted                   ? "bvh_refit"
                                                          : "bvh_build";
  return {{build, impl_->octree_ms},
          {"upload", impl_->upload_ms},
          {"trace_gather", impl_->trace_ms}};
}

std::size_t OpenClBackend::device_memory_bytes() const {
  return impl_->geometry_bytes + impl_->batch_bytes;
}

std::vector<glm::vec4> OpenClBackend::ray_directions_for_test(std::span<const glm::vec3> normals,
                                                              const SdfOptions& options) {
  validate_options(options);
  Impl& m = *impl_;
  m.ensure_table(options.rays, options.cone_degrees);
  const std::size_t n = normals.size(), nr = static_cast<std::size_t>(options.rays);
  std::vector<glm::vec4> in(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = glm::vec4(normals[i], 0.0f);
  detail::Buffer in_buf, out_buf;
  in_buf.reserve(m.context.get(), n * sizeof(cl_float4), CL_MEM_READ_ONLY, "test normals");
  out_buf.reserve(m.context.get(), n * nr * sizeof(cl_float4), CL_MEM_WRITE_ONLY, "test directions");
  m.write(in_buf.get(), n * sizeof(cl_float4), in.data(), "test normals");
  set_args(m.k_dirs.get(), "ray_directions", in_buf.get(), m.table.get(), cl_int{options.rays},
           static_cast<cl_uint>(n), out_buf.get());
  m.run(m.k_dirs.get(), n * nr, 0, "ray_directions");
  std::vector<glm::vec4> out(n * nr);
  check(clEnqueueReadBuffer(m.queue.get(), out_buf.get(), CL_TRUE, 0, out.size() * sizeof(cl_float4),
                            out.data(), 0, nullptr, nullptr),
        "reading test directions back");
  return out;
}

RawSdf OpenClBackend::gather_lengths_for_test(std::span<const float> lengths,
                                              std::span<const float> weights, int rays_per_point) {
  Impl& m = *impl_;
  if (rays_per_point < 1 || weights.size() != static_cast<std::size_t>(rays_per_point) ||
      lengths.size() % weights.size() != 0)
    throw InputError("gather_lengths_for_test needs rays_per_point weights and whole points");
  const std::size_t nr = weights.size(), n = lengths.size() / nr;
  std::vector<std::uint64_t> keys(lengths.size());
  for (std::size_t i = 0; i < lengths.size(); ++i) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &lengths[i], sizeof(bits));
    keys[i] = lengths[i] >= 0.0f ? (std::uint64_t{bits} << 32) | (i % nr) : kNoHitKey;
  }
  std::vector<glm::vec4> table(nr);
  for (std::size_t i = 0; i < nr; ++i) table[i] = glm::vec4(0.0f, 0.0f, 0.0f, weights[i]);
  detail::Buffer key_buf, table_buf, value_buf, kept_buf;
  const cl_context ctx = m.context.get();
  key_buf.reserve(ctx, keys.size() * sizeof(cl_ulong), CL_MEM_READ_WRITE, "test lengths");
  table_buf.reserve(ctx, nr * sizeof(cl_float4), CL_MEM_READ_ONLY, "test weights");
  value_buf.reserve(ctx, n * sizeof(cl_float), CL_MEM_WRITE_ONLY, "test values");
  kept_buf.reserve(ctx, n * sizeof(cl_uint), CL_MEM_WRITE_ONLY, "test counts");
  m.write(key_buf.get(), keys.size() * sizeof(cl_ulong), keys.data(), "test lengths");
  m.write(table_buf.get(), nr * sizeof(cl_float4), table.data(), "test weights");
  set_args(m.k_gather.get(), "gather_points", key_buf.get(), cl_int{rays_per_point},
           static_cast<cl_uint>(n), table_buf.get(), value_buf.get(), kept_buf.get());
  m.run(m.k_gather.get(), n, 0, "gather_points");
  RawSdf raw;
  raw.values.resize(n);
  raw.kept_rays.resize(n);
  check(clEnqueueReadBuffer(m.queue.get(), value_buf.get(), CL_TRUE, 0, n * sizeof(float),
                            raw.values.data(), 0, nullptr, nullptr),
        "reading test values back");
  check(clEnqueueReadBuffer(m.queue.get(), kept_buf.get(), CL_TRUE, 0, n * sizeof(std::uint32_t),
                            raw.kept_rays.data(), 0, nullptr, nullptr),
        "reading test counts back");
  return raw;
}

std::vector<std::uint32_t> OpenClBackend::definition_probe_for_test(std::span<const glm::vec4> cases) {
  Impl& m = *impl_;
  if (cases.size() % 3 != 0) throw InputError("definition_probe_for_test needs three entries per case");
  const std::size_t n = cases.size() / 3;
  std::vector<std::uint32_t> out(n);
  if (n == 0) return out;
  detail::Kernel probe = m.make_kernel("definition_probe");
  detail::Buffer in_buf, out_buf;
  const cl_context ctx = m.context.get();
  in_buf.reserve(ctx, cases.size() * sizeof(cl_float4), CL_MEM_READ_ONLY, "test cases");
  out_buf.reserve(ctx, n * sizeof(cl_uint), CL_MEM_WRITE_ONLY, "test results");
  m.write(in_buf.get(), cases.size() * sizeof(cl_float4), cases.data(), "test cases");
  set_args(probe.get(), "definition_probe", in_buf.get(), static_cast<cl_uint>(n), out_buf.get());
  m.run(probe.get(), n, 0, "definition_probe");
  check(clEnqueueReadBuffer(m.queue.get(), out_buf.get(), CL_TRUE, 0, n * sizeof(cl_uint), out.data(), 0,
                            nullptr, nullptr),
        "reading test results back");
  return out;
}

}  // namespace sdfkit::cl
