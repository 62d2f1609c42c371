#pragma once
// `sdfkit bench --batch N` (issue 15, thousands of assets): N cow-sized assets (CGAL's cow, 2904
// vertices and 5804 triangles, each under its own random similarity transform with a small
// vertex jitter, so no two files are alike) written as OFF, binary PLY and OBJ in turn, then one
// `sdfkit batch -j J` over them in its own process, and a second run that finds every result
// complete (the resume check). Reports the wall and CPU time, the load average, and the batch
// report's per-asset mean of every stage (load, weld, BVH build, upload, trace, write, record).

#include <nlohmann/json.hpp>

#include <string>

namespace sdfkit::bench {

struct BatchBenchOptions {
  int assets = 1000;
  int jobs = 2;
  std::string backend = "opencl";  // batch --backend
  std::string format = "txt";      // batch --format
  int rays = 30;
  std::string work_dir;            // assets in <work_dir>/batch-assets-N, results in batch-out
  std::string sdfkit;              // the sdfkit executable
};

// Generates the assets (unless present), runs the batch twice; returns the JSON record and
// fills `markdown` with a table row set.
nlohmann::json run_batch_bench(const BatchBenchOptions& o, std::string& markdown);

}  // namespace sdfkit::bench
