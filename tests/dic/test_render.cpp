// Rendering DEM frames for DIC: exact ground truth for known rigid motions of the grains, and
// `granoscope render` end to end.
#include <gtest/gtest.h>

#include <unistd.h>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "hdf5_trajectory.hpp"
#include "image_io.hpp"
#include "render_frames.hpp"

namespace fs = std::filesystem;
using namespace gs::dic;

namespace {

// A slab of non-overlapping spheres (random sequential addition), d50 ~ 2 mm.
gs::Frame packing(int target, std::uint64_t seed) {
  gs::Frame f;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> x(0.0, 0.03), y(0.0, 0.006), z(0.0, 0.03),
      r(0.0008, 0.0012);
  for (int tries = 0; tries < 200000 && static_cast<int>(f.particles.size()) < target; ++tries) {
    gs::Particle p;
    p.position = {x(rng), y(rng), z(rng)};
    p.radius = r(rng);
    bool ok = true;
    for (const auto& q : f.particles)
      if ((q.position - p.position).norm() < q.radius + p.radius) {
        ok = false;
        break;
      }
    if (!ok) continue;
    p.id = static_cast<std::int64_t>(f.particles.size()) + 1;
    p.mass = 1e-5;
    f.particles.push_back(p);
  }
  f.domain.lo = {0, 0, 0};
  f.domain.hi = {0.03, 0.006, 0.03};
  return f;
}

}  // namespace

TEST(Render, TranslationGroundTruthAndImageShift) {
  const gs::Frame f0 = packing(250, 1);
  const Camera cam = make_camera(f0, View::Front, 20.0, 0.5, "test");
  EXPECT_GT(cam.rows, 200);
  gs::Frame f1 = f0;
  const double shift_px = 3.0;
  for (auto& p : f1.particles) p.position.x() += shift_px / cam.px_per_m;
  const GroundTruth gt = ground_truth(f0, f1, cam);
  int grains = 0, visible = 0;
  for (int r = 0; r < cam.rows; ++r)
    for (int c = 0; c < cam.cols; ++c) {
      if (gt.grain.at<int>(r, c) < 0) continue;
      ++grains;
      ASSERT_NEAR(gt.u.at<double>(r, c), shift_px, 1e-9);
      ASSERT_NEAR(gt.v.at<double>(r, c), 0.0, 1e-9);
      visible += gt.visible.at<std::uint8_t>(r, c);
    }
  EXPECT_GT(grains, cam.rows * cam.cols / 2);
  EXPECT_EQ(visible, grains);  // a common translation hides nothing
  RenderOptions ro;
  const cv::Mat a = render_frame(f0, cam, ro);
  const cv::Mat b = render_frame(f1, cam, ro);
  double diff = 0.0;
  int n = 0;
  for (int r = 0; r < cam.rows; ++r)
    for (int c = 0; c + 3 < cam.cols; ++c) {
      diff += std::abs(b.at<double>(r, c + 3) - a.at<double>(r, c));
      ++n;
    }
  EXPECT_LT(diff / n, 1e-6);
  // Texture is not flat: a natural speckle with spread grey levels.
  cv::Scalar mean, sd;
  cv::meanStdDev(a, mean, sd);
  EXPECT_GT(sd[0], 30.0);
}

TEST(Render, RotationAboutViewAxisMovesSurfacePointsRigidly) {
  gs::Frame f0;
  gs::Particle p;
  p.id = 7;
  p.radius = 0.001;
  p.mass = 1e-5;
  f0.particles.push_back(p);
  const Camera cam = make_camera(f0, View::Front, 40.0, 0.2, "test");
  gs::Frame f1 = f0;
  const double angle = 0.3;  // about +y (the view direction of the front view)
  f1.particles[0].orientation =
      Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()));
  const GroundTruth gt = ground_truth(f0, f1, cam);
  const Eigen::Vector2d centre = cam.to_pixel(p.position);
  int checked = 0;
  for (int r = 0; r < cam.rows; ++r)
    for (int c = 0; c < cam.cols; ++c) {
      if (gt.grain.at<int>(r, c) != 0) continue;
      // In image axes (x right = lab x, y down = -lab z) a rotation about +y by angle turns
      // (x, y) into (x cos + y sin ..); compute it from the lab rotation directly.
      const double dx = (c - centre.x()) / cam.px_per_m, dz = -(r - centre.y()) / cam.px_per_m;
      const Eigen::Vector3d rel(dx, 0.0, dz);
      const Eigen::Vector3d moved = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()) * rel;
      EXPECT_NEAR(gt.u.at<double>(r, c), (moved.x() - dx) * cam.px_per_m, 1e-9);
      EXPECT_NEAR(gt.v.at<double>(r, c), -(moved.z() - dz) * cam.px_per_m, 1e-9);
      ++checked;
    }
  EXPECT_GT(checked, 1000);
}

TEST(Render, CliWritesFramesAndGroundTruth) {
  const fs::path dir =
      fs::temp_directory_path() / ("gs_render_cli_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  gs::Trajectory t;
  t.metadata.code_version = gs::code_version();
  t.metadata.provenance = "test";
  gs::Frame f0 = packing(120, 2);
  gs::Frame f1 = f0;
  f1.step = 1;
  f1.time = 1.0;
  for (auto& q : f1.particles) q.position.x() += 0.0002 * (q.position.z() / 0.03);  // simple shear
  t.frames = {f0, f1};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  const std::string bin = std::string(GS_BINARY_DIR) + "/bin/granoscope";
  const std::string cmd = bin + " render " + (dir / "run.h5").string() + " --px-per-d50 12 -o " +
                          (dir / "frames").string() + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::exists(dir / "frames" / "frame_0000.png"));
  EXPECT_TRUE(fs::exists(dir / "frames" / "frame_0001.png"));
  EXPECT_TRUE(fs::exists(dir / "frames" / "ground_truth.h5"));
  const cv::Mat img = read_grey_image(dir / "frames" / "frame_0001.png");
  EXPECT_GT(img.rows, 100);
  const std::string bad = bin + " render " + (dir / "none.h5").string() + " -o " +
                          (dir / "frames").string() + " 2> /dev/null";
  EXPECT_EQ(WEXITSTATUS(std::system(bad.c_str())), 2);
  const std::string badview = bin + " render " + (dir / "run.h5").string() +
                              " --view diagonal -o " + (dir / "frames").string() + " 2> /dev/null";
  EXPECT_EQ(WEXITSTATUS(std::system(badview.c_str())), 2);
  fs::remove_all(dir);
}
