#include "sdfkit/core/sdf.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/topology.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace sdfkit {

void validate_options(const SdfOptions& o) {
  if (o.rays < 1 || o.rays > 1024)
    throw UsageError("--rays must be between 1 and 1024, got " + std::to_string(o.rays));
  if (!(o.cone_degrees > 0.0f && o.cone_degrees <= 180.0f))
    throw UsageError("--cone must be in (0, 180] degrees, got " + std::to_string(o.cone_degrees));
}

SdfQuery make_query(const Mesh& mesh, SdfDomain domain) {
  SdfQuery q;
  q.domain = domain;
  q.origin_offset = kOriginOffset * bounding_box(mesh.positions).diagonal();
  if (domain == SdfDomain::Vertex) {
    q.origins = mesh.positions;  // a view, not a copy (76 MiB at 6.7M vertices)
    q.normals = vertex_normals(mesh);
  } else {
    auto centroids = std::make_shared<const std::vector<glm::vec3>>(face_centroids(mesh));
    q.origins = *centroids;
    q.origin_storage = std::move(centroids);
    q.normals = face_normals(mesh);
  }
  q.valid.resize(q.origins.size());
  for (std::size_t i = 0; i < q.origins.size(); ++i)
    q.valid[i] = q.normals[i] != glm::vec3(0.0f);
  return q;
}

SdfField finish_field(const Mesh& mesh, SdfDomain domain, RawSdf raw) {
  SdfField field;
  field.domain = domain;
  const std::size_t n = raw.values.size();
  field.values = std::move(raw.values);
  field.kept_rays = std::move(raw.kept_rays);
  field.kept_rays.resize(n, 0);
  field.filled.assign(n, 0);

  std::vector<std::uint8_t> has(n);
  double total = 0.0;
  std::size_t valued = 0;
  for (std::size_t i = 0; i < n; ++i) {
    has[i] = field.kept_rays[i] > 0 && std::isfinite(field.values[i]);
    if (has[i]) {
      total += field.values[i];
      ++valued;
    } else {
      field.values[i] = 0.0f;
      field.filled[i] = 1;
      ++field.filled_count;
    }
  }
  if (field.filled_count == 0) return field;

  // The rings of the gaps only (the rounds below read no other ring).
  std::vector<std::uint8_t> gaps;
  if (domain == SdfDomain::Vertex) {
    gaps.resize(n);
    for (std::size_t i = 0; i < n; ++i) gaps[i] = !has[i];
  }
  const Adjacency adj = domain == SdfDomain::Vertex ? vertex_adjacency(mesh, gaps) : face_adjacency(mesh);
  gaps = std::vector<std::uint8_t>();
  // Ring by ring: each round fills every gap that touches a valued point, from values known at
  // the start of the round, so the result does not depend on the order of the points.
  std::vector<std::uint32_t> frontier;
  for (std::size_t i = 0; i < n; ++i)
    if (!has[i]) frontier.push_back(static_cast<std::uint32_t>(i));
  std::vector<std::pair<std::uint32_t, float>> updates;
  while (!frontier.empty()) {
    updates.clear();
    std::vector<std::uint32_t> still;
    for (std::uint32_t i : frontier) {
      double s = 0.0;
      int c = 0;
      if (i < adj.size())
        for (std::uint32_t k = adj.offsets[i]; k < adj.offsets[i + 1]; ++k)
          if (has[adj.indices[k]]) {
            s += field.values[adj.indices[k]];
            ++c;
          }
      if (c > 0)
        updates.emplace_back(i, static_cast<float>(s / c));
      else
        still.push_back(i);
    }
    if (updates.empty()) break;
    for (const auto& [i, v] : updates) {
      field.values[i] = v;
      has[i] = 1;
    }
    frontier.swap(still);
  }
  const float fallback = valued > 0 ? static_cast<float>(total / static_cast<double>(valued)) : 0.0f;
  for (std::uint32_t i : frontier) field.values[i] = fallback;
  return field;
}

std::vector<float> normalized(std::span<const float> values) {
  std::vector<float> out(values.size(), 0.0f);
  if (values.empty()) return out;
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  const float range = *hi - *lo;
  if (!(range > 0.0f)) return out;
  for (std::size_t i = 0; i < values.size(); ++i) out[i] = (values[i] - *lo) / range;
  return out;
}

SdfField compute_sdf(SdfBackend& backend, const Mesh& mesh, const SdfOptions& options) {
  validate_options(options);
  RawSdf raw;
  {  // the query is freed before the field is finished
    const SdfQuery query = make_query(mesh, options.domain);
    raw = backend.compute(query, options);
    if (raw.values.size() != query.size() || raw.kept_rays.size() != query.size())
      throw Error("backend " + backend.name() + " returned " + std::to_string(raw.values.size()) +
                  " values for " + std::to_string(query.size()) + " points");
  }
  return finish_field(mesh, options.domain, std::move(raw));
}

}  // namespace sdfkit
