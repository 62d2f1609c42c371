#pragma once
// Linear skeletons of unoriented point clouds (the paper's section 5.3): PCA normals, MST
// orientation, a tangent-plane Delaunay surface, the SDF per point, points shifted inward by
// half their SDF, and agglomerative clustering into an ordered polyline. Each step is its own
// function; point_cloud_skeleton() chains them. All lengths are in the cloud's model units.

#include "sdfkit/core/mesh.hpp"
#include "sdfkit/core/sdf.hpp"

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace sdfkit::pointcloud {

// ---- Step 1: neighbours and normals ---------------------------------------------------------

// The k nearest neighbours of every point (itself excluded), nearest first, from a k-d tree
// (nanoflann). index and dist2 are n*k entries, row i = point i; dist2 in squared model units.
// When the cloud has k or fewer points, k is lowered to n - 1.
struct Neighbours {
  int k = 0;
  std::vector<std::uint32_t> index;
  std::vector<float> dist2;
  std::span<const std::uint32_t> of(std::size_t i) const {
    return {index.data() + i * static_cast<std::size_t>(k), static_cast<std::size_t>(k)};
  }
};
// Default k for normals, orientation and the local surfaces, chosen by measurement on the
// shared worm frames (engine/pointcloud/README.md: k = 8 gave ambiguous normals on the thin tail,
// 16 and more smoothed the tips and cost time).
inline constexpr int kDefaultNeighbours = 12;
Neighbours k_nearest(std::span<const glm::vec3> points, int k);
// The first k of every row (k <= nb.k): a sparser graph from the same search.
Neighbours first_neighbours(const Neighbours& nb, int k);

// Unit normals, unoriented: the eigenvector of the smallest eigenvalue of the covariance of
// each point with its k neighbours. n entries.
std::vector<glm::vec3> pca_normals(std::span<const glm::vec3> points, const Neighbours& nb);

// ---- Step 2: orientation ----------------------------------------------------------------------

struct Orientation {
  std::vector<glm::vec3> normals;       // n unit normals pointing out of the surface
  std::uint32_t seed = 0;               // the topmost point along `up_axis`
  std::vector<std::uint32_t> ambiguous; // points whose MST edge had |n_i . n_j| < 0.5
  std::size_t components = 1;           // connected parts of the neighbour graph (each seeded)
};
// Hoppe 1992: the point with the largest coordinate along up_axis (0 = x, 1 = y, 2 = z) gets the
// normal that points +up_axis; the sign is propagated over the minimum spanning tree of the
// symmetric neighbour graph weighted 1 - |n_i . n_j|. Each connected part is seeded the same way.
Orientation orient_normals_mst(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                               const Neighbours& nb, int up_axis = 1);

// ---- Step 3: surface --------------------------------------------------------------------------

// Bowyer-Watson Delaunay triangulation of 2D points (x, y), as index triples, counter-clockwise.
// Duplicate points are skipped. Exposed for tests.
std::vector<std::array<std::uint32_t, 3>> delaunay_2d(std::span<const float> xy);

// The star of the origin in the Delaunay triangulation of {origin} + the 2D points xy (x, y):
// the pairs (i, j) of neighbours such that (origin, i, j) is a counter-clockwise Delaunay
// triangle, found as the origin's Voronoi cell (the neighbours' bisectors clipping a square far
// outside them). O(k^2) for k neighbours; agrees with delaunay_2d's triangles at the origin
// (tested). The origin on the hull of its neighbours gets an open star.
std::vector<std::array<std::uint32_t, 2>> delaunay_star(std::span<const float> xy);

// Per point: its k neighbours projected on its tangent plane, a 2D Delaunay triangulation, and
// the triangles of the point's own star, oriented by the point's normal, copied into one global
// triangle soup (closed, not necessarily manifold). Identical triangles (same three points) are
// kept once when `deduplicate`. positions = points.
Mesh tangent_plane_surface(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                           const Neighbours& nb, bool deduplicate = true);

// ---- Step 4: SDF and inward shift -------------------------------------------------------------

// The SDF at every point (model units), from rays cast inward (against `normals`) at the
// surface. Calls backend.set_mesh(surface). Points without a kept ray get their neighbours'
// mean (finish_field).
std::vector<float> point_sdf(SdfBackend& backend, const Mesh& surface, std::span<const glm::vec3> normals,
                             const SdfOptions& options);

// Per point, the median of its own and its neighbours' SDF values (nb's k neighbours): a single
// ray bundle that escaped through a gap of the soup (or hit a far part of the body) makes an
// isolated outlier, which the median removes while a smooth field is kept (a linear field is
// unchanged where the neighbourhood is symmetric).
std::vector<float> median_filter(std::span<const float> sdf, const Neighbours& nb);

// p_i - n_i * sdf_i / 2: the points moved onto the medial curve.
std::vector<glm::vec3> shift_inward(std::span<const glm::vec3> points, std::span<const glm::vec3> normals,
                                    std::span<const float> sdf);

// ---- Step 5: clustering into a polyline -------------------------------------------------------

enum class Linkage {
  Single,   // cluster distance = shortest point distance
  Average,  // root mean square of all point-to-point distances (exact from cluster moments)
};

// Agglomerative clustering constrained to the neighbour graph: adjacent clusters are merged in
// order of linkage distance. The full merge sequence is kept once, so that any threshold t can
// be applied in O(n): the clustering at t stops at the first merge whose distance exceeds t.
class MergeTree {
public:
  MergeTree(std::span<const glm::vec3> points, const Neighbours& connectivity, Linkage linkage);
  // Clusters left when merging stops at threshold t (monotone non-increasing in t).
  std::size_t cluster_count(float t) const;
  // Per point, its cluster id in [0, cluster_count(t)).
  std::vector<std::uint32_t> labels(float t) const;
  // The state after the first m merges of the sequence, as labels.
  std::vector<std::uint32_t> labels_after(std::size_t merges) const;
  // The thresholds [lo, hi) that stop with exactly `count` clusters; lo >= hi when no threshold
  // gives that count (the sequence's distance at that step was below an earlier one). Found by
  // binary search over the sequence's running maximum.
  std::pair<float, float> threshold_range(std::size_t count) const;
  std::size_t point_count() const { return n_; }
  std::size_t merge_count() const { return merges_.size(); }
  // The linkage distance of every merge, in merge order.
  std::span<const float> merge_heights() const { return heights_; }

private:
  std::size_t n_ = 0;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> merges_;  // in order
  std::vector<float> heights_;                                   // per merge
  std::vector<float> prefix_max_;                                // max merge distance so far
};

struct Node {
  glm::vec3 position{0.0f};
  float radius = 0.0f;  // mean SDF / 2 of the node's points
};
struct Polyline {
  std::vector<Node> nodes;  // ordered from one end to the other
  std::size_t segments() const { return nodes.empty() ? 0 : nodes.size() - 1; }
  float length() const;
};

// Orders clusters into a polyline: cluster centroids, the clusters' adjacency over the neighbour
// graph, its minimum spanning tree, and the tree's longest path. Clusters off the path are
// folded into the path cluster they hang from. radius = mean of sdf/2 over the node's points.
Polyline order_clusters(std::span<const glm::vec3> shifted, std::span<const float> sdf,
                        std::span<const std::uint32_t> labels, const Neighbours& connectivity);

// Binary search for the threshold t in [min sdf, max sdf] that gives exactly `segments` + 1
// ordered nodes. exact = false (and the nearest count found) when no t gives it.
struct SegmentSearch {
  Polyline polyline;
  float threshold = 0.0f;
  bool exact = false;
  int iterations = 0;
};
SegmentSearch polyline_with_segments(std::span<const glm::vec3> shifted, std::span<const float> sdf,
                                     const MergeTree& tree, const Neighbours& connectivity, int segments);

// The polyline resampled at `nodes` points equally spaced by arc length (ends kept); radii
// interpolated linearly.
Polyline resample(const Polyline& polyline, int nodes);

// Reverses polylines so that consecutive frames keep the same end first: frame f is reversed
// when its ends match frame f-1's ends better swapped. Returns how many were reversed.
std::size_t orient_sequence(std::vector<Polyline>& frames);

// Mean distance from points sampled every `step` along `a` (and its nodes) to polyline `b`.
float mean_distance(const Polyline& a, const Polyline& b, float step);
// Distance from p to the polyline (segments), model units.
float distance_to_polyline(const glm::vec3& p, const Polyline& line);

// ---- The whole pipeline -----------------------------------------------------------------------

struct SkeletonOptions {
  int neighbours = kDefaultNeighbours;
  int up_axis = 1;
  int cluster_neighbours = 6;  // the clustering's graph: the first of the k neighbours
  // 0 = every point. Otherwise a cloud with more points runs the whole pipeline on this many,
  // drawn uniformly at random (fixed seed): a 30k-point worm gives the same polyline from 4k
  // points (bench/RESULTS.md) at a fraction of the time.
  std::size_t max_points = 0;
  int segments = 0;  // 0 = threshold mode
  float threshold = 0.0f;  // used when segments == 0; 0 = the mean SDF
  Linkage linkage = Linkage::Average;
  // 16 rays, then the neighbours' median (`median`). The median removes isolated outliers that
  // pulled 30k-point synthetic worms' polylines (worst 0.26 % -> 0.18 %); the worm's 100 frames
  // are unchanged (0.194 %). 8 rays with the median were as accurate on the worm and at 30k but
  // shortened one 2000-point synthetic worm's polyline below 85 % of its length (the tips), so
  // 16 stay (sdfkit_pointcloud_bench --rays, --no-median).
  SdfOptions sdf{16, kDefaultConeDegrees, SdfDomain::Vertex, FalseHitRule::Paper};
  // The SDF's median over each point's neighbours before the shift (median_filter).
  bool median = true;
};
struct StepTime {
  std::string step;
  double milliseconds = 0.0;      // wall clock
  double cpu_milliseconds = 0.0;  // the process's CPU time over all its threads (PoCL's too)
};
struct SkeletonResult {
  Polyline polyline;
  std::vector<std::uint32_t> sample;  // with max_points: the input indices used (else empty)
  std::vector<glm::vec3> normals;  // oriented (per used point: see `sample`)
  std::vector<float> sdf;
  std::vector<glm::vec3> shifted;
  std::vector<std::uint32_t> ambiguous;
  std::size_t surface_triangles = 0;
  float threshold = 0.0f;
  bool exact = true;  // segments mode: exactly `segments` segments were found
  std::vector<StepTime> times;
};
// Throws InputError for fewer than 8 points, non-finite coordinates or options out of range.
SkeletonResult point_cloud_skeleton(std::span<const glm::vec3> points, SdfBackend& backend,
                                    const SkeletonOptions& options);
void validate_options(const SkeletonOptions& options);

// A sequence of frames: every frame's skeleton, then orient_sequence() so that the same end
// comes first in every frame, and each polyline resampled at `subdivided_nodes` (0 = none).
struct SequenceSkeleton {
  std::vector<SkeletonResult> frames;
  std::vector<Polyline> subdivided;
  std::size_t reversed = 0;             // frames whose polyline was reversed to match the previous
  std::vector<std::size_t> inexact;     // frames where no threshold gave exactly `segments`
  std::vector<std::size_t> ambiguous;   // per frame, the number of ambiguous normals
};
SequenceSkeleton skeleton_sequence(const std::vector<std::vector<glm::vec3>>& frames, SdfBackend& backend,
                                   const SkeletonOptions& options, int subdivided_nodes = 0);

// The JSON document: {"nodes": [{"position": [x,y,z], "radius": r}, ...], ...} for one frame, or
// {"frames": [{"name", "nodes", ...}, ...], ...} for several; "subdivided" nodes when asked.
std::string skeleton_json(const SequenceSkeleton& seq, const std::vector<std::string>& names,
                          const SkeletonOptions& options);

// ---- Input --------------------------------------------------------------------------------------

// One point cloud: PLY (vertex x y z only is read; ascii or binary little/big endian), XYZ/CSV
// text (three numbers per line separated by spaces, tabs or commas; '#' comments and a non-numeric
// header line are skipped). Throws InputError with the path for anything else.
std::vector<glm::vec3> read_point_cloud(const std::string& path);

// A sequence of frames, every frame's points in the same order where the source guarantees it:
//  * a Sibernetic frame set (a directory with positions_f32le.bin and particles.txt, as in
//    shared/worm): `surface_only` keeps the shell == 1 particles, else all of them;
//  * a directory of .ply/.xyz/.csv/.txt files, in file-name order;
//  * a glob pattern ('*' and '?' in the file-name part) over such files;
//  * a single file (one frame).
struct FrameSet {
  std::vector<std::vector<glm::vec3>> frames;
  std::vector<std::string> names;  // file names or "frame N"
  double frame_time = 0.0;         // seconds between frames when the source says (Sibernetic)
};
FrameSet read_frames(const std::string& source, bool surface_only = true);

// ---- Synthetic worms ----------------------------------------------------------------------------

// A tube of radius r(s) = max_radius * (taper profile: sqrt-shaped ends) around a planar curve
// of the given length (a sine wave of `wave_amplitude` and `waves` periods along x, in the x-z
// plane), with hemispherical-ish closed tips. Points sampled uniformly in (s, angle) with
// Gaussian noise of `noise` model units along the normal. midline = the exact axis curve.
struct SyntheticWorm {
  std::vector<glm::vec3> points;
  Polyline midline;  // 201 nodes on the exact axis, radius = tube radius there
  float length = 0.0f;
};
struct WormShape {
  float length = 150.0f;
  float max_radius = 5.0f;
  float wave_amplitude = 20.0f;
  float waves = 1.0f;
  float phase = 0.0f;  // radians, the wave's phase (animate by changing it)
  float noise = 0.05f;
  std::size_t points = 2000;
  std::uint32_t seed = 1;
};
SyntheticWorm synthetic_worm(const WormShape& shape);

}  // namespace sdfkit::pointcloud
