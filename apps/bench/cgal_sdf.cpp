// Benchmark helper, not part of the library: CGAL's sdf_values on an OFF mesh, timed.
// CGAL is GPL-licensed; this program exists only so `sdfkit-bench` can run it side by side as a
// separate process. Prints one JSON object: {"mesh":..., "faces":..., "rays":..., "seconds":...}.
// Usage: sdfkit-cgal-sdf MESH.off [RAYS=25] [VALUES_OUT.txt]
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/mesh_segmentation.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Face = SurfaceMesh::Face_index;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s MESH.off [RAYS] [VALUES_OUT.txt]\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  const int rays = argc > 2 ? std::stoi(argv[2]) : 25;
  SurfaceMesh mesh;
  std::ifstream in(path);
  if (!in || !(in >> mesh) || !CGAL::is_triangle_mesh(mesh)) {
    std::fprintf(stderr, "sdfkit-cgal-sdf: error: %s: not a triangle mesh CGAL can read\n", path.c_str());
    return 1;
  }
  auto sdf = mesh.add_property_map<Face, double>("f:sdf", 0.0).first;
  const auto start = std::chrono::steady_clock::now();
  // The default cone of sdf_values is 2/3 pi (120 degrees); no post-processing (raw values).
  CGAL::sdf_values(mesh, sdf, 2.0 / 3.0 * CGAL_PI, rays, false);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (argc > 3) {
    std::ofstream out(argv[3]);
    for (Face f : mesh.faces()) out << sdf[f] << '\n';
  }
  std::printf("{\"mesh\": \"%s\", \"faces\": %zu, \"rays\": %d, \"seconds\": %.6f}\n", path.c_str(),
              static_cast<std::size_t>(mesh.number_of_faces()), rays, seconds);
  return 0;
}
