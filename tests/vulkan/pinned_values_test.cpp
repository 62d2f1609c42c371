// The depth-peeling backend's values on fixed meshes, pinned (see pinned.hpp): both peel modes,
// both false-hit rules, an open and a closed mesh.
#include "depth_peel_test_util.hpp"

#include "pinned.hpp"

#include "sdfkit/vulkan/depth_peel.hpp"

namespace sdfkit::vk {
namespace {

struct Case {
  PeelMode mode;
  FalseHitRule rule;
  bool open;
};

TEST(DepthPeelPinned, ValuesOfFixedMeshesAreUnchanged) {
  const Case cases[] = {
      {PeelMode::Layers, FalseHitRule::Paper, true},       {PeelMode::Layers, FalseHitRule::Cgal, true},
      {PeelMode::FragmentLists, FalseHitRule::Paper, true}, {PeelMode::FragmentLists, FalseHitRule::Cgal, true},
      {PeelMode::Layers, FalseHitRule::Paper, false},      {PeelMode::FragmentLists, FalseHitRule::Cgal, false},
  };
  const test::Pinned pinned[] = {
      // layers paper open
      {1635.07544, 800, {2.02103519f, 1.95308173f, 1.90329492f, 1.88381541f, 2.18587637f, 1.98659313f}},
      // layers cgal open
      {1564.72936, 800, {2.00886297f, 1.88587952f, 1.84835005f, 1.8589958f, 1.98659718f, 1.93329418f}},
      // lists paper open
      {1634.16823, 800, {2.02103519f, 1.95308173f, 1.90329492f, 1.88381541f, 2.18587637f, 1.98659313f}},
      // lists cgal open
      {1563.50296, 800, {2.00886297f, 1.88587952f, 1.84835005f, 1.8589958f, 1.98659718f, 1.93329418f}},
      // layers paper closed
      {1603.23581, 800, {2.01526856f, 1.90463686f, 1.90690148f, 1.88718891f, 2.18693161f, 2.04962301f}},
      // lists cgal closed
      {1564.36157, 800, {2.00383401f, 1.85048926f, 1.83015025f, 1.85890174f, 2.01911211f, 1.98021364f}},
  };
  const Mesh open = test::open_torus();
  const Mesh closed = shapes::torus(3.0f, 1.0f, 40, 20);
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    const Case& c = cases[i];
    DepthPeelConfig cfg;
    cfg.views = 32;
    cfg.resolution = 128;
    cfg.mode = c.mode;
    auto be = test::make_test_backend(cfg);
    if (!be) GTEST_SKIP() << "no Vulkan device";
    const Mesh& mesh = c.open ? open : closed;
    be->set_mesh(mesh);
    SdfOptions o;
    o.false_hit = c.rule;
    const RawSdf got = be->compute(make_query(mesh, SdfDomain::Vertex), o);
    test::expect_pinned(got, pinned[i],
                        std::string(c.mode == PeelMode::Layers ? "layers " : "lists ") +
                            (c.rule == FalseHitRule::Paper ? "paper " : "cgal ") + (c.open ? "open" : "closed"));
    SDFKIT_EXPECT_NO_VALIDATION_MESSAGES(be->context());
  }
}

}  // namespace
}  // namespace sdfkit::vk
