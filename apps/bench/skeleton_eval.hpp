#pragma once
// sdfkit_skeleton_bench --eval DIR: the skeleton evaluation over every closed mesh of a data set
// (CGAL's data/ by default) and the procedural models, side by side with CGAL's
// Mean_curvature_flow_skeletonization. See skeleton_eval.cpp.

#include "sdfkit/core/sdf.hpp"

#include <cstddef>
#include <string>

struct SkeletonEvalArgs {
  std::string dir;                    // searched recursively for .off / .obj / .ply files
  std::size_t max_vertices = 100000;  // larger meshes are listed as skipped
  std::string filter;                 // comma-separated substrings: only meshes whose name contains one
  std::string dump;                   // when set: write both skeletons as OBJ files here
  bool no_sdf_run = true;             // also run with the SDF terms off
  // When set: CGAL's skeleton of each mesh is read from DIR/<stem>.cgal.obj (an earlier run's
  // --dump) instead of being computed, so two versions of ours are compared against the same
  // CGAL skeleton (CGAL's MCF differs from run to run); CGAL's time is then not known ("–").
  std::string cgal_dir;
  bool procedural = true;             // also evaluate the procedural models
  // When > 0: CGAL gets an isotropically remeshed copy of each mesh (target edge length this
  // fraction of the bounding-box diagonal, or the mesh's mean edge length where that is
  // shorter; CGAL's isotropic_remeshing) instead of the mesh as it is: MCF moves vertices along
  // the surface's own triangles, and on a coarse CAD mesh (a box of 8 vertices) it collapses to
  // a stub. CGAL's time is then its MCF's on the denser mesh (remeshing not timed).
  double cgal_remesh = 0.0;
};

// Prints the per-mesh table, the list of skipped files and a summary; returns the exit code.
int run_skeleton_eval(const SkeletonEvalArgs& args, sdfkit::SdfBackend& backend);
