#include "sdfkit/reference/embree_backend.hpp"

#include "sdfkit/core/error.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace sdfkit::reference {
namespace {

// ---------------------------------------------------------------------------------------------
// Embree handles, each owned by a move-only RAII type (rtcRelease* on destruction).

struct DeviceRelease {
  void operator()(RTCDevice d) const { rtcReleaseDevice(d); }
};
struct SceneRelease {
  void operator()(RTCScene s) const { rtcReleaseScene(s); }
};
struct GeometryRelease {
  void operator()(RTCGeometry g) const { rtcReleaseGeometry(g); }
};
using DeviceHandle = std::unique_ptr<RTCDeviceTy, DeviceRelease>;
using SceneHandle = std::unique_ptr<RTCSceneTy, SceneRelease>;
using GeometryHandle = std::unique_ptr<RTCGeometryTy, GeometryRelease>;

const char* error_name(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE: return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN: return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT: return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION: return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY: return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU: return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED: return "RTC_ERROR_CANCELLED";
  }
  return "unknown RTCError";
}

// Collects what Embree's device error callback reports. The callback may run on any thread,
// inside Embree, so it only records; raise() turns the first recorded error into a
// DeviceError at the end of the stage that caused it (no exception crosses Embree's C API).
class ErrorSink {
public:
  static void callback(void* self, RTCError code, const char* message) {
    static_cast<ErrorSink*>(self)->record(code, message);
  }
  void record(RTCError code, const char* message) {
    const std::lock_guard lock(mutex_);
    if (code_ != RTC_ERROR_NONE) return;
    code_ = code;
    message_ = message ? message : "";
  }
  // Throws DeviceError("Embree failed while <stage>: <message> (<code>)") if an error came.
  void raise(const char* stage) {
    const std::lock_guard lock(mutex_);
    if (code_ == RTC_ERROR_NONE) return;
    std::string text = std::string("Embree failed while ") + stage + ": " +
                       (message_.empty() ? "no message" : message_) + " (" + error_name(code_) +
                       ")";
    code_ = RTC_ERROR_NONE;
    message_.clear();
    throw DeviceError(text);
  }

private:
  std::mutex mutex_;
  RTCError code_ = RTC_ERROR_NONE;
  std::string message_;
};

// Embree's memory monitor: bytes currently allocated by the device and the peak since reset.
struct MemoryMonitor {
  std::atomic<std::int64_t> current{0};
  std::atomic<std::int64_t> peak{0};

  static bool callback(void* self, ssize_t bytes, bool /*post*/) {
    auto* m = static_cast<MemoryMonitor*>(self);
    const std::int64_t now = m->current.fetch_add(bytes) + bytes;
    std::int64_t p = m->peak.load();
    while (now > p && !m->peak.compare_exchange_weak(p, now)) {
    }
    return true;
  }
  void reset_peak() { peak.store(current.load()); }
};

double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The rays of one point in Embree's packet layout for K = 1, 4, 8, 16.
template <int K> struct Packet;
template <> struct Packet<4> {
  using Type = RTCRayHit4;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, Type* r) {
    rtcIntersect4(valid, s, c, r);
  }
};
template <> struct Packet<8> {
  using Type = RTCRayHit8;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, Type* r) {
    rtcIntersect8(valid, s, c, r);
  }
};
template <> struct Packet<16> {
  using Type = RTCRayHit16;
  static void intersect(const int* valid, RTCScene s, RTCIntersectContext* c, Type* r) {
    rtcIntersect16(valid, s, c, r);
  }
};

}  // namespace

// ---------------------------------------------------------------------------------------------

struct EmbreeBackend::Impl {
  EmbreeOptions options;
  unsigned threads = 1;
  // Declared before the device: they must outlive every callback Embree makes.
  std::unique_ptr<ErrorSink> errors = std::make_unique<ErrorSink>();
  std::unique_ptr<MemoryMonitor> memory = std::make_unique<MemoryMonitor>();
  DeviceHandle device;
  // The current geometry; released before the device (reverse declaration order).
  SceneHandle scene;
  GeometryHandle geometry;
  float* vertex_buffer = nullptr;  // Embree-owned, 3 floats per vertex (+ padding)

  Mesh mesh;                                // the current mesh (positions updated in place)
  std::vector<std::uint8_t> degenerate;     // per face
  std::vector<glm::vec3> face_normal;       // per face, outward unit (zero when degenerate)
  std::vector<std::uint32_t> prim_to_face;  // Embree primID -> face index

  std::optional<double> build_ms, trace_ms;
  std::size_t compute_peak_bytes = 0;

  void build_scene();
  void refit();
  void trace_range(const SdfQuery& query, const SdfOptions& sdf,
                   std::span<const ConeRay> rays, std::atomic<std::size_t>& next,
                   std::size_t chunk, RawSdf& out) const;
  template <int K>
  void trace_point_packets(RTCIntersectContext& ctx, const glm::vec3& org, const Frame& frame,
                           std::span<const ConeRay> rays, const glm::vec3& n, FalseHitRule rule,
                           std::vector<float>& lengths, std::vector<float>& weights) const;
  void trace_point_single(RTCIntersectContext& ctx, const glm::vec3& org, const Frame& frame,
                          std::span<const ConeRay> rays, const glm::vec3& n, FalseHitRule rule,
                          std::vector<float>& lengths, std::vector<float>& weights) const;
};

// Builds a fresh scene from `mesh`: the non-degenerate triangles, the primID -> face map and
// our outward face normals. The geometry asks for refitting so update_positions is cheap.
void EmbreeBackend::Impl::build_scene() {
  geometry.reset();
  scene.reset();
  vertex_buffer = nullptr;
  degenerate = degenerate_faces(mesh);
  face_normal = face_normals(mesh);
  prim_to_face.clear();
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    if (!degenerate[f]) prim_to_face.push_back(static_cast<std::uint32_t>(f));

  scene.reset(rtcNewScene(device.get()));
  // Robust: watertight traversal, so rays through shared edges and vertices never slip through.
  rtcSetSceneFlags(scene.get(), RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene.get(), RTC_BUILD_QUALITY_MEDIUM);
  errors->raise("creating the scene");
  if (prim_to_face.empty()) {
    // Nothing to hit: an empty committed scene makes every ray miss.
    rtcCommitScene(scene.get());
    errors->raise("building the BVH");
    return;
  }

  geometry.reset(rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE));
  rtcSetGeometryBuildQuality(geometry.get(), RTC_BUILD_QUALITY_REFIT);
  vertex_buffer = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry.get(), RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
      mesh.positions.size()));
  auto* index_buffer = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
      geometry.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t),
      prim_to_face.size()));
  errors->raise("allocating the geometry buffers");
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    vertex_buffer[3 * v + 0] = mesh.positions[v].x;
    vertex_buffer[3 * v + 1] = mesh.positions[v].y;
    vertex_buffer[3 * v + 2] = mesh.positions[v].z;
  }
  for (std::size_t p = 0; p < prim_to_face.size(); ++p) {
    const Triangle& t = mesh.triangles[prim_to_face[p]];
    index_buffer[3 * p + 0] = t[0];
    index_buffer[3 * p + 1] = t[1];
    index_buffer[3 * p + 2] = t[2];
  }
  rtcCommitGeometry(geometry.get());
  rtcAttachGeometry(scene.get(), geometry.get());
  rtcCommitScene(scene.get());
  errors->raise("building the BVH");
}

// Copies the moved positions into Embree's vertex buffer and refits the BVH.
void EmbreeBackend::Impl::refit() {
  face_normal = face_normals(mesh);
  if (!geometry) return;  // no triangle to move
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    vertex_buffer[3 * v + 0] = mesh.positions[v].x;
    vertex_buffer[3 * v + 1] = mesh.positions[v].y;
    vertex_buffer[3 * v + 2] = mesh.positions[v].z;
  }
  rtcUpdateGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(geometry.get());
  rtcCommitScene(scene.get());
  errors->raise("refitting the BVH");
}

// One point's rays, K at a time in an Embree packet. Lane j of packet b holds ray b*K + j, so
// the order of the lengths (and thus the gather) never depends on scheduling.
template <int K>
void EmbreeBackend::Impl::trace_point_packets(RTCIntersectContext& ctx, const glm::vec3& org,
                                              const Frame& frame, std::span<const ConeRay> rays,
                                              const glm::vec3& n, FalseHitRule rule,
                                              std::vector<float>& lengths,
                                              std::vector<float>& weights) const {
  alignas(64) typename Packet<K>::Type rh;
  alignas(64) int valid[K];
  glm::vec3 dirs[K];
  for (std::size_t base = 0; base < rays.size(); base += K) {
    for (int j = 0; j < K; ++j) {
      const std::size_t r = base + static_cast<std::size_t>(j);
      valid[j] = r < rays.size() ? -1 : 0;
      const glm::vec3 d = r < rays.size() ? world_direction(frame, rays[r]) : -n;
      dirs[j] = d;
      rh.ray.org_x[j] = org.x;
      rh.ray.org_y[j] = org.y;
      rh.ray.org_z[j] = org.z;
      rh.ray.dir_x[j] = d.x;
      rh.ray.dir_y[j] = d.y;
      rh.ray.dir_z[j] = d.z;
      rh.ray.tnear[j] = 0.0f;
      rh.ray.tfar[j] = std::numeric_limits<float>::infinity();
      rh.ray.time[j] = 0.0f;
      rh.ray.mask[j] = ~0u;
      rh.ray.id[j] = static_cast<unsigned>(j);
      rh.ray.flags[j] = 0;
      rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID[j] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][j] = RTC_INVALID_GEOMETRY_ID;
    }
    Packet<K>::intersect(valid, scene.get(), &ctx, &rh);
    for (int j = 0; j < K; ++j) {
      if (!valid[j] || rh.hit.geomID[j] == RTC_INVALID_GEOMETRY_ID) continue;
      const glm::vec3& hn = face_normal[prim_to_face[rh.hit.primID[j]]];
      if (!accept_hit(rule, n, dirs[j], hn)) continue;
      lengths.push_back(rh.ray.tfar[j]);
      weights.push_back(rays[base + static_cast<std::size_t>(j)].weight);
    }
  }
}

// One point's rays, one rtcIntersect1 call each.
void EmbreeBackend::Impl::trace_point_single(RTCIntersectContext& ctx, const glm::vec3& org,
                                             const Frame& frame, std::span<const ConeRay> rays,
                                             const glm::vec3& n, FalseHitRule rule,
                                             std::vector<float>& lengths,
                                             std::vector<float>& weights) const {
  for (const ConeRay& r : rays) {
    const glm::vec3 d = world_direction(frame, r);
    RTCRayHit rh{};
    rh.ray.org_x = org.x;
    rh.ray.org_y = org.y;
    rh.ray.org_z = org.z;
    rh.ray.dir_x = d.x;
    rh.ray.dir_y = d.y;
    rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene.get(), &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    const glm::vec3& hn = face_normal[prim_to_face[rh.hit.primID]];
    if (!accept_hit(rule, n, d, hn)) continue;
    lengths.push_back(rh.ray.tfar);
    weights.push_back(r.weight);
  }
}

// A worker: takes chunks of `chunk` points from `next` until none is left, writing each
// point's value and kept-ray count into `out` (disjoint entries per point).
void EmbreeBackend::Impl::trace_range(const SdfQuery& query, const SdfOptions& sdf,
                                      std::span<const ConeRay> rays,
                                      std::atomic<std::size_t>& next, std::size_t chunk,
                                      RawSdf& out) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  std::vector<float> lengths, weights;
  lengths.reserve(rays.size());
  weights.reserve(rays.size());
  const std::size_t n = query.size();
  for (;;) {
    const std::size_t begin = next.fetch_add(chunk);
    if (begin >= n) return;
    const std::size_t end = std::min(n, begin + chunk);
    for (std::size_t i = begin; i < end; ++i) {
      if (!query.valid[i]) continue;
      const glm::vec3 normal = query.normals[i];
      const Frame frame = tangent_frame(-normal);
      const glm::vec3 org = query.origins[i] - query.origin_offset * normal;
      lengths.clear();
      weights.clear();
      switch (options.packet_size) {
        case 4: trace_point_packets<4>(ctx, org, frame, rays, normal, sdf.false_hit, lengths, weights); break;
        case 8: trace_point_packets<8>(ctx, org, frame, rays, normal, sdf.false_hit, lengths, weights); break;
        case 16: trace_point_packets<16>(ctx, org, frame, rays, normal, sdf.false_hit, lengths, weights); break;
        default: trace_point_single(ctx, org, frame, rays, normal, sdf.false_hit, lengths, weights); break;
      }
      const GatherResult g = gather(lengths, weights);
      out.values[i] = g.value;
      out.kept_rays[i] = g.kept;
    }
  }
}

// ---------------------------------------------------------------------------------------------

EmbreeBackend::EmbreeBackend(EmbreeOptions options) : impl_(std::make_unique<Impl>()) {
  if (options.packet_size != 1 && options.packet_size != 4 && options.packet_size != 8 &&
      options.packet_size != 16)
    throw InputError("the Embree packet size must be 1, 4, 8 or 16, got " +
                     std::to_string(options.packet_size));
  impl_->options = options;
  impl_->threads = options.threads != 0 ? options.threads
                                        : std::max(1u, std::thread::hardware_concurrency());
  impl_->device.reset(rtcNewDevice(nullptr));
  if (!impl_->device) {
    const RTCError code = rtcGetDeviceError(nullptr);
    throw DeviceError(std::string("could not start Embree (") + error_name(code) +
                      "); the CPU may lack the SSE2 support Embree needs");
  }
  rtcSetDeviceErrorFunction(impl_->device.get(), &ErrorSink::callback, impl_->errors.get());
  rtcSetDeviceMemoryMonitorFunction(impl_->device.get(), &MemoryMonitor::callback,
                                    impl_->memory.get());
}

EmbreeBackend::~EmbreeBackend() = default;

std::string EmbreeBackend::name() const { return "embree"; }

std::string EmbreeBackend::device_name() const {
  RTCDevice d = impl_->device.get();
  return "Embree " + std::to_string(rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_VERSION_MAJOR)) +
         "." + std::to_string(rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_VERSION_MINOR)) + "." +
         std::to_string(rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_VERSION_PATCH)) + " (CPU, " +
         std::to_string(impl_->threads) + (impl_->threads == 1 ? " thread)" : " threads)");
}

unsigned EmbreeBackend::thread_count() const { return impl_->threads; }

void EmbreeBackend::set_mesh(const Mesh& mesh) {
  validate_mesh(mesh, "the mesh given to the Embree backend");
  const auto start = std::chrono::steady_clock::now();
  impl_->mesh = mesh;
  try {
    impl_->build_scene();
  } catch (...) {
    impl_->geometry.reset();
    impl_->scene.reset();
    impl_->mesh = Mesh{};
    throw;
  }
  impl_->build_ms = milliseconds_since(start);
}

void EmbreeBackend::update_positions(std::span<const glm::vec3> positions) {
  if (!impl_->scene) throw Error("update_positions needs a mesh: call set_mesh first");
  if (positions.size() != impl_->mesh.positions.size())
    throw Error("update_positions got " + std::to_string(positions.size()) +
                " positions for a mesh of " + std::to_string(impl_->mesh.positions.size()) +
                " vertices");
  Mesh moved{std::vector<glm::vec3>(positions.begin(), positions.end()), impl_->mesh.triangles};
  validate_mesh(moved, "the positions given to the Embree backend");
  const auto start = std::chrono::steady_clock::now();
  impl_->mesh.positions = std::move(moved.positions);
  // A triangle that became degenerate (or stopped being one) changes the primitive set, which
  // a refit cannot express: rebuild then.
  if (degenerate_faces(impl_->mesh) != impl_->degenerate)
    impl_->build_scene();
  else
    impl_->refit();
  impl_->build_ms = milliseconds_since(start);
}

RawSdf EmbreeBackend::compute(const SdfQuery& query, const SdfOptions& options) {
  validate_options(options);
  if (!impl_->scene) throw Error("the Embree backend has no mesh: call set_mesh before compute");
  const std::size_t n = query.size();
  if (query.normals.size() != n || query.valid.size() != n)
    throw InputError("the SDF query has " + std::to_string(n) + " origins but " +
                     std::to_string(query.normals.size()) + " normals and " +
                     std::to_string(query.valid.size()) + " validity flags");
  const auto start = std::chrono::steady_clock::now();
  impl_->memory->reset_peak();
  const std::vector<ConeRay> rays = cone_rays(options.rays, options.cone_degrees);

  RawSdf out;
  out.values.assign(n, 0.0f);
  out.kept_rays.assign(n, 0u);
  // Small chunks keep the threads balanced (points differ in cost); each point is written by
  // exactly one thread, so the result does not depend on the schedule.
  const std::size_t chunk = 64;
  const std::size_t workers =
      std::max<std::size_t>(1, std::min<std::size_t>(impl_->threads, (n + chunk - 1) / chunk));
  std::atomic<std::size_t> next{0};
  std::vector<std::exception_ptr> failures(workers);
  auto work = [&](std::size_t w) {
    try {
      impl_->trace_range(query, options, rays, next, chunk, out);
    } catch (...) {
      failures[w] = std::current_exception();
      next.store(n);  // stop the others early
    }
  };
  if (workers == 1) {
    work(0);
  } else {
    std::vector<std::thread> pool;
    pool.reserve(workers - 1);
    for (std::size_t w = 1; w < workers; ++w) pool.emplace_back(work, w);
    work(0);
    for (std::thread& t : pool) t.join();
  }
  for (const std::exception_ptr& e : failures)
    if (e) std::rethrow_exception(e);
  impl_->errors->raise("tracing rays");
  impl_->trace_ms = milliseconds_since(start);
  impl_->compute_peak_bytes = static_cast<std::size_t>(std::max<std::int64_t>(0, impl_->memory->peak.load()));
  return out;
}

std::vector<StageTiming> EmbreeBackend::last_timings() const {
  std::vector<StageTiming> t;
  if (impl_->build_ms) t.push_back({"bvh_build", *impl_->build_ms});
  if (impl_->trace_ms) t.push_back({"trace_gather", *impl_->trace_ms});
  return t;
}

std::size_t EmbreeBackend::device_memory_bytes() const { return impl_->compute_peak_bytes; }

}  // namespace sdfkit::reference
