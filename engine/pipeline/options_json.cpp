// Every option of a request as one JSON object: the reports' "options" and the batch's resume
// fingerprint are this one serialisation, so an option that changes the result cannot be left
// out of one of them. The field counts below stop the build when a new option is added to one of
// the structures without being written here.
#include "sdfkit/pipeline.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>

namespace sdfkit {
namespace {

// The number of members of an aggregate: the most arguments its brace initialization accepts.
struct AnyMember {
  template <class T>
  operator T() const;  // never defined: used in unevaluated contexts only
};
template <class T, class... A>
constexpr std::size_t member_count() {
  if constexpr (requires { T{A{}..., AnyMember{}}; })
    return member_count<T, A..., AnyMember>();
  else
    return sizeof...(A);
}

static_assert(member_count<SdfOptions>() == 4, "SdfOptions: options_to_json must write every member (the batch fingerprint is made of it)");
static_assert(member_count<BackendConfig>() == 10, "BackendConfig: options_to_json must write every member (the batch fingerprint is made of it)");
static_assert(member_count<io::LoadOptions>() == 4, "io::LoadOptions: options_to_json must write every member (the batch fingerprint is made of it)");
static_assert(member_count<io::WriteOptions>() == 4, "io::WriteOptions: options_to_json must write every member (the batch fingerprint is made of it)");
static_assert(member_count<ComputeRequest>() == 8, "ComputeRequest: options_to_json must write every member (the batch fingerprint is made of it)");

// FNV-1a over the overlays' bytes: they are data, not settings, and may be large.
std::string overlay_digest(const io::Overlay& o) {
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  mix(o.points.data(), o.points.size() * sizeof(glm::vec3));
  mix(o.lines.data(), o.lines.size() * sizeof(o.lines[0]));
  mix(o.triangles.data(), o.triangles.size() * sizeof(Triangle));
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

nlohmann::json options_object_base(const ComputeRequest& r) {
  const BackendConfig& b = r.backend;
  nlohmann::json order = nlohmann::json::array();
  for (BackendKind k : b.auto_order) order.push_back(to_string(k));
  nlohmann::json overlays = nlohmann::json::array();
  for (const io::Overlay& o : r.write.overlays)
    overlays.push_back({{"name", o.name},
                        {"points", o.points.size()},
                        {"lines", o.lines.size()},
                        {"triangles", o.triangles.size()},
                        {"digest", overlay_digest(o)}});
  nlohmann::json write = {{"color", r.write.color}, {"normalized", r.write.normalized}, {"overlays", overlays}};
  // Written only when set, so that fingerprints of jobs without it stay what they were.
  if (!r.write.texcoord1.empty()) {
    io::Overlay uv;  // digest of the corner UVs through the overlay digest's byte mixer
    for (const auto& t : r.write.texcoord1)
      for (const glm::vec2& q : t) uv.points.push_back({q.x, q.y, 0.0f});
    write["texcoord1"] = {{"triangles", r.write.texcoord1.size()}, {"digest", overlay_digest(uv)}};
  }
  return {
      {"backend",
       {{"kind", to_string(b.kind)},
        {"auto_order", order},
        {"device", b.device},
        {"views", b.views},
        {"resolution", b.resolution},
        {"peel_mode", b.vulkan_mode},
        {"validation", b.validation},
        {"profile", b.profile},
        {"memory_cap", b.memory_cap},
        {"accel", b.accel}}},
      {"sdf",
       {{"rays", r.sdf.rays},
        {"cone_degrees", r.sdf.cone_degrees},
        {"per", r.sdf.domain == SdfDomain::Face ? "face" : "vertex"},
        {"false_hits", r.sdf.false_hit == FalseHitRule::Cgal ? "cgal" : "paper"}}},
      {"load",
       {{"weld_tolerance", r.load.weld_tolerance},
        {"allow_external_paths", r.load.allow_external_paths},
        {"max_triangles", r.load.max_triangles},
        {"max_file_size", r.load.max_file_size}}},
      {"write", write},
      {"smooth_rings", r.smooth_rings}};
}

// With texture-space smoothing (issue 13) its radius too; absent when off, so the fingerprints of
// requests without it are what they were.
nlohmann::json options_object(const ComputeRequest& r) {
  nlohmann::json j = options_object_base(r);
  if (r.smooth_texture_px > 0.0f) j["smooth_texture_px"] = r.smooth_texture_px;
  return j;
}

}  // namespace

std::string options_to_json(const ComputeRequest& request) { return options_object(request).dump(); }

}  // namespace sdfkit
