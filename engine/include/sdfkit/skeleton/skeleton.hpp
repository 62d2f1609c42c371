#pragma once
// SDF-driven skeletons (Shapira, Shamir & Cohen-Or 2008, section 5), built on the mesh
// contraction of Au, Tai, Chu, Cohen-Or & Lee 2008 ("Skeleton extraction by mesh contraction").
//
// The road:  closed mesh ──contract()──▶ contracted mesh (same connectivity, near-zero volume)
//            ──connectivity surgery (half-edge collapses)──▶ curve skeleton
//            ──embedding refinement, radii from the SDF──▶ nodes
//            ──visibility check──▶ sheets where a curve is not reliable ──▶ Skeleton.
//
// The SDF comes from any SdfBackend (a session: the GPU backends keep their context and
// buffers). contract() calls backend->set_mesh(mesh) once, then update_positions() and
// compute_sdf() at every iteration on the current, contracting mesh. extract() on a mesh above
// ContractionOptions::proxy_vertices contracts a simplified proxy that way, then calls
// set_mesh(input) once more for the input's own SDF.
//
// Input: a closed (watertight) triangle mesh. A mesh with boundary edges is refused with an
// InputError. extract() splits non-manifold edges (parts touching along an edge: the triangles
// are paired across the solid they bound) and builds the skeleton of the split mesh, with node
// vertices mapped back to the input's and a warning; contract() and build_skeleton() still
// need an edge-manifold mesh. A mesh of several components is contracted
// as one system (the Laplacian is block-diagonal, the SDF sees all components, as in the plain
// SDF of that mesh); the skeleton then has one connected part per component.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/sdf.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <span>
#include <vector>

namespace sdfkit::skeleton {

// Which SDF normalizes the holding weights W_H_i /= SDFnorm_i (1 - bias) + bias.
enum class HoldingSdf {
  // The SDF of the input mesh: thin parts are held more for the whole contraction (default).
  // Measured on CGAL's elephant (2775 vertices, defaults otherwise): 13 iterations to the area
  // stop, against 17 with Current, whose weights swing as parts finish contracting (the
  // total area grew from 0.29 to 0.41 of the original over five iterations).
  Initial,
  // The smallest SDF measured so far at each vertex (the SDF of the current mesh, made
  // monotone: see ContractionResult::last_sdf).
  Current,
};

struct ContractionOptions {
  // Initial contraction weight W_L0 = wl_scale * diag^2 / (mean face area), diag the bounding
  // box diagonal. Au et al. print W_L0 = 1e-3 * sqrt(A); with their dimensionless cotangent
  // Laplacian that value depends on the model's units, and a step shrinks a tube of radius r
  // meshed with edges h by about 1 / (1 + (W_L h^2 / r^2)^2), so the weight that starts the
  // contraction scales with r^2 / h^2: dividing by the mean face area (in diag^2) makes the
  // iteration count independent of units and resolution. Measured on CGAL's elephant with the
  // SDF term: wl_scale 1e-3 -> 13 iterations, 1e-4 -> 17; Au's literal value (in diag units)
  // needed over 20. 1e-3 is faster but coarser: the star test's mean node distance to the
  // medial axis is 0.0088 against 0.0016 at 1e-4, and CGAL's camel stops after 2 iterations
  // (a step grew the area), so the default is 1e-4 (those counts are with sl = 2).
  double wl_scale = 1e-4;
  // W_L is multiplied by sl after every iteration (Au: S_L = 2) ... Measured (CGAL meshes
  // through the 1000-vertex proxy, Embree): sl = 3 needs 10 / 11 / 8 iterations on hand /
  // elephant / camel against 15 / 15 / 11 with 2, at equal or better curve reliability (90.6 /
  // 91.4 / 94.1 % against 93.8 / 81.9 / 95.5 %), and centres the contracted star better (mean
  // vertex distance to the medial axis 0.042 against 0.049; 0.061 and 0.080 without the SDF
  // term); CGAL's cow: curve reliability 0.91 against 0.82. Hence 3.
  double sl = 3.0;
  // S_L instead of `sl` when a component of the mesh has genus > 0. A faster contraction
  // shrinks a ring faster than the holding weights hold it, and the handle closes before the
  // surgery sees it. Measured over CGAL's data set (eval, genus > 0 meshes): with 3, cycles =
  // genus failed on anchor 3/4, couplingdown 3/9, pipe 0/1, mpi 2/1, elephant 6/3 (75 % sheet
  // nodes); with 2 all of these hold (elephant 0 % sheets), joint went 2 -> 1 of 2, at ~1.5x the
  // iterations. Genus-0 meshes keep `sl` (their speed is where 3 was chosen).
  double sl_handles = 2.0;
  // ... or by sl^2 after an iteration that shrank the total area by less than this fraction
  // (0 = never): a stall while thin parts, held by the SDF weights, wait for W_L.
  double stall_ratio = 0.0;
  double wh0 = 1.0;  // initial holding weight W_H0 for every vertex
  // Weight of the SDF centering term: attraction of v_i to C_i = v_i - SDF_i/2 * n_i, where
  // SDF_i is the smallest SDF measured at vertex i so far (contraction only thins the shape;
  // rays escaping through the folds of a partly collapsed mesh measure far surfaces).
  double wc = 0.5;
  bool sdf_term = true;   // use the centering term and the SDF holding weights (needs a backend)
  double sdf_bias = 0.01; // W_H_i /= SDFnorm_i * (1 - bias) + bias
  HoldingSdf holding_sdf = HoldingSdf::Initial;
  // Stop when the total area falls below this fraction of the initial area (or when a step would
  // grow the area: see ContractionResult::stop_reason).
  double area_ratio_stop = 1e-3;
  int max_iterations = 20;  // hard cap on the iterations (>= 1)
  // Options of the SDF (domain: Vertex). The first iteration measures it with sdf.rays (that
  // SDF normalizes the holding weights and, without a proxy, is Skeleton::sdf; through a proxy
  // extract() measures the input's SDF and the proxy starts from its per-vertex means) ...
  SdfOptions sdf;
  // ... and every later iteration recomputes it on the current mesh with this many rays
  // (0 = sdf.rays): the centering term needs only an approximate thickness, and takes the
  // smallest value measured so far, mostly the first. Measured on the star (3888 vertices):
  // the contracted vertices' mean distance to the medial axis is 0.0423 / 0.0423 / 0.0422 /
  // 0.0422 with 4 / 8 / 16 / 30 rays; the SDF is 60-70 % of an iteration at 30 rays. 4 rays
  // against 8 through the proxy: curve reliability about the same on CGAL's hand, elephant and
  // camel, hand's contraction SDF 19 ms instead of 25 (engine/skeleton/README.md).
  int iteration_rays = 4;
  // extract(): a mesh with more vertices than this is contracted through a proxy simplified to
  // this many vertices (manifold-preserving quadric edge collapses that keep closedness and
  // genus); every input vertex follows the proxy vertex it was merged into, and the skeleton
  // is still built for the input (nodes hold input vertices, radii, centre points and
  // visibility from the input's SDF and surface). 0 = always contract the input itself.
  // contract() ignores it. Measured (README.md): 500 broke the hand's contraction (curve
  // reliability 54 %) and 700 the star test (four arm ends instead of five); 1000 passes every
  // test, and makes refined_elephant's contraction 0.06 s instead of 12-19 s.
  std::size_t proxy_vertices = 1000;
};

struct ContractionResult {
  Mesh contracted;              // same triangles as the input, contracted positions
  int iterations = 0;           // solves that were accepted
  std::vector<float> first_sdf; // per-vertex SDF of the input mesh (empty without SDF term)
  std::vector<float> last_sdf;  // per-vertex SDF of the last contracted mesh that was measured
  double area_ratio = 1.0;      // total area now / initial total area
  // Why the loop ended: "area ratio below ...", "the area stopped shrinking ..." (a step would
  // have grown the total area by over 25%: the contraction has converged as far as it goes,
  // the remaining un-contracted parts are grouped by the surgery), "iteration cap", or a
  // failure (also in warnings).
  std::string stop_reason;
  std::vector<std::string> warnings;
  double sdf_seconds = 0.0;    // wall-clock time in the SDF (update_positions + compute_sdf)
  double solve_seconds = 0.0;  // wall-clock time building and solving the linear systems
};

// Contracts `mesh` (closed) by iterated Laplacian smoothing with holding and SDF centering
// constraints. `backend` may be nullptr: then no SDF term (the plain Au et al. contraction).
// Never returns NaN positions: a failing factorization or a non-finite solution stops the loop
// with the last good state and a warning. Throws InputError for unusable input (see top).
// `first_sdf`: the per-vertex SDF of `mesh` as given when the caller has it already (the first
// iteration then uses it instead of measuring it with options.sdf.rays; extract() passes the
// input's SDF averaged over the input vertices of each proxy vertex); empty = measure it.
ContractionResult contract(const Mesh& mesh, SdfBackend* backend, const ContractionOptions& options,
                           std::span<const float> first_sdf = {});

struct SkeletonOptions {
  double ggt = 0.05;   // grouping: global part of the distance, fraction of the bbox diagonal
  double gmt = 1.25;   // grouping: multiple of the local radius SDF_i/2
  bool sheets = true;  // keep unreliable regions as triangle sheets
  // Sheet node spacing, fraction of the bbox diagonal: the contracted sheet is clustered on a
  // grid of this cell (0 = one sheet node per surface vertex).
  double sheet_spacing = 0.025;
  double shape_weight = 1.0;     // Au's w_a: weight of the quadric shape cost
  double sampling_weight = 0.1;  // Au's w_b: weight of the sampling cost
  // Place each curve node at the centre of the part of the solid its vertices enclose (the mean
  // of their SDF centre points u - SDF/2 n); off = the contracted position (if inside).
  bool refine_embedding = true;
  // Give each curve leaf a tip node when the centre point of its vertex farthest along the limb
  // lies over a node radius beyond the leaf, inside the solid: the node takes the leaf's
  // vertices beyond the midpoint and sits at their centre, so leaves reach the ends of limbs
  // instead of stopping at the centre of the last node's region. Before that, a
  // leaf hanging off a degree-2 node, inside the tube of the edge that node continues on (a knee
  // hanging off the foot), is threaded into that edge, so the farther node becomes the leaf.
  bool extend_leaves = true;
  // Drop a terminal curve branch whose nodes' balls (centre, radius) all lie inside the rest of
  // the skeleton's balls swept along its curve edges: it adds nothing to the solid the
  // skeleton describes (a bump on the surface, a spur beside a limb); its vertices go to the
  // node it hangs from.
  bool prune_branches = true;
  // Unfold a terminal curve branch that runs out along its limb and back (a leg contracted to
  // a flat ribbon collapses to its two rims, joined at the hoof), or that runs beside another
  // limb (a rim hanging from the junction as a strand of its own): the run of nodes from the
  // leaf that lies beside the rest of the branch or another curve edge is threaded into it, so
  // the leaf is where the branch turned, and a strand beside its limb goes into the limb.
  bool unfold_branches = true;
  // Cut each curve edge longer than two local radii into cross-sections one local radius apart,
  // with a node at the centre of each (the mean of its vertices' centre points), so the curve
  // follows a bending limb instead of a chord between grouped nodes.
  bool section_nodes = true;
  // Give a branch to a protrusion that the contraction merged whole into a node of the body (an
  // ear, a foot): a connected region of vertices whose centre points lie outside the skeleton's
  // union of node balls swept along its curve edges, that reaches farther from its base (the
  // vertices around it) than the base's radius, whose mean ball is outside the union too and
  // that borders no sheet, gets nodes by the rules of the unseen regions (one node seen by half
  // of them, else one per piece unless mostly flat) and a leaf at its tip.
  bool protrusion_branches = true;
};

struct Node {
  glm::vec3 position{0.0f};
  float radius = 0.0f;                  // local radius in model units (SDF/2 of its vertices)
  std::vector<std::uint32_t> vertices;  // input-mesh vertices this node represents (see extract())
  bool sheet = false;                   // node of a sheet (a cluster of the contracted sheet)
};

struct Skeleton {
  std::vector<Node> nodes;
  std::vector<std::array<std::uint32_t, 2>> edges;  // curve edges, indices into nodes, i < j
  std::vector<Triangle> sheet_triangles;            // sheet patches, indices into nodes
  // Share of surface vertices whose node is visible from them along a segment inside the solid
  // (a vertex that cannot see its node is first moved to the nearest node it sees; with sheets
  // on, the vertices that see no curve node become sheet nodes, so this is 1 except for
  // vertices that see no interior point at all: zero-thickness fins, one vertex of CGAL's cow).
  double reliability = 0.0;
  double curve_reliability = 0.0;  // the same for the curve skeleton before sheets were added
  int iterations = 0;              // contraction iterations
  // Vertices of the mesh that was contracted: the proxy's (ContractionOptions::proxy_vertices)
  // or the input's.
  std::size_t contracted_vertices = 0;
  // Wall-clock seconds per stage of extract() (zero for stages that did not run).
  struct Timings {
    double simplify = 0.0;           // building the proxy
    double contraction_sdf = 0.0;    // SDF recomputed during the contraction
    double contraction_solve = 0.0;  // linear systems of the contraction
    double contraction = 0.0;        // the whole contraction (SDF, solves, areas, normals)
    double input_sdf = 0.0;          // the input's SDF when the contraction did not measure it
    double build = 0.0;              // surgery, refinement, visibility, sheets
  } seconds;
  // Per-vertex SDF of the input mesh (model units, gaps filled) with the contraction's SDF
  // options; empty when extract() ran without a backend.
  std::vector<float> sdf;
  std::vector<std::string> warnings;
};

// Contraction + connectivity surgery + refinement + sheets. `backend` may be nullptr (no SDF:
// no centering term, radii are the mean distance from a node to its vertices, grouping uses the
// distance from a vertex to its contracted position, centre points come from one ray along the
// inward normal). With a backend and sdf_term off, the SDF is computed once (radii, grouping,
// centre points) but not used in the contraction. Every vertex a triangle uses belongs to exactly
// one node; every node lies inside the solid. The mesh must be wound outward (as load_asset and
// orient_outward leave it): the SDF, the centre points and the inside tests (the winding number:
// where closed pieces overlap, the solid is their union) read the winding. One skeleton per
// connected piece: a node stands for vertices of one piece. Vertices no triangle uses (glTF, OBJ and PLY allow
// them) are not part of the surface: they belong to no node, take no part in the contraction or
// in the scales taken from the bounding box, and their Skeleton::sdf is 0 (a warning counts them).
Skeleton extract(const Mesh& mesh, SdfBackend* backend, const ContractionOptions& contraction,
                 const SkeletonOptions& options);

// Builds the skeleton of an already contracted mesh (the second half of extract()):
// `original` the input, `contracted` the output of contract() (same triangles), `sdf` the
// per-vertex SDF of the original (may be empty).
Skeleton build_skeleton(const Mesh& original, const Mesh& contracted, const std::vector<float>& sdf,
                        const SkeletonOptions& options);

// {"nodes":[{"position":[x,y,z],"radius":r,"sheet":false,"vertices":[...]}...],
//  "edges":[[i,j]...], "sheet_triangles":[[i,j,k]...], "reliability":..., "iterations":...,
//  "warnings":[...]}
std::string to_json(const Skeleton& skeleton);

// Wavefront OBJ: one `v` per node, `l` per edge, `f` per sheet triangle (1-based).
void write_obj(std::ostream& out, const Skeleton& skeleton);

// Independent cycles of the skeleton as a 2-complex (curve edges, sheet triangles and their
// edges): its first Betti number over Z/2, E - V + components - rank of the triangles'
// boundaries (= E - V + components - F unless sheets close around a void; never negative).
// For a curve skeleton (no sheets) this is the number of handles of the shape.
int cycle_count(const Skeleton& skeleton);

}  // namespace sdfkit::skeleton
