#include "sdfkit/io/solids.hpp"

#include "gltf_model.hpp"

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <cmath>
#include <map>

namespace sdfkit::io {
namespace {

// L^T L of the world transform's linear part.
glm::dmat3 gram(const std::array<double, 16>& m) {
  glm::dmat3 l;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) l[c][r] = m[static_cast<std::size_t>(4 * c + r)];
  return glm::transpose(l) * l;
}

double trace(const glm::dmat3& g) { return g[0][0] + g[1][1] + g[2][2]; }

// Same shape up to a similarity: the traces' normalised Gram matrices agree.
bool same_class(const glm::dmat3& a, const glm::dmat3& b) {
  const double ta = trace(a), tb = trace(b);
  if (!(ta > 0.0) || !(tb > 0.0)) return false;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (std::abs(a[c][r] / ta - b[c][r] / tb) > 1e-5) return false;
  return true;
}

}  // namespace

SolidPlan plan_solids(const Asset& asset) {
  SolidPlan plan;
  const auto* src = (asset.format == Format::Gltf || asset.format == Format::Glb)
                        ? static_cast<const detail::GltfSource*>(asset.source.get())
                        : nullptr;
  if (src == nullptr || src->instances.empty()) {
    Solid all;
    all.vertex_ranges.push_back({0u, static_cast<std::uint32_t>(asset.input_positions.size())});
    all.triangle_ranges.push_back({0u, static_cast<std::uint32_t>(asset.input_triangles.size())});
    plan.solids.push_back(std::move(all));
    plan.representatives.push_back(0);
    return plan;
  }
  // Instances arrive primitive by primitive, a node's primitives one after the other.
  std::vector<glm::dmat3> grams;
  for (const detail::GltfPrimitiveInstance& inst : src->instances) {
    if (plan.solids.empty() || plan.solids.back().node != inst.node) {
      Solid s;
      s.node = inst.node;
      s.mesh = inst.mesh;
      plan.solids.push_back(std::move(s));
      grams.push_back(gram(inst.world));
    }
    plan.solids.back().vertex_ranges.push_back({inst.first_vertex, inst.vertex_count});
    plan.solids.back().triangle_ranges.push_back({inst.first_triangle, inst.triangle_count});
  }
  // Per mesh, its classes: (group, Gram matrix of the representative).
  std::map<int, std::vector<std::pair<int, std::size_t>>> classes;
  for (std::size_t i = 0; i < plan.solids.size(); ++i) {
    Solid& s = plan.solids[i];
    auto& list = classes[s.mesh];
    bool found = false;
    for (const auto& [group, rep] : list) {
      const Solid& r = plan.solids[rep];
      if (r.vertex_ranges.size() == s.vertex_ranges.size() && same_class(grams[i], grams[rep])) {
        s.group = group;
        s.scale = std::sqrt(trace(grams[i]) / trace(grams[rep]));
        found = true;
        break;
      }
    }
    if (!found) {
      s.group = static_cast<int>(plan.representatives.size());
      s.scale = 1.0;
      plan.representatives.push_back(i);
      list.push_back({s.group, i});
    }
  }
  return plan;
}

}  // namespace sdfkit::io
