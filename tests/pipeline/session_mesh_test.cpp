// One copy of the mesh (issue 15, memory at 13M triangles): a Session keeps the mesh it is given
// and shares that object with its backend (set_shared_mesh) instead of copying it, and the
// pipeline moves an asset's mesh into the session. Checked by buffer address with a recording
// backend, without a device; run_compute's files against write_field of the full asset.
#include "scratch.hpp"

#include "sdfkit/core/shapes.hpp"
#include "sdfkit/pipeline.hpp"
#include "sdfkit/session.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <memory>

using namespace sdfkit;

namespace {

// Records what the session hands over; every point gets the value 1 with one kept ray.
class RecordingBackend final : public SdfBackend {
public:
  std::string name() const override { return "recording"; }
  std::string device_name() const override { return "none"; }
  void set_mesh(const Mesh& m) override { ++copies, triangles_seen = m.triangles.data(); }
  void set_shared_mesh(std::shared_ptr<const Mesh> m) override {
    if (!share) return SdfBackend::set_shared_mesh(std::move(m));
    triangles_seen = m->triangles.data();
    held = std::move(m);
  }
  void release_mesh() override { held.reset(); }
  void update_positions(std::span<const glm::vec3> p) override { positions_moved = p.size(); }
  // 1 everywhere, or with `distinct` each point's own value (its x + 2y + 3z + 10).
  RawSdf compute(const SdfQuery& q, const SdfOptions&) override {
    RawSdf raw{std::vector<float>(q.size(), 1.0f), std::vector<std::uint32_t>(q.size(), 1u)};
    if (distinct)
      for (std::size_t i = 0; i < q.size(); ++i) raw.values[i] = q.origins[i].x + 2 * q.origins[i].y + 3 * q.origins[i].z + 10;
    return raw;
  }

  bool share = true;  // false: the default set_shared_mesh (a backend that copies)
  bool distinct = false;
  int copies = 0;
  std::size_t positions_moved = 0;
  const Triangle* triangles_seen = nullptr;
  std::shared_ptr<const Mesh> held;
};

Session recording_session(RecordingBackend*& out, bool share = true) {
  auto backend = std::make_unique<RecordingBackend>();
  backend->share = share;
  out = backend.get();
  return Session(std::move(backend));
}

}  // namespace

TEST(SessionMesh, MovedInMeshIsSharedWithTheBackendNotCopied) {
  RecordingBackend* backend = nullptr;
  Session session = recording_session(backend);
  Mesh mesh = shapes::icosphere(1.0f, 2);
  const Triangle* triangles = mesh.triangles.data();
  const glm::vec3* positions = mesh.positions.data();
  session.set_mesh(std::move(mesh));
  EXPECT_EQ(backend->copies, 0);
  EXPECT_EQ(backend->triangles_seen, triangles);
  ASSERT_TRUE(backend->held);
  EXPECT_EQ(backend->held.get(), &session.mesh());  // one object, not an equal copy
  EXPECT_EQ(session.mesh().positions.data(), positions);

  // update_positions moves the session's own vertices in place; the backend is told.
  std::vector<glm::vec3> moved(session.mesh().positions.size(), glm::vec3(0.5f));
  session.update_positions(moved);
  EXPECT_EQ(backend->positions_moved, moved.size());
  EXPECT_EQ(backend->held->positions, moved);
  EXPECT_EQ(backend->held->triangles.data(), triangles);
}

// A backend that keeps its own copy (the default set_shared_mesh) still works.
TEST(SessionMesh, CopyingBackendKeepsWorking) {
  RecordingBackend* backend = nullptr;
  Session session = recording_session(backend, false);
  Mesh mesh = shapes::icosphere(1.0f, 1);
  const Triangle* triangles = mesh.triangles.data();
  session.set_mesh(std::move(mesh));
  EXPECT_EQ(backend->copies, 1);
  EXPECT_EQ(backend->triangles_seen, triangles);  // set_mesh(*shared): a view of the same mesh
  const SdfField f = session.compute({});
  EXPECT_EQ(f.values, std::vector<float>(session.mesh().positions.size(), 1.0f));
}

// The pipeline moves the asset's mesh into the session: the backend computes on the asset's
// own buffers, the session keeps them (a later compute uses them), and the result's asset gets
// an equal mesh back after the computation.
TEST(SessionMesh, PipelineMovesTheAssetsMeshIntoTheSession) {
  RecordingBackend* backend = nullptr;
  Session session = recording_session(backend);
  io::Asset asset = load_input("builtin:sphere");
  const Triangle* triangles = asset.mesh.triangles.data();
  const Mesh original = asset.mesh;
  ComputeRequest request;
  request.input = "builtin:sphere";
  const ComputeResult r = compute_asset(request, std::move(asset), [&]() -> Session& { return session; });
  EXPECT_EQ(backend->copies, 0);
  EXPECT_EQ(backend->triangles_seen, triangles);
  ASSERT_TRUE(session.has_mesh());
  EXPECT_EQ(session.mesh().triangles.data(), triangles);
  EXPECT_EQ(backend->held.get(), &session.mesh());
  EXPECT_EQ(r.asset.mesh.triangles, original.triangles);
  EXPECT_EQ(r.asset.mesh.positions, original.positions);
  EXPECT_EQ(r.field.values.size(), original.positions.size());
}

// run_compute writes PLY and txt from an asset without its input copy where welding merged
// nothing (sphere), and from the full asset otherwise (tube, welded at its seams): either way
// the file is byte for byte what write_field makes of the full asset.
TEST(SessionMesh, RunComputeWritesWhatTheFullAssetWrites) {
  const test::ScratchDir dir;
  const auto bytes = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  for (const std::string shape : {"sphere", "tube"})
    for (const std::string ext : {"ply", "txt"}) {
      RecordingBackend* backend = nullptr;
      Session session = recording_session(backend);
      backend->distinct = true;
      ComputeRequest request;
      request.input = "builtin:" + shape;
      request.output = dir.path(shape + "-run." + ext);
      run_compute(request, session);
      // The caller's session keeps what update_positions needs (only the one-shot run_compute,
      // whose session goes with it, has its backend release the mesh).
      EXPECT_TRUE(backend->held) << shape << "." << ext;
      request.output.clear();
      const ComputeResult full = compute_asset(request, [&]() -> Session& { return session; });
      ASSERT_FALSE(full.asset.input_positions.empty());
      const std::string expected = dir.path(shape + "-full." + ext);
      io::write_field(expected, full.asset, full.field);
      const std::string got = bytes(dir.path(shape + "-run." + ext));
      EXPECT_GT(got.size(), 1000u) << shape << "." << ext;
      EXPECT_EQ(got, bytes(expected)) << shape << "." << ext;
    }
}
