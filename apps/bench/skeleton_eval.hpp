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
  bool procedural = true;             // also evaluate the procedural models
};

// Prints the per-mesh table, the list of skipped files and a summary; returns the exit code.
int run_skeleton_eval(const SkeletonEvalArgs& args, sdfkit::SdfBackend& backend);
