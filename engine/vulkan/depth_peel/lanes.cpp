// Lanes: on CPU devices two contexts render halves of the cameras on their own threads; the
// second lane's samples are appended to the first lane's per point before the gather.
#include "session.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace sdfkit::vk {

void DepthPeelBackend::Impl::append_lane_samples(const Impl& second, std::size_t n, std::uint32_t max_samples) {
  auto* have_counts = static_cast<std::uint32_t*>(staged_counts.mapped());
  auto* have_samples = static_cast<glm::vec2*>(staged_samples.mapped());
  const auto* more_counts = static_cast<const std::uint32_t*>(second.staged_counts.mapped());
  const auto* more_samples = static_cast<const glm::vec2*>(second.staged_samples.mapped());
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t have = std::min(have_counts[i], max_samples);
    const std::uint32_t add = std::min(more_counts[i], max_samples - have);
    const std::size_t base = i * max_samples;
    std::copy_n(more_samples + base, add, have_samples + base + have);
    have_counts[i] += more_counts[i];
  }
}

int resolve_lanes(const DepthPeelConfig& config, const Context& ctx) {
  if (config.mode != PeelMode::FragmentLists) return 1;
  if (config.lanes > 0) return std::min(config.lanes, 2);
  return ctx.info().type == "cpu" && config.views >= 16 ? 2 : 1;
}

}  // namespace sdfkit::vk
