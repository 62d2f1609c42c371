#pragma once
// `sdfkit bench --huge`: CGAL's armadillo subdivided to millions of triangles (midpoint
// subdivision, levels 3 and 4: 3.3M and 13.3M triangles), written as binary PLY and OBJ, each
// run through `sdfkit compute --json` in its own process; the table has the time and the
// process's peak resident memory of every stage (load = read + weld, BVH build, upload, trace,
// write) from the run's JSON report.

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace sdfkit::bench {

struct HugeOptions {
  std::string work_dir;            // meshes and outputs go here (1.2 GB for level 4)
  std::vector<int> levels = {3, 4};
  std::vector<std::string> formats = {"ply", "obj"};
  std::string backend = "opencl";  // passed to sdfkit compute --backend
  std::string sdfkit;              // the sdfkit executable
  int rays = 30;
};

// Writes `name`-subdiv<L>.{ply,obj} under work_dir unless present (same size as before);
// returns the path for (level, format).
std::string huge_mesh_path(const HugeOptions& o, int level, const std::string& format);
void generate_huge_meshes(const HugeOptions& o);

// Runs every (level, format); returns {"runs": [...]} and fills `markdown`.
nlohmann::json run_huge(const HugeOptions& o, std::string& markdown);

}  // namespace sdfkit::bench
