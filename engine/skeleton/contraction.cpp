// Mesh contraction (Au et al. 2008) with the SDF centering term and SDF holding weights
// (Shapira et al. 2008, section 5).

#include "sdfkit/skeleton/skeleton.hpp"

#include "laplacian.hpp"
#include "validate.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/core/log.hpp"

#include <Eigen/SparseCholesky>
#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <numeric>

namespace sdfkit::skeleton {
namespace {

// Holding weights grow as sqrt(A0 / At); the growth is capped so that a fully collapsed
// one-ring (At -> 0) stays a finite, well-conditioned constraint.
constexpr double kMaxHoldingGrowth = 1e4;
// A contraction step must not grow the surface area by more than this factor; one that does is
// diverging (ill-conditioned system), so the loop stops with the state before it.
constexpr double kMaxAreaGrowth = 1.25;

void validate(const ContractionOptions& o) {
  auto bad = [](const std::string& what) { throw InputError("contraction option " + what); };
  if (!(o.wl_scale > 0.0) || !std::isfinite(o.wl_scale)) bad("wl_scale must be positive");
  if (!(o.sl >= 1.0) || !std::isfinite(o.sl)) bad("sl (contraction growth) must be at least 1");
  if (!(o.sl_handles >= 1.0) || !std::isfinite(o.sl_handles)) bad("sl_handles (contraction growth) must be at least 1");
  if (!(o.wh0 > 0.0) || !std::isfinite(o.wh0)) bad("wh0 (holding weight) must be positive");
  if (!(o.wc >= 0.0) || !std::isfinite(o.wc)) bad("wc (SDF centering weight) must be >= 0");
  if (!(o.sdf_bias > 0.0 && o.sdf_bias <= 1.0)) bad("sdf_bias must be in (0, 1]");
  if (!(o.area_ratio_stop >= 0.0 && o.area_ratio_stop < 1.0)) bad("area_ratio_stop must be in [0, 1)");
  if (o.max_iterations < 1 || o.max_iterations > 1000) bad("max_iterations must be in [1, 1000]");
  if (o.iteration_rays < 0 || o.iteration_rays > 4096) bad("iteration_rays must be in [0, 4096]");
  validate_options(o.sdf);
}

double total(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

bool all_finite(const Eigen::MatrixXd& m) { return m.allFinite(); }

}  // namespace

ContractionResult contract(const Mesh& mesh, SdfBackend* backend, const ContractionOptions& options,
                           std::span<const float> first_sdf) {
  validate(options);
  detail::require_closed(mesh, "skeleton extraction");
  if (!first_sdf.empty() && first_sdf.size() != mesh.positions.size())
    throw InputError("contract() got " + std::to_string(first_sdf.size()) + " first SDF values for " +
                     std::to_string(mesh.positions.size()) + " vertices");
  ContractionResult result;
  result.contracted = mesh;
  const bool use_sdf = options.sdf_term && backend != nullptr;
  SdfOptions sdf_options = options.sdf;
  sdf_options.domain = SdfDomain::Vertex;

  const std::size_t n = mesh.positions.size();
  const double diag = bounding_box(mesh.positions).diagonal();
  const std::vector<double> area0 = detail::one_ring_areas(mesh);
  const double total0 = total(area0);
  const double mean_face_area = total0 / 3.0 / static_cast<double>(mesh.triangles.size());
  // Dimensionless W_L0 (see the header): wl_scale over the mean face area measured in diag^2.
  double wl = options.wl_scale * (diag * diag) / mean_face_area;
  std::vector<double> wh(n, options.wh0);

  bool backend_has_mesh = false;  // set_mesh at the first measurement, update_positions after
  Eigen::MatrixXd V(static_cast<Eigen::Index>(n), 3);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) V(static_cast<Eigen::Index>(i), k) = mesh.positions[i][k];

  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  std::vector<float> thickness;  // per vertex: the smallest SDF measured so far
  Eigen::Index pattern_nonzeros = 0;
  double factor_ms = 0.0;
  using Clock = std::chrono::steady_clock;
  auto ms_since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  const double wc2 = use_sdf ? options.wc * options.wc : 0.0;
  // The holding weights' SDF factor: from the input's SDF (HoldingSdf::Initial) or the
  // thinnest measured so far (Current).
  auto divide_holding = [&](const std::vector<float>& sdf) {
    const std::vector<float> norm = normalized(sdf);
    for (std::size_t i = 0; i < n; ++i) wh[i] /= norm[i] * (1.0 - options.sdf_bias) + options.sdf_bias;
  };
  for (int it = 0; it < options.max_iterations; ++it) {
    Mesh& current = result.contracted;
    // The matrix A = W_L^2 L^2 + W_H^2 + W_C^2 depends on the current positions, W_L and the
    // holding weights, not on this iteration's SDF (which enters the right-hand side through
    // C), unless the holding weights follow the current SDF. So it is assembled and factorized
    // on a second thread while the SDF is measured (the host mostly waits for the device
    // there); with HoldingSdf::Current only the Laplacian term is. The operations are the same
    // either way, so the result is too.
    const bool holding_now = use_sdf && it > 0 && options.holding_sdf == HoldingSdf::Initial;
    if (holding_now) divide_holding(result.first_sdf);
    const bool factor_early = !use_sdf || it == 0 || holding_now;
    // The sparsity pattern depends only on the connectivity (every edge is stored, also with
    // weight 0), so the fill-reducing ordering and symbolic analysis are done once. (Measured
    // on refined_elephant, 44k vertices: factorization ~0.28 s CPU per iteration; the
    // quasi-definite augmented system [-I, L; L, D/W_L^2] has the same fill and cost.)
    struct System {
      Eigen::SparseMatrix<double> A;
      double factor_ms = 0.0;  // 0 until factorized
    };
    // Adds the holding and centering weights' diagonal to the Laplacian term and factorizes.
    auto factorize = [&solver, &pattern_nonzeros, it, &wh, wc2, n, &ms_since](System& sys) {
      for (std::size_t i = 0; i < n; ++i) {
        const auto r = static_cast<Eigen::Index>(i);
        sys.A.coeffRef(r, r) += wh[i] * wh[i] + wc2;
      }
      const auto t = Clock::now();
      if (it == 0 || sys.A.nonZeros() != pattern_nonzeros) {
        solver.analyzePattern(sys.A);
        pattern_nonzeros = sys.A.nonZeros();
      }
      solver.factorize(sys.A);
      sys.factor_ms = ms_since(t);
    };
    auto system = std::async(std::launch::async, [&current, wl, factor_early, &factorize] {
      System sys;
      const Eigen::SparseMatrix<double> L = detail::cotangent_laplacian(current);
      sys.A = (wl * wl) * (L * L);  // L is symmetric: L^T L = L L
      if (factor_early) factorize(sys);
      return sys;
    });
    const auto t_sdf = Clock::now();
    Eigen::MatrixXd C;
    if (use_sdf) {
      // The first SDF at full quality (holding weights, Skeleton::sdf) unless given, the later
      // ones with iteration_rays: the centering term needs only an approximate thickness.
      std::vector<float> values;
      if (it == 0 && !first_sdf.empty()) {
        values.assign(first_sdf.begin(), first_sdf.end());
      } else {
        if (!backend_has_mesh) backend->set_mesh(current);
        else backend->update_positions(current.positions);
        backend_has_mesh = true;
        sdf_options.rays = it > 0 && options.iteration_rays > 0 ? options.iteration_rays : options.sdf.rays;
        values = compute_sdf(*backend, current, sdf_options).values;
        if (log_level() <= LogLevel::Debug) {
          std::string stages;
          for (const StageTiming& st : backend->last_timings()) stages += " " + st.stage + " " + std::to_string(st.milliseconds);
          log_debug("contraction SDF stages (ms):" + stages);
        }
      }
      if (it == 0) {
        result.first_sdf = values;
        thickness = values;
      }
      // Contraction only thins the shape, so a vertex's SDF never grows: on the crumpled,
      // partly collapsed mesh of later iterations some rays escape through folds and measure
      // far surfaces; those values would pull vertices outward (C_i) and, through the
      // normalization, make every other vertex look thin and hold it (measured on CGAL's
      // elephant: the area grew from 0.28 to 0.40 of the original over five iterations).
      for (std::size_t i = 0; i < n; ++i) thickness[i] = std::min(thickness[i], values[i]);
      result.last_sdf = std::move(values);
      const std::vector<glm::vec3> normals = vertex_normals(current);
      C = V;
      for (std::size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k)
          C(static_cast<Eigen::Index>(i), k) -= 0.5 * thickness[i] * normals[i][k];
    }

    const double sdf_ms = ms_since(t_sdf);
    result.sdf_seconds += 1e-3 * sdf_ms;
    const auto t_solve = Clock::now();
    System sys = system.get();  // the solver is the main thread's again from here
    if (!factor_early) {
      divide_holding(thickness);
      factorize(sys);
    }
    factor_ms = sys.factor_ms;
    Eigen::MatrixXd rhs(static_cast<Eigen::Index>(n), 3);
    for (std::size_t i = 0; i < n; ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      const double wh2 = wh[i] * wh[i];
      rhs.row(r) = wh2 * V.row(r);
      if (use_sdf) rhs.row(r) += wc2 * C.row(r);
    }
    if (solver.info() != Eigen::Success) {
      result.warnings.push_back("contraction stopped after " + std::to_string(it) +
                                " iterations: the sparse factorization failed; the last good "
                                "state is kept");
      result.stop_reason = "factorization failed";
      break;
    }
    const Eigen::MatrixXd next = solver.solve(rhs);
    if (solver.info() != Eigen::Success || !all_finite(next)) {
      result.warnings.push_back("contraction stopped after " + std::to_string(it) +
                                " iterations: the solve gave non-finite positions; the last "
                                "good state is kept");
      break;
    }
    const double solve_ms = ms_since(t_solve);
    result.solve_seconds += 1e-3 * solve_ms;
    const double previous_ratio = result.area_ratio;
    Mesh candidate = current;
    for (std::size_t i = 0; i < n; ++i)
      candidate.positions[i] = glm::vec3(next(static_cast<Eigen::Index>(i), 0),
                                         next(static_cast<Eigen::Index>(i), 1),
                                         next(static_cast<Eigen::Index>(i), 2));
    const std::vector<double> area = detail::one_ring_areas(candidate);
    const double ratio = total0 > 0.0 ? total(area) / total0 : 0.0;
    if (ratio > kMaxAreaGrowth * result.area_ratio) {
      result.stop_reason = "the area stopped shrinking (ratio " + std::to_string(result.area_ratio) +
                           ", next step " + std::to_string(ratio) + "); the last state is kept";
      break;
    }
    V = next;
    current = std::move(candidate);
    result.iterations = it + 1;
    result.area_ratio = ratio;
    log_debug("contraction iteration " + std::to_string(it + 1) + ": area ratio " +
              std::to_string(result.area_ratio) + ", SDF " + std::to_string(sdf_ms) +
              " ms, solve " + std::to_string(solve_ms) + " ms (factorization " +
              std::to_string(factor_ms) + " ms)");
    if (result.area_ratio < options.area_ratio_stop) {
      result.stop_reason = "area ratio below " + std::to_string(options.area_ratio_stop);
      break;
    }

    // A step that shrank the area by less than stall_ratio is a stall (typically thin parts
    // held by the SDF weights while W_L catches up): W_L then grows by sl^2.
    wl *= previous_ratio - result.area_ratio < options.stall_ratio * previous_ratio
              ? options.sl * options.sl
              : options.sl;
    for (std::size_t i = 0; i < n; ++i) {
      const double growth = area[i] > 0.0 ? std::sqrt(area0[i] / area[i]) : kMaxHoldingGrowth;
      wh[i] = options.wh0 * std::min(growth, kMaxHoldingGrowth);
    }
  }
  if (result.iterations == options.max_iterations && result.area_ratio >= options.area_ratio_stop) {
    result.stop_reason = "iteration cap";
    result.warnings.push_back("contraction reached the iteration cap (" +
                              std::to_string(options.max_iterations) + ") at area ratio " +
                              std::to_string(result.area_ratio));
  }
  if (result.stop_reason.empty()) result.stop_reason = "stopped early (see warnings)";
  log_info("contraction: " + std::to_string(result.iterations) + " iterations, " + result.stop_reason);
  for (const std::string& w : result.warnings) log_warning(w);
  return result;
}

}  // namespace sdfkit::skeleton
