#pragma once
// The SDF pipeline's data: what a backend is asked (SdfQuery), what it answers (RawSdf), and
// the finished field (SdfField) with filled gaps. A backend sees only a Mesh and a query.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/sdf_definition.hpp"

#include <algorithm>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace sdfkit {

enum class SdfDomain { Vertex, Face };

struct SdfOptions {
  int rays = kDefaultRays;                  // rays per point (ray backends)
  float cone_degrees = kDefaultConeDegrees; // full aperture of the cone, degrees, (0, 180]
  SdfDomain domain = SdfDomain::Vertex;
  FalseHitRule false_hit = FalseHitRule::Paper;
};

// Throws InputError with a sentence when an option is out of range.
void validate_options(const SdfOptions& options);

// The points to evaluate, each with its outward normal. Points with valid == 0 (isolated
// vertices, degenerate faces) cast no ray and get filled values.
struct SdfQuery {
  SdfDomain domain = SdfDomain::Vertex;
  // The surface points, a view: of the mesh's positions for vertices (make_query: the mesh must
  // outlive the query), or of `origin_storage` when the points are computed (face centroids).
  std::span<const glm::vec3> origins;
  std::shared_ptr<const std::vector<glm::vec3>> origin_storage;  // shared: copies stay valid
  std::vector<glm::vec3> normals;         // unit outward normals (zero where invalid)
  std::vector<std::uint8_t> valid;        // 1 = cast rays from this point
  float origin_offset = 0.0f;             // kOriginOffset * bounding-box diagonal
  std::size_t size() const { return origins.size(); }
};

// The query of a mesh's vertices or faces; a vertex query's origins view mesh.positions.
SdfQuery make_query(const Mesh& mesh, SdfDomain domain);

// A backend's answer: per point, the gathered value and the number of kept rays (0 = no value).
struct RawSdf {
  std::vector<float> values;
  std::vector<std::uint32_t> kept_rays;
};

// The finished field, in model units, one value per query point.
struct SdfField {
  SdfDomain domain = SdfDomain::Vertex;
  std::vector<float> values;             // finite everywhere
  std::vector<std::uint32_t> kept_rays;  // 0 where the value was filled
  std::vector<std::uint8_t> filled;      // 1 where the value was filled
  std::size_t filled_count = 0;
};

// Fills points without a value by the mean of their valued neighbours (vertex one-ring or
// edge-adjacent faces), repeated outward ring by ring until nothing changes; points in parts
// with no valued point at all get the mean of all valued points, or 0 when nothing has a value.
SdfField finish_field(const Mesh& mesh, SdfDomain domain, RawSdf raw);

// (v - min) / (max - min) per value; all zeros when max == min.
std::vector<float> normalized(std::span<const float> values);

// One stage of a backend's last compute() or set_mesh(), for benchmarks and --profile.
struct StageTiming {
  std::string stage;  // "octree_build", "upload", "trace_gather", "peel", ...
  double milliseconds = 0.0;
  // A part of another stage (the device time of one pass, "gpu_*"), not added to totals.
  bool nested = false;
};

// The sum of the stages that are not nested in another.
inline double total_milliseconds(std::span<const StageTiming> stages) {
  double total = 0.0;
  for (const StageTiming& s : stages)
    if (!s.nested) total += s.milliseconds;
  return total;
}

// Adds `stages` to the running sums by stage name, in the order of first appearance.
inline void accumulate_stages(std::vector<StageTiming>& sums, std::span<const StageTiming> stages) {
  for (const StageTiming& s : stages) {
    auto it = std::find_if(sums.begin(), sums.end(), [&](const StageTiming& t) { return t.stage == s.stage; });
    if (it == sums.end()) sums.push_back(s);
    else it->milliseconds += s.milliseconds;
  }
}

// Every backend implements this. A backend object is a session: it keeps its device context,
// compiled programs and uploaded geometry between calls.
class SdfBackend {
public:
  virtual ~SdfBackend() = default;
  SdfBackend() = default;
  SdfBackend(const SdfBackend&) = delete;
  SdfBackend& operator=(const SdfBackend&) = delete;

  virtual std::string name() const = 0;
  // Human-readable device description ("llvmpipe (LLVM 15.0.6, 256 bits)", "Embree 3.13 CPU").
  virtual std::string device_name() const = 0;
  // Uploads geometry and builds whatever the backend needs; replaces earlier geometry.
  virtual void set_mesh(const Mesh& mesh) = 0;
  // set_mesh for a mesh its owner shares instead of lending: the backend may keep `mesh` (what
  // update_positions needs of it: the triangles) instead of a copy. The owner must not change
  // the triangles while the backend holds it, and moves vertices only by also calling
  // update_positions with the new positions. The default copies what set_mesh copies.
  virtual void set_shared_mesh(std::shared_ptr<const Mesh> mesh) { set_mesh(*mesh); }
  // Drops the backend's reference to a mesh of set_shared_mesh (the owner may then move it
  // away): compute() keeps working on the uploaded geometry, update_positions needs a set_mesh
  // first.
  virtual void release_mesh() {}
  // Moves the vertices of the current mesh (same count, same triangles) and rebuilds derived
  // data; cheaper than set_mesh. Throws Error when the count differs.
  virtual void update_positions(std::span<const glm::vec3> positions) = 0;
  // Evaluates the query against the current mesh.
  virtual RawSdf compute(const SdfQuery& query, const SdfOptions& options) = 0;
  // Wall-clock time of the stages of the last set_mesh/update_positions/compute calls.
  virtual std::vector<StageTiming> last_timings() const { return {}; }
  // Peak device memory the backend held during the last compute(), in bytes (0 = unknown).
  virtual std::size_t device_memory_bytes() const { return 0; }
};

// Convenience: query, compute, fill. backend.set_mesh(mesh) must have been called.
SdfField compute_sdf(SdfBackend& backend, const Mesh& mesh, const SdfOptions& options);

}  // namespace sdfkit
