// Point-cloud readers: PLY (ascii and binary, extra properties, faces ignored), XYZ/CSV text,
// Sibernetic frame sets, directories and globs in file-name order; bad input is one InputError.
#include "scratch.hpp"

#include "sdfkit/core/error.hpp"
#include "sdfkit/pointcloud/pointcloud.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

namespace pc = sdfkit::pointcloud;
using sdfkit::test::ScratchDir;

TEST(PointcloudIo, AsciiPlyWithExtraPropertiesAndFaces) {
  ScratchDir d;
  const std::string p = d.write("a.ply",
                                "ply\nformat ascii 1.0\ncomment x\nelement vertex 3\nproperty float nx\nproperty float x\n"
                                "property float y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                "end_header\n9 1 2 3\n9 4 5 6\n9 7 8 9.5\n3 0 1 2\n");
  const auto pts = pc::read_point_cloud(p);
  ASSERT_EQ(pts.size(), 3u);
  EXPECT_EQ(pts[2], glm::vec3(7, 8, 9.5f));
}

TEST(PointcloudIo, BinaryPlyBothEndians) {
  ScratchDir d;
  for (bool big : {false, true}) {
    std::string header = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                         " 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nend_header\n";
    std::string body;
    for (float v : {1.0f, 2.0f, 3.0f, -4.0f, 5.0f, 6.5f}) {
      unsigned char b[4];
      std::memcpy(b, &v, 4);
      if (big) std::swap(b[0], b[3]), std::swap(b[1], b[2]);
      body.append(reinterpret_cast<char*>(b), 4);
      if (body.size() % 13 == 12) body.push_back('\x07');  // the colour after z
    }
    const std::string p = d.write(big ? "b.ply" : "l.ply", header + body);
    const auto pts = pc::read_point_cloud(p);
    ASSERT_EQ(pts.size(), 2u);
    EXPECT_EQ(pts[0], glm::vec3(1, 2, 3));
    EXPECT_EQ(pts[1], glm::vec3(-4, 5, 6.5f));
  }
}

TEST(PointcloudIo, TextFormatsAndErrors) {
  ScratchDir d;
  EXPECT_EQ(pc::read_point_cloud(d.write("a.xyz", "# c\n1 2 3\n\n4\t5\t6 # tail\n")).size(), 2u);
  const auto csv = pc::read_point_cloud(d.write("a.csv", "x,y,z\n1,2,3\n4,5,6\n"));
  ASSERT_EQ(csv.size(), 2u);
  EXPECT_EQ(csv[1], glm::vec3(4, 5, 6));
  EXPECT_THROW(pc::read_point_cloud(d.write("b.xyz", "1 2 3\n4 5\n")), sdfkit::InputError);
  EXPECT_THROW(pc::read_point_cloud(d.write("c.xyz", "1 2 nan\n")), sdfkit::InputError);
  EXPECT_THROW(pc::read_point_cloud(d.write("e.xyz", "")), sdfkit::InputError);
  EXPECT_THROW(pc::read_point_cloud(d.write("f.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n")),
               sdfkit::InputError);
  EXPECT_THROW(pc::read_point_cloud(d.path("missing.xyz")), sdfkit::InputError);
  // A mesh file is refused by name, not read as text (an OFF's "OFF" line and counts looked like a point).
  for (const char* name : {"m.off", "m.OBJ", "m.glb"})
    EXPECT_THROW(pc::read_point_cloud(d.write(name, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")), sdfkit::InputError) << name;
}

TEST(PointcloudIo, DirectoriesAndGlobsInNameOrder) {
  ScratchDir d;
  d.write("f10.xyz", "10 0 0\n");
  d.write("f02.xyz", "2 0 0\n");
  d.write("f01.xyz", "1 0 0\n");
  d.write("notes.md", "not a cloud\n");
  const pc::FrameSet dir = pc::read_frames(d.dir().string());
  ASSERT_EQ(dir.frames.size(), 3u);
  EXPECT_EQ(dir.frames[0][0].x, 1.0f);
  EXPECT_EQ(dir.frames[2][0].x, 10.0f);
  const pc::FrameSet glob = pc::read_frames((d.dir() / "f0?.xyz").string());
  ASSERT_EQ(glob.frames.size(), 2u);
  EXPECT_EQ(glob.names[1], "f02.xyz");
  EXPECT_THROW(pc::read_frames((d.dir() / "g*.xyz").string()), sdfkit::InputError);
  EXPECT_THROW(pc::read_frames((d.dir() / "nothing").string()), sdfkit::InputError);
}

TEST(PointcloudIo, SiberneticFrameSet) {
  const std::string worm = std::string(SDFKIT_SOURCE_DIR) + "/tests/data/worm";
  const pc::FrameSet shell = pc::read_frames(worm, true);
  const pc::FrameSet all = pc::read_frames(worm, false);
  ASSERT_EQ(all.frames.size(), 100u);
  EXPECT_EQ(all.frames[0].size(), 2290u);
  EXPECT_EQ(shell.frames[99].size(), 1421u);
  EXPECT_NEAR(all.frame_time, 0.016, 1e-9);
  // The first particles are shell particles: the same positions in both.
  EXPECT_EQ(shell.frames[5][0], all.frames[5][0]);
  // A truncated positions file is refused.
  ScratchDir d;
  std::filesystem::copy_file(worm + "/particles.txt", d.path("particles.txt"));
  d.write("positions_f32le.bin", std::string(2290 * 12 + 4, '\0'));
  EXPECT_THROW(pc::read_frames(d.dir().string()), sdfkit::InputError);
}
