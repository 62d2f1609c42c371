// A file whose faces are wound every which way (a polygon soup's export, CGAL's *-shuffled test
// meshes) or inside out gives the SDF of the solid it bounds: load_asset orients the welded mesh
// (orient_outward), so the values equal those of the same file wound right. The control: the
// same faces computed as given are far off.
#include "mesh_text.hpp"
#include "scratch.hpp"

#include "sdfkit/core/sdf.hpp"
#include "sdfkit/core/shapes.hpp"
#include "sdfkit/io/asset.hpp"
#include "sdfkit/reference/embree_backend.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace sdfkit;

namespace {

std::vector<float> sdf_of(const Mesh& m) {
  reference::EmbreeBackend backend;
  backend.set_mesh(m);
  return compute_sdf(backend, m, SdfOptions{}).values;
}

double max_relative_difference(const std::vector<float>& a, const std::vector<float>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    d = std::max(d, std::fabs(static_cast<double>(a[i]) - b[i]) / std::max(1e-6, std::fabs(static_cast<double>(b[i]))));
  return d;
}

}  // namespace

TEST(Orientation, MixedAndInvertedWindingsGiveTheSolidsSdf) {
  test::ScratchDir dir;
  const Mesh good = shapes::torus(2.0f, 0.6f, 64, 32);
  const std::vector<float> expected = sdf_of(good);

  Mesh mixed = good;
  std::mt19937 rng(11);
  for (Triangle& t : mixed.triangles)
    if (rng() & 1u) std::swap(t[1], t[2]);
  Mesh inside_out = good;
  for (Triangle& t : inside_out.triangles) std::swap(t[1], t[2]);

  for (const auto& [name, bad] : {std::pair{"mixed.off", mixed}, std::pair{"inside_out.off", inside_out}}) {
    const io::Asset a = io::load_asset(dir.write(name, test::off_text(bad)));
    ASSERT_EQ(a.mesh.positions.size(), good.positions.size()) << name;
    EXPECT_EQ(a.mesh.triangles, good.triangles) << name;
    EXPECT_GT(a.flipped_faces, 0u) << name;
    ASSERT_EQ(a.warnings.size(), 1u) << name;
    EXPECT_NE(a.warnings[0].find("flipped"), std::string::npos) << a.warnings[0];
    // The file's own winding is kept for writing back.
    EXPECT_EQ(a.input_triangles, bad.triangles) << name;
    // Float rounding of the normals' sums only (the corners of a flipped face add in another order).
    EXPECT_LT(max_relative_difference(sdf_of(a.mesh), expected), 1e-4) << name;
    // Control: computed as wound in the file, the values are wrong somewhere by far more.
    EXPECT_GT(max_relative_difference(sdf_of(bad), expected), 0.5) << name;
  }
}
