// The OpenCL backend's values on a fixed open mesh, pinned (see pinned.hpp): both false-hit
// rules, every tracer.
#include "device_fixture.hpp"

#include "pinned.hpp"

namespace sdfkit {
namespace {

TEST(OpenClPinned, ValuesOfAFixedMeshAreUnchanged) {
  const test::Pinned pinned[] = {
      // bundles paper
      {1601.70488, 800, {2.02373147f, 2.08984518f, 1.98978007f, 1.98106933f, 2.00729966f, 2.0689075f}},
      // bundles cgal
      {1564.62397, 800, {2.01742458f, 2.02513289f, 1.9103024f, 1.95241427f, 1.93625605f, 1.98550844f}},
      // single paper
      {1601.70488, 800, {2.02373147f, 2.08984518f, 1.98978007f, 1.98106933f, 2.00729966f, 2.0689075f}},
      // single cgal
      {1564.62397, 800, {2.01742458f, 2.02513289f, 1.9103024f, 1.95241427f, 1.93625605f, 1.98550844f}},
      // octree paper
      {1601.70488, 800, {2.02373147f, 2.08984518f, 1.98978007f, 1.98106933f, 2.00729966f, 2.0689075f}},
      // octree cgal
      {1564.62397, 800, {2.01742458f, 2.02513289f, 1.9103024f, 1.95241427f, 1.93625605f, 1.98550844f}},
  };
  const Mesh mesh = test::open_torus();
  const SdfQuery query = make_query(mesh, SdfDomain::Vertex);
  std::size_t i = 0;
  for (const test::Tracer tracer : {test::Tracer::BvhBundles, test::Tracer::BvhSingle, test::Tracer::Octree}) {
    SDFKIT_REQUIRE_CL_ACCEL(backend, tracer);
    backend.set_mesh(mesh);
    for (const FalseHitRule rule : {FalseHitRule::Paper, FalseHitRule::Cgal}) {
      SdfOptions o;
      o.false_hit = rule;
      test::expect_pinned(backend.compute(query, o), pinned[i++],
                          std::string(test::tracer_name(tracer)) + (rule == FalseHitRule::Paper ? " paper" : " cgal"));
    }
  }
}

}  // namespace
}  // namespace sdfkit
