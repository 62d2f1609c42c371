// sdfkit compare: two results on the same mesh -> Pearson correlation, relative differences and
// their histogram; with -o a picture coloured white (equal) to red (>= 5% apart), as in the
// paper's Figures 6 and 9. With --diffusion: one result smoothed by heat diffusion, k-ring and
// texture space, side by side (compare_diffusion.cpp).
#include "commands.hpp"
#include "compare_diffusion.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/io/field.hpp"
#include "sdfkit/post/compare.hpp"
#ifdef SDFKIT_CLI_HAS_RENDER
#include "sdfkit/render/figure.hpp"
#include "sdfkit/vulkan/context.hpp"
#endif

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

namespace sdfkit::cli {
namespace {

// One side of the comparison: values per welded point of `asset` when a mesh is known.
struct Side {
  std::optional<io::Asset> asset;
  SdfDomain domain = SdfDomain::Vertex;
  std::vector<float> values;
};

Side load_side(const std::string& path, const std::optional<io::Asset>& mesh, const io::LoadOptions& load) {
  Side s;
  if (io::format_from_path(path) == io::Format::Txt) {
    const std::vector<float> raw = io::read_values_txt(path);
    if (mesh) {
      s.domain = io::domain_of_count(*mesh, raw.size(), path);
      s.values = io::welded_values(*mesh, s.domain, raw);
    } else {
      s.values = raw;
    }
    return s;
  }
  ResultValues r = load_or_compute(path, nullptr, load);
  s.domain = r.domain;
  s.values = std::move(r.values);
  s.asset = std::move(r.asset);
  return s;
}

// Per point |a - b| / |b| (0 where both are 0, 1 where only b is 0).
std::vector<float> absolute_relative(std::span<const float> a, std::span<const float> b) {
  std::vector<float> d(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const float diff = std::fabs(a[i] - b[i]);
    d[i] = b[i] != 0.0f ? diff / std::fabs(b[i]) : (diff == 0.0f ? 0.0f : 1.0f);
  }
  return d;
}

void print_histogram(std::span<const float> rel, double limit) {
  constexpr int kBins = 10;
  std::vector<std::size_t> counts(kBins + 1, 0);
  for (const float r : rel) {
    const int b = r >= limit ? kBins : static_cast<int>(r / limit * kBins);
    ++counts[static_cast<std::size_t>(std::min(b, kBins))];
  }
  std::size_t top = 1;
  for (const std::size_t c : counts) top = std::max(top, c);
  std::printf("relative difference |a-b|/|b|, %zu points:\n", rel.size());
  for (int b = 0; b <= kBins; ++b) {
    char label[48];
    if (b < kBins)
      std::snprintf(label, sizeof label, "[%5.2f%%, %5.2f%%)", 100.0 * limit * b / kBins,
                    100.0 * limit * (b + 1) / kBins);
    else
      std::snprintf(label, sizeof label, ">= %.2f%%", 100.0 * limit);
    const std::size_t c = counts[static_cast<std::size_t>(b)];
    const int bar = static_cast<int>(40.0 * static_cast<double>(c) / static_cast<double>(top) + 0.5);
    std::printf("  %-18s %8zu %s\n", label, c, std::string(static_cast<std::size_t>(bar), '#').c_str());
  }
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("compare", "Compare two SDF results on the same mesh (B is the reference)");
  struct Args {
    std::string a, b, mesh, output;
    double limit = 0.05;
    io::LoadOptions load;
    int views = 4, width = 1600, height = 900;
  };
  auto a = std::make_shared<Args>();
  auto d = std::make_shared<DiffusionCompareArgs>();
  auto diffusion = std::make_shared<bool>(false);
  cmd->add_option("A", a->a, "Result: .glb/.gltf (_SDF), .ply (quality) or .txt (with --mesh)")->required();
  cmd->add_option("B", a->b, "Reference result, same kinds as A (not with --diffusion)");
  // --diffusion (issue 13): A smoothed three ways at each sigma, k-ring and texture space against heat diffusion.
  cmd->add_flag("--diffusion", *diffusion,
                "Instead: smooth A (per vertex) by heat diffusion, k-ring smoothing and texture-space diffusion at each "
                "sigma and print how far k-ring and texture space are from heat diffusion");
  cmd->add_option("--sigma", d->sigmas, "--diffusion: Gaussian sigmas in model units")->delimiter(',')->check(CLI::PositiveNumber);
  cmd->add_option("--sigma-edges", d->sigma_edges, "--diffusion: Gaussian sigmas in mean edge lengths")
      ->delimiter(',')->check(CLI::PositiveNumber);
  cmd->add_option("--atlas-size", d->atlas_size, "--diffusion: texture space's atlas side (default 2048)")
      ->check(CLI::Range(16, 16384));
  cmd->add_option("--skeleton", d->skeleton, "--diffusion: skeleton JSON of the mesh (default: extracted)");
  cmd->add_option("--device", d->device, "--diffusion: Vulkan device (index or name)");
  cmd->add_option("--heat-steps", d->heat_steps, "--diffusion: implicit steps of the heat reference")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--json", d->json, "--diffusion: also write the table as JSON");
  cmd->add_option("--mesh", a->mesh, "The mesh the .txt values belong to");
  cmd->add_option("-o,--output", a->output, "PNG of the mesh coloured white (equal) to red (>= --limit apart)");
  cmd->add_option("--limit", a->limit, "Relative difference drawn full red (default 0.05 = 5%)")
      ->check(CLI::Range(1e-6, 10.0));
  cmd->add_option("--views", a->views, "Views of the mesh in the picture")->check(CLI::Range(1, 64));
  cmd->add_option("--width", a->width, "Picture width in pixels")->check(CLI::Range(64, 8192));
  cmd->add_option("--height", a->height, "Picture height in pixels")->check(CLI::Range(64, 8192));
  cmd->add_option("--weld-tolerance", a->load.weld_tolerance, "Weld positions closer than this (model units; default 1e-6 of the bounding box, 0 = bitwise-equal only)")
      ->check(CLI::NonNegativeNumber);
  add_asset_options(*cmd, a->load);
  cmd->callback([a, d, diffusion, cmd] {
    const auto given = [cmd](const char* name) { return cmd->get_option(name)->count() > 0; };
    if (*diffusion) {
      for (const char* k : {"B", "--output", "--limit", "--views", "--width", "--height"})
        if (given(k)) throw UsageError(std::string(k) + " is not used by --diffusion");
      if (d->sigmas.empty() == d->sigma_edges.empty())
        throw UsageError("--diffusion needs exactly one of --sigma and --sigma-edges");
      d->input = a->a;
      d->mesh = a->mesh;
      d->load = a->load;
      compare_diffusion(*d);
      return;
    }
    for (const char* k : {"--sigma", "--sigma-edges", "--atlas-size", "--skeleton", "--device", "--heat-steps", "--json"})
      if (given(k)) throw UsageError(std::string(k) + " needs --diffusion");
    if (a->b.empty()) throw UsageError("compare needs two results, A and B (or --diffusion)");
    if (!a->output.empty()) check_png_name(a->output);
    std::optional<io::Asset> mesh;
    if (!a->mesh.empty()) mesh = load_input(a->mesh, a->load);
    Side sa = load_side(a->a, mesh, a->load);
    if (!mesh && sa.asset) mesh = sa.asset;
    Side sb = load_side(a->b, mesh, a->load);
    if (!mesh && sb.asset) mesh = sb.asset;
    // A .txt read before any mesh was known: map it now.
    if (mesh && !sa.asset && sa.values.size() != (sb.domain == SdfDomain::Face ? mesh->mesh.face_count()
                                                                               : mesh->mesh.vertex_count()))
      sa = load_side(a->a, mesh, a->load);
    if (sa.values.size() != sb.values.size())
      throw InputError(a->a + " has " + std::to_string(sa.values.size()) + " values but " + a->b + " has " +
                       std::to_string(sb.values.size()) + ": they are not results on the same mesh");
    if (sa.domain != sb.domain)
      throw InputError(a->a + " and " + a->b + " are not both per-vertex or both per-face results");
    if (sa.values.empty()) throw InputError(a->a + ": no values to compare");

    const FieldComparison c = compare_fields(sa.values, sb.values);
    std::printf("A %s\nB %s (reference)\n", a->a.c_str(), a->b.c_str());
    std::printf("points                          %zu (%s)\n", c.points,
                sa.domain == SdfDomain::Vertex ? "vertices" : "faces");
    std::printf("pearson                         %.6f\n", c.pearson);
    std::printf("median relative |a-b|/|b|       %.4f%%\n", 100.0 * c.median_relative);
    std::printf("95th percentile relative        %.4f%%\n", 100.0 * c.p95_relative);
    std::printf("max relative                    %.4f%%\n", 100.0 * c.max_relative);
    std::printf("median signed relative (a-b)/|b| %+.4f%%\n", 100.0 * c.median_signed_relative);
    std::printf("median signed difference a-b    %+.6g (model units)\n", c.median_signed);
    const std::vector<float> rel = absolute_relative(sa.values, sb.values);
    print_histogram(rel, a->limit);

    if (a->output.empty()) return;
    if (!mesh) throw UsageError("a picture needs the mesh: give --mesh");
#ifdef SDFKIT_CLI_HAS_RENDER
    render::RenderOptions o;
    o.views = a->views;
    o.width = a->width;
    o.height = a->height;
    o.lo = 0.0f;
    o.hi = static_cast<float>(a->limit);
    o.palette = render::difference_scale(o.hi).palette;
    vk::Context ctx;
    const render::Image img = render::render_figure(ctx, mesh->mesh, rel, sa.domain, o);
    render::write_png(a->output, img);
    std::printf("wrote %s (white: equal, red: >= %g%% apart)\n", a->output.c_str(), 100.0 * a->limit);
#else
    throw Error("this sdfkit was built without Vulkan: no pictures");
#endif
  });
}

}  // namespace sdfkit::cli
