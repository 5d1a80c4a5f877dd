// Rendering DEM frames for DIC: exact ground truth for known rigid motions of the grains, and
// `granoscope render` end to end: the written images and ground_truth.h5 are read back and
// compared with what the input positions and radii imply (image size, pixel coverage of the
// sphere disks, bit depth, format, noise, supersampling), and `granoscope dic` on a rendered
// pair recovers the imposed motion.
#include <gtest/gtest.h>

#include <unistd.h>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include <sys/wait.h>

#include <algorithm>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "h5_read.hpp"
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

namespace {

namespace h5 = gs::test::h5;

struct CliRun {
  int rc;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream is(p, std::ios::binary);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

CliRun granoscope(const std::string& args, const fs::path& dir) {
  const auto o = dir / "stdout.txt", e = dir / "stderr.txt";
  const std::string cmd = std::string(GS_BINARY_DIR) + "/bin/granoscope " + args + " > " +
                          o.string() + " 2> " + e.string() + " < /dev/null";
  const int status = std::system(cmd.c_str());
  CliRun r{WIFEXITED(status) ? WEXITSTATUS(status) : 128, slurp(o), slurp(e)};
  fs::remove(o);
  fs::remove(e);
  return r;
}

class RenderCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("gs_render_cli_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override {  // GS_KEEP=1 keeps the frames
    if (!std::getenv("GS_KEEP")) fs::remove_all(dir);
  }
  std::string p(const std::string& name) const { return (dir / name).string(); }
  void write_run(const std::vector<gs::Frame>& frames) {
    gs::Trajectory t;
    t.metadata.provenance = "test";
    t.frames = frames;
    for (std::size_t k = 0; k < t.frames.size(); ++k) t.frames[k].step = static_cast<long>(k);
    gs::write_hdf5_trajectory(dir / "run.h5", t);
  }
  cv::Mat image(const std::string& name) const { return cv::imread(p(name), cv::IMREAD_UNCHANGED); }
  fs::path dir;
};

// The front-view camera the documentation describes, computed from the input alone: d50 = the
// median diameter by count (upper median), px_per_m = px_per_d50 / d50, a margin of margin_d50
// * d50 around the extent of the disks, and one more pixel than the extent covers.
struct ExpectedCamera {
  double d50, ppm, a0, b0;
  int rows, cols;
};

ExpectedCamera expected_front_camera(const gs::Frame& f, double px_per_d50, double margin_d50) {
  std::vector<double> d;
  for (const auto& q : f.particles) d.push_back(2.0 * q.radius);
  std::sort(d.begin(), d.end());
  ExpectedCamera c{};
  c.d50 = d[d.size() / 2];
  c.ppm = px_per_d50 / c.d50;
  double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
  for (const auto& q : f.particles) {
    amin = std::min(amin, q.position.x() - q.radius);
    amax = std::max(amax, q.position.x() + q.radius);
    bmin = std::min(bmin, q.position.z() - q.radius);
    bmax = std::max(bmax, q.position.z() + q.radius);
  }
  const double m = margin_d50 * c.d50;
  c.a0 = amin - m;
  c.b0 = bmax + m;
  c.cols = static_cast<int>(std::ceil((amax - amin + 2 * m) * c.ppm)) + 1;
  c.rows = static_cast<int>(std::ceil((bmax - bmin + 2 * m) * c.ppm)) + 1;
  return c;
}

// Index of the sphere whose disk (front view) contains lab point (a, z) and whose surface there
// is nearest the camera (smallest y of the visible cap), -1 for none.
int first_hit(const gs::Frame& f, double a, double b) {
  int best = -1;
  double best_depth = 1e300;
  for (int i = 0; i < static_cast<int>(f.particles.size()); ++i) {
    const auto& q = f.particles[static_cast<std::size_t>(i)];
    const double da = q.position.x() - a, db = q.position.z() - b;
    const double h2 = q.radius * q.radius - da * da - db * db;
    if (h2 < 0.0) continue;
    const double depth = q.position.y() - std::sqrt(h2);
    if (depth < best_depth) {
      best_depth = depth;
      best = i;
    }
  }
  return best;
}

// Per pixel, how many of the s x s supersampling rays (at x = c - 0.5 + (i + 0.5)/s) hit a disk.
cv::Mat hits(const gs::Frame& f, const ExpectedCamera& cam, int s) {
  cv::Mat h(cam.rows, cam.cols, CV_32S, cv::Scalar(0));
  for (int r = 0; r < cam.rows; ++r)
    for (int c = 0; c < cam.cols; ++c)
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) {
          const double x = c - 0.5 + (i + 0.5) / s, y = r - 0.5 + (j + 0.5) / s;
          h.at<int>(r, c) += first_hit(f, cam.a0 + x / cam.ppm, cam.b0 - y / cam.ppm) >= 0;
        }
  return h;
}

}  // namespace

// Exact answers from the input positions and radii: the image size and camera of
// ExpectedCamera; the ground-truth grain map equals, pixel for pixel, the first sphere hit at
// each pixel centre; an 8-bit PNG by default and a 16-bit one with --bits 16; and with
// --supersample s a pixel is exactly the background grey (15, i.e. 3855 in 16 bits) iff none of
// its s x s rays hits a disk, so the background pixel count is the count of such pixels.
// Supersampling antialiases the edges measurably: at s = 4 fewer pixels are pure background than
// at s = 1 (the edge pixels whose centre misses a disk but one of the 16 rays hits it; measured
// 34920 and 33849 background pixels).
TEST_F(RenderCli, SizeBitDepthAndDiskCoverageFollowTheInput) {
  const gs::Frame f0 = packing(60, 2);
  write_run({f0});
  const ExpectedCamera cam = expected_front_camera(f0, 12.0, 0.5);
  ASSERT_EQ(granoscope("render " + p("run.h5") + " --px-per-d50 12 -o " + p("d"), dir).rc, 0);
  for (int s : {1, 4}) {
    const std::string out = "s" + std::to_string(s);
    const CliRun r =
        granoscope("render " + p("run.h5") + " --px-per-d50 12 --bits 16 --supersample " +
                       std::to_string(s) + " -o " + p(out),
                   dir);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find(std::to_string(cam.cols) + "x" + std::to_string(cam.rows) + " px"),
              std::string::npos)
        << r.out;
  }
  const cv::Mat img8 = image("d/frame_0000.png");
  ASSERT_EQ(img8.type(), CV_8UC1);
  EXPECT_EQ(img8.cols, cam.cols);
  EXPECT_EQ(img8.rows, cam.rows);
  const fs::path gt = dir / "d" / "ground_truth.h5";
  EXPECT_EQ(h5::attr_string(gt, "format"), "granoscope-render-truth");
  EXPECT_EQ(h5::attr_string(gt, "view"), "front");
  EXPECT_DOUBLE_EQ(h5::attr_number(gt, "px_per_m"), cam.ppm);
  EXPECT_DOUBLE_EQ(h5::attr_number(gt, "a0_m"), cam.a0);
  EXPECT_DOUBLE_EQ(h5::attr_number(gt, "b0_m"), cam.b0);
  const auto grain = h5::read(gt, "/grain");
  ASSERT_EQ(grain.dims,
            (std::vector<hsize_t>{static_cast<hsize_t>(cam.rows), static_cast<hsize_t>(cam.cols)}));
  long covered = 0, mismatched = 0;
  double disk_area_px = 0.0;
  for (const auto& q : f0.particles)
    disk_area_px += std::numbers::pi * q.radius * q.radius * cam.ppm * cam.ppm;
  for (int r = 0; r < cam.rows; ++r)
    for (int c = 0; c < cam.cols; ++c) {
      const int want = first_hit(f0, cam.a0 + c / cam.ppm, cam.b0 - r / cam.ppm);
      mismatched += grain[static_cast<std::size_t>(r * cam.cols + c)] != want;
      covered += want >= 0;
    }
  EXPECT_EQ(mismatched, 0);
  // Projected disks overlap, so the covered area is below the sum of the disk areas.
  EXPECT_GT(covered, 0.5 * disk_area_px);
  EXPECT_LT(covered, disk_area_px);
  long background[2] = {0, 0}, expected_background[2] = {0, 0};
  int idx = 0;
  for (int s : {1, 4}) {
    const cv::Mat img = image("s" + std::to_string(s) + "/frame_0000.png");
    ASSERT_EQ(img.type(), CV_16UC1) << s;
    ASSERT_EQ(img.size(), img8.size());
    const cv::Mat h = hits(f0, cam, s);
    long wrong = 0;
    for (int r = 0; r < cam.rows; ++r)
      for (int c = 0; c < cam.cols; ++c) {
        const bool bg = img.at<std::uint16_t>(r, c) == 15 * 257;
        const bool none = h.at<int>(r, c) == 0;
        background[idx] += bg;
        expected_background[idx] += none;
        wrong += bg != none;
      }
    EXPECT_EQ(wrong, 0) << "supersample " << s;
    ++idx;
  }
  EXPECT_EQ(background[0], cam.rows * cam.cols - covered);  // s = 1: the ray through the centre
  EXPECT_EQ(background[1], expected_background[1]);
  EXPECT_LT(background[1], background[0]);
  RecordProperty("background_px_s1", static_cast<int>(background[0]));
  RecordProperty("background_px_s4", static_cast<int>(background[1]));
}

// --bits, --format, --noise. Exact answers: the 16-bit image is round(257 v) and the 8-bit one
// round(v) of the same grey level v, so |I16 - 257 I8| <= 129 everywhere, and the 16-bit image
// uses levels between the 8-bit ones (I16 not a multiple of 257 at > 90 % of the grain pixels);
// --format tif writes a TIFF (II*\0 or MM\0* magic) holding the same pixels as the PNG, 8 and 16
// bit; --noise 0.01 adds Gaussian noise of 0.01 x full scale (655.35 in 16 bits): the
// difference from the noise-free image has that standard deviation to 2 % (standard error of
// the estimate 0.4 %) and zero mean to 4 standard errors, and differs between the two frames.
TEST_F(RenderCli, BitsFormatAndNoiseOptions) {
  const gs::Frame f0 = packing(80, 3);
  gs::Frame f1 = f0;
  for (auto& q : f1.particles) q.position.x() += 1e-4;
  write_run({f0, f1});
  const std::string in = "render " + p("run.h5") + " --px-per-d50 12";
  ASSERT_EQ(granoscope(in + " -o " + p("p8"), dir).rc, 0);
  ASSERT_EQ(granoscope(in + " --bits 16 -o " + p("p16"), dir).rc, 0);
  ASSERT_EQ(granoscope(in + " --format tif -o " + p("t8"), dir).rc, 0);
  ASSERT_EQ(granoscope(in + " --format tif --bits 16 -o " + p("t16"), dir).rc, 0);
  ASSERT_EQ(granoscope(in + " --bits 16 --noise 0.01 -o " + p("n16"), dir).rc, 0);
  const cv::Mat i8 = image("p8/frame_0000.png"), i16 = image("p16/frame_0000.png");
  ASSERT_EQ(i8.type(), CV_8UC1);
  ASSERT_EQ(i16.type(), CV_16UC1);
  ASSERT_EQ(i8.size(), i16.size());
  int worst = 0;
  long grain = 0, fine = 0;
  for (int r = 0; r < i8.rows; ++r)
    for (int c = 0; c < i8.cols; ++c) {
      const int a = i16.at<std::uint16_t>(r, c), b = i8.at<std::uint8_t>(r, c);
      worst = std::max(worst, std::abs(a - 257 * b));
      if (a != 15 * 257) {
        ++grain;
        fine += a % 257 != 0;
      }
    }
  EXPECT_LE(worst, 129);
  EXPECT_GT(fine, 0.9 * static_cast<double>(grain));
  for (const char* d : {"t8", "t16"}) {
    const std::string tif = slurp(dir / d / "frame_0001.tif");
    ASSERT_GE(tif.size(), 4u) << d;
    EXPECT_TRUE(tif.compare(0, 4, std::string("II*\0", 4)) == 0 ||
                tif.compare(0, 4, std::string("MM\0*", 4)) == 0)
        << d;
    EXPECT_FALSE(fs::exists(dir / d / "frame_0001.png"));
  }
  for (const auto& [tif, png] : std::vector<std::pair<std::string, std::string>>{
           {"t8/frame_0001.tif", "p8/frame_0001.png"},
           {"t16/frame_0001.tif", "p16/frame_0001.png"}}) {
    const cv::Mat a = image(tif), b = image(png);
    ASSERT_EQ(a.type(), b.type()) << tif;
    ASSERT_EQ(a.size(), b.size()) << tif;
    EXPECT_EQ(cv::countNonZero(a != b), 0) << tif;
  }
  cv::Mat n[2], clean[2];
  for (int k = 0; k < 2; ++k) {
    image("n16/frame_000" + std::to_string(k) + ".png").convertTo(n[k], CV_64F);
    image("p16/frame_000" + std::to_string(k) + ".png").convertTo(clean[k], CV_64F);
    cv::Scalar mean, sd;
    cv::meanStdDev(n[k] - clean[k], mean, sd);
    const double N = static_cast<double>(n[k].total()), sigma = 0.01 * 65535.0;
    EXPECT_NEAR(sd[0], sigma, 0.02 * sigma) << k;
    EXPECT_NEAR(mean[0], 0.0, 4.0 * sigma / std::sqrt(N)) << k;
    RecordProperty("noise_sd_frame" + std::to_string(k), std::to_string(sd[0]));
  }
  // Independent realisations: the two noise fields are uncorrelated (|rho| < 5 / sqrt(N)).
  const cv::Mat e0 = n[0] - clean[0], e1 = n[1] - clean[1];
  const double rho = e0.dot(e1) / std::sqrt(e0.dot(e0) * e1.dot(e1));
  EXPECT_LT(std::abs(rho), 5.0 / std::sqrt(static_cast<double>(e0.total())));
  // Bad values: one line each, exit 2, no frame written.
  for (const auto& [opt, msg] : std::vector<std::pair<std::string, std::string>>{
           {"--bits 12", "error: --bits: must be 8 or 16 (12)\n"},
           {"--format jpg", "error: --format: must be png or tif (jpg)\n"},
           {"--noise -0.1",
            "error: --noise: must be in [0, 1) (fraction of full scale) (-0.10000000000000001)\n"},
           {"--supersample 0", "error: --supersample: must be in 1..16 (0)\n"},
           {"--view diagonal",
            "error: --view: must be front, back, left, right, top or bottom (diagonal)\n"}}) {
    const CliRun r = granoscope(in + " " + opt + " -o " + p("bad"), dir);
    EXPECT_EQ(r.rc, 2) << opt;
    EXPECT_EQ(r.err, msg);
    EXPECT_FALSE(fs::exists(dir / "bad" / "frame_0000.png")) << opt;
  }
  const CliRun missing = granoscope("render " + p("none.h5") + " -o " + p("bad"), dir);
  EXPECT_EQ(missing.rc, 2);
  EXPECT_EQ(missing.err, "error: " + p("none.h5") + ": no such file\n");
}

// `granoscope dic` on rendered frames (12 px per d50, subset 31 px = 2.6 d50). (1) Every grain
// translated by (+1.3, -0.7) px (lab +x, +z): the ground truth is exactly (1.3, -0.7) px at
// every grain pixel, and DIC recovers it at every valid POI (> 90 % of them; measured 1892 of
// 1936) to 0.08 px, RMS 0.015 px (measured worst 0.047 px, RMS 0.0096 px). (2) Positions and
// radii scaled by 1.01 about the centre of the view: an exact image dilation, so the ground truth
// is u = 0.01 (x - xc), v = 0.01 (y - yc) at every grain pixel, DIC matches it at the valid POIs
// to 0.08 px (measured 0.046 px) and the small-strain output is exx = eyy = 0.01, exy = 0 to 2e-4
// on average (measured 0.01002, 0.00995, -1.6e-5).
TEST_F(RenderCli, DicOfARenderedPairRecoversTheImposedMotion) {
  const gs::Frame f0 = packing(250, 1);
  const ExpectedCamera cam = expected_front_camera(f0, 12.0, 0.5);
  gs::Frame shifted = f0, dilated = f0;
  for (auto& q : shifted.particles) {
    q.position.x() += 1.3 / cam.ppm;
    q.position.z() += 0.7 / cam.ppm;
  }
  // Centre of the view in the lab (front view: a = x, b = z).
  const double xc = cam.a0 + 0.5 * (cam.cols - 1) / cam.ppm,
               zc = cam.b0 - 0.5 * (cam.rows - 1) / cam.ppm;
  const Eigen::Vector3d centre(xc, 0.003, zc);
  const double e = 0.01;
  for (auto& q : dilated.particles) {
    q.position = centre + (1.0 + e) * (q.position - centre);
    q.radius *= 1.0 + e;
  }
  write_run({f0, shifted, dilated});
  ASSERT_EQ(granoscope("render " + p("run.h5") + " --px-per-d50 12 -o " + p("f"), dir).rc, 0);
  const fs::path gt = dir / "f" / "ground_truth.h5";
  const auto gu = h5::read(gt, "/u"), gv = h5::read(gt, "/v"), grain = h5::read(gt, "/grain");
  ASSERT_EQ(gu.dims, (std::vector<hsize_t>{3, static_cast<hsize_t>(cam.rows),
                                           static_cast<hsize_t>(cam.cols)}));
  const std::size_t plane = static_cast<std::size_t>(cam.rows * cam.cols);
  const double pxc = 0.5 * (cam.cols - 1), pyc = 0.5 * (cam.rows - 1);
  for (std::size_t k = 0; k < plane; ++k) {
    if (grain[k] < 0) continue;
    ASSERT_NEAR(gu[plane + k], 1.3, 1e-5);
    ASSERT_NEAR(gv[plane + k], -0.7, 1e-5);
    const double x = static_cast<double>(k % static_cast<std::size_t>(cam.cols)),
                 y = static_cast<double>(k / static_cast<std::size_t>(cam.cols));
    ASSERT_NEAR(gu[2 * plane + k], e * (x - pxc), 1e-4);
    ASSERT_NEAR(gv[2 * plane + k], e * (y - pyc), 1e-4);
  }
  ASSERT_EQ(granoscope("dic " + p("f/frame_0000.png") + " " + p("f/frame_0001.png") + " " +
                           p("f/frame_0002.png") +
                           " --subset 31 --step 4 --strain-window 7 --strain small -o " + p("d.h5"),
                       dir)
                .rc,
            0);
  const auto x = h5::read(dir / "d.h5", "/x"), y = h5::read(dir / "d.h5", "/y");
  const auto u = h5::read(dir / "d.h5", "/u"), v = h5::read(dir / "d.h5", "/v"),
             valid = h5::read(dir / "d.h5", "/valid");
  const auto exx = h5::read(dir / "d.h5", "/exx_small"), eyy = h5::read(dir / "d.h5", "/eyy_small"),
             exy = h5::read(dir / "d.h5", "/exy_small");
  const std::size_t n = x.size() * y.size();
  double worst_t = 0.0, worst_d = 0.0, sum2_t = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
  int nvalid = 0, nstrain = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double px = x[k % x.size()], py = y[k / x.size()];
    if (valid[k] == 1.0) {
      ++nvalid;
      worst_t = std::max({worst_t, std::abs(u[k] - 1.3), std::abs(v[k] + 0.7)});
      sum2_t += (u[k] - 1.3) * (u[k] - 1.3) + (v[k] + 0.7) * (v[k] + 0.7);
    }
    if (valid[n + k] == 1.0)
      worst_d = std::max(
          {worst_d, std::abs(u[n + k] - e * (px - pxc)), std::abs(v[n + k] - e * (py - pyc))});
    if (std::isfinite(exx[n + k])) {
      ++nstrain;
      sxx += exx[n + k];
      syy += eyy[n + k];
      sxy += exy[n + k];
    }
  }
  EXPECT_GT(nvalid, static_cast<int>(0.9 * static_cast<double>(n)));
  EXPECT_LT(worst_t, 0.08);
  EXPECT_LT(std::sqrt(sum2_t / (2.0 * nvalid)), 0.015);
  EXPECT_LT(worst_d, 0.08);
  ASSERT_GT(nstrain, static_cast<int>(0.8 * static_cast<double>(n)));
  EXPECT_NEAR(sxx / nstrain, e, 2e-4);
  EXPECT_NEAR(syy / nstrain, e, 2e-4);
  EXPECT_NEAR(sxy / nstrain, 0.0, 2e-4);
  RecordProperty("worst_translation_error_px", std::to_string(worst_t));
  RecordProperty("rms_translation_error_px", std::to_string(std::sqrt(sum2_t / (2.0 * nvalid))));
  RecordProperty("pois", static_cast<int>(n));
  RecordProperty("worst_dilation_error_px", std::to_string(worst_d));
  RecordProperty("mean_exx", std::to_string(sxx / nstrain));
  RecordProperty("mean_eyy", std::to_string(syy / nstrain));
  RecordProperty("mean_exy", std::to_string(sxy / nstrain));
  RecordProperty("valid", nvalid);
}
