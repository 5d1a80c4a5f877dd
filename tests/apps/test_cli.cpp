// End-to-end tests of the `granoscope` executable: counts, bounding box and d50 computed from the
// fixtures, conversions, bad input, figures (particles drawn where the input puts them).
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "../io/test_util.hpp"
#include "cli_util.hpp"
#include "trajectory_io.hpp"

namespace {

const std::filesystem::path kData = GS_TEST_DATA_DIR;

using gs::test::expect_rejected;
using gs::test::slurp;
using Result = gs::test::CliResult;

Result run(const std::string& args, const std::filesystem::path& scratch) {
  return gs::test::run_cli(args, scratch);
}

/// d50 by the definition of analysis/grain_size.hpp: cumulative volume passing at each distinct
/// diameter counting half of its own class (mid-point rule), linear interpolation at 1/2.
double d50_of(const gs::Frame& f) {
  std::map<double, double> cls;  // diameter -> volume (r^3) of its class
  double total = 0.0;
  for (const auto& p : f.particles) {
    cls[2 * p.radius] += p.radius * p.radius * p.radius;
    total += p.radius * p.radius * p.radius;
  }
  double below = 0.0, prev_d = 0.0, prev_c = -1.0;
  for (const auto& [d, v] : cls) {
    const double c = (below + 0.5 * v) / total;
    if (0.5 <= c) return prev_c < 0 ? d : prev_d + (d - prev_d) * (0.5 - prev_c) / (c - prev_c);
    below += v;
    prev_d = d;
    prev_c = c;
  }
  return prev_d;
}

/// The "bounding box:" and "d50:" lines `info` prints for the last frame of `t`.
std::string box_and_d50(const gs::Trajectory& t) {
  const gs::Frame& f = t.frames.back();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto& p : f.particles) {
    lo = lo.cwiseMin(p.position - Eigen::Vector3d::Constant(p.radius));
    hi = hi.cwiseMax(p.position + Eigen::Vector3d::Constant(p.radius));
  }
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "bounding box: [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g] m (last frame)\n"
                "d50:          %.6g m (by volume, last frame)\n",
                lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z(), d50_of(f));
  return buf;
}

std::vector<std::string> listing(const std::filesystem::path& dir) {
  std::vector<std::string> v;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    v.push_back(e.path().filename().string());
  std::sort(v.begin(), v.end());
  return v;
}

}  // namespace

TEST(Cli, InfoReportsFixtureCounts) {
  // Counts of the fixtures (tests/data/README); bounding box (centres -+ radius) and d50 (by
  // volume) computed here from the frames the readers return.
  gs::test::ScratchDir dir("cli_info");
  const auto yade = kData / "yade" / "yade_export-spheres-00000000.vtk";
  Result r = run("info " + yade.string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("particles:    40 (first frame)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("contacts:     74 (first frame)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(box_and_d50(gs::read_snapshots(yade))), std::string::npos)
      << r.out << "expected:\n"
      << box_and_d50(gs::read_snapshots(yade));
  r = run("info " + (kData / "liggghts" / "dump.atoms").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("frames:       2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("particles:    60 (first frame), 60 (last frame)"), std::string::npos);
  EXPECT_NE(r.out.find("contacts:     11 (first frame), 54 (last frame)"), std::string::npos);
  EXPECT_NE(r.out.find("steps 10000 .. 20000"), std::string::npos);
  EXPECT_NE(r.out.find("d50:          0.006 m"), std::string::npos);
  const auto atoms = gs::read_snapshots(kData / "liggghts" / "dump.atoms");
  EXPECT_NE(r.out.find(box_and_d50(atoms)), std::string::npos) << r.out << box_and_d50(atoms);
  r = run("info " + (kData / "yade" / "yade_spheres.20000.vtu").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("particles:    40"), std::string::npos);
}

TEST(Cli, ConvertRoundTripHdf5VtuHdf5) {
  gs::test::ScratchDir dir("cli_convert");
  ASSERT_EQ(
      run("convert " + (kData / "liggghts" / "dump.atoms").string() + " " + (dir / "a.h5").string(),
          dir.path)
          .rc,
      0);
  ASSERT_EQ(
      run("convert " + (dir / "a.h5").string() + " " + (dir / "b.vtu").string() + " --frame 1",
          dir.path)
          .rc,
      0);
  ASSERT_EQ(run("convert " + (dir / "b.vtu").string() + " " + (dir / "c.h5").string(), dir.path).rc,
            0);
  const auto a = gs::read_snapshots(dir / "a.h5"), c = gs::read_snapshots(dir / "c.h5");
  ASSERT_EQ(a.frames.size(), 2u);
  ASSERT_EQ(c.frames.size(), 1u);
  gs::test::expect_same_frame(a.frames[1], c.frames[0]);
  const Result r = run("info " + (dir / "c.h5").string(), dir.path);
  EXPECT_NE(r.out.find("contacts:     54"), std::string::npos) << r.out;
}

/// Bad input files (in `in`) with the message each must give ("" = any), cases [first, last).
/// Every one is rejected by `info` and `convert` to each output format with one line and exit
/// code 2, and leaves nothing in `out`.
void expect_bad_inputs_rejected(const gs::test::ScratchDir& dir, std::size_t first,
                                std::size_t last) {
  const auto in = dir / "in";
  const auto out = dir / "out";
  std::filesystem::create_directories(in);
  std::filesystem::create_directories(out);
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(in / name, std::ios::binary) << text;
    return (in / name).string();
  };
  // A good HDF5 file to damage.
  gs::Trajectory t;
  t.frames = {gs::test::random_frame(20, 10, 1), gs::test::random_frame(20, 10, 2)};
  gs::write_snapshots(in / "good.h5", t);
  std::filesystem::copy_file(in / "good.h5", in / "trunc.h5");
  std::filesystem::resize_file(in / "trunc.h5", std::filesystem::file_size(in / "good.h5") / 2);
  std::filesystem::copy_file(in / "good.h5", in / "schema.h5");
  {
    hid_t f = H5Fopen((in / "schema.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t a = H5Aopen(f, "schema_version", H5P_DEFAULT);
    const long long v = 7;
    H5Awrite(a, H5T_NATIVE_LLONG, &v);
    H5Aclose(a);
    H5Fclose(f);
  }
  const std::string atoms = slurp(kData / "liggghts" / "dump.atoms");
  std::string garbage(4096, '\0');
  for (std::size_t i = 0; i < garbage.size(); ++i)
    garbage[i] = static_cast<char>((i * 2654435761u) >> 13);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {(in / "missing.h5").string(), "no such file"},
      {(in / "trunc.h5").string(), "cannot open HDF5 file (corrupt or truncated)"},
      {(in / "schema.h5").string(), "unsupported schema_version (7)"},
      {write("nan.csv", "id,x,y,z,r\n0,0,0,0,0.001\n1,0.5,0,0,nan\n"),
       "particle 1 radius is not finite (nan)"},
      {write("neg.csv", "id,x,y,z,r\n0,0,0,0,-0.001\n"),
       "particle 0 radius is not positive (-0.001)"},
      {write("cols.csv", "id,x,y,r\n0,0,0,0.001\n"), "missing column in header (z)"},
      {write("short.csv", "id,x,y,z,r\n0,0,0,0.001\n"), "line 2: expected 5 fields (4)"},
      {write("garbage.h5", garbage), "not an HDF5 file (bad signature)"},
      {write("garbage.csv", garbage), ""},
      {write("garbage.vtu", garbage), ""},
      {write("trunc.atoms", atoms.substr(0, atoms.find('\n', 3000) + 1)), "truncated dump"},
      {write("cut.atoms", atoms.substr(0, 3000)), "expected 16 columns"},
  };
  for (std::size_t k = first; k < std::min(last, cases.size()); ++k) {
    const auto& [file, what] = cases[k];
    SCOPED_TRACE(file);
    Result r = run("info " + file, dir.path);
    expect_rejected(r, file);
    if (!what.empty()) {
      EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
    }
    for (const char* ext : {".h5", ".vtu", ".pvd", ".csv"}) {
      r = run("convert " + file + " " + (out / (std::string("x") + ext)).string(), dir.path);
      expect_rejected(r, file);
    }
    EXPECT_TRUE(listing(out).empty()) << "partial output left behind";
  }
}

// Two tests over the bad inputs (each under 10 s).
TEST(Cli, BadInputGivesOneLineAndExitCode2AndNoOutput) {
  gs::test::ScratchDir dir("cli_bad");
  expect_bad_inputs_rejected(dir, 0, 6);
}

TEST(Cli, BadInputGivesOneLineAndExitCode2AndNoOutputTextFormats) {
  gs::test::ScratchDir dir("cli_bad2");
  expect_bad_inputs_rejected(dir, 6, 12);
  const auto in = dir / "in";
  const auto out = dir / "out";
  // Bad output type and bad frame index are rejected before anything is written.
  Result r = run("convert " + (in / "good.h5").string() + " " + (out / "x.txt").string(), dir.path);
  expect_rejected(r, (out / "x.txt").string());
  r = run("convert " + (in / "good.h5").string() + " " + (out / "x.vtu").string() + " --frame 5",
          dir.path);
  expect_rejected(r, (out / "x.vtu").string());
  EXPECT_TRUE(listing(out).empty());
  // Usage errors exit 2 as well.
  EXPECT_EQ(run("info", dir.path).rc, 2);
  EXPECT_EQ(run("nonsense", dir.path).rc, 2);
  EXPECT_EQ(run("--help", dir.path).rc, 0);
}

TEST(Cli, FiguresWritesANonBlankPositionsPng) {
  gs::test::ScratchDir dir("cli_fig");
  ASSERT_EQ(run("convert " + (kData / "liggghts" / "dump.atoms").string() + " " +
                    (dir / "run.h5").string(),
                dir.path)
                .rc,
            0);
  const Result r =
      run("figures " + (dir / "run.h5").string() + " -o " + (dir / "figs").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  const auto png = dir / "figs" / "run_positions_front_000001.png";
  ASSERT_TRUE(std::filesystem::exists(png)) << r.out << r.err;
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(img.empty());
  EXPECT_GT(img.cols, 300);
  cv::Scalar mean, sd;
  cv::meanStdDev(img, mean, sd);
  EXPECT_GT(sd[0], 10.0) << "blank image";
  // The last frame's spheres all have one radius, so they are drawn in one colour, the middle
  // of viridis (matplotlib widens the limits of a constant field around it), and in the front
  // view (x right, z up, equal aspect) their discs together span the box of the spheres' x and
  // z extents: the largest region of that colour (discs joined across their 0.4 px outlines)
  // has the aspect ratio of that box, to a pixel at each edge.
  const gs::Frame last = gs::read_snapshots(dir / "run.h5").frames.back();
  double lo_x = 1e300, hi_x = -1e300, lo_z = 1e300, hi_z = -1e300;
  for (const auto& p : last.particles) {
    ASSERT_EQ(p.radius, last.particles[0].radius);
    lo_x = std::min(lo_x, p.position.x() - p.radius);
    hi_x = std::max(hi_x, p.position.x() + p.radius);
    lo_z = std::min(lo_z, p.position.z() - p.radius);
    hi_z = std::max(hi_z, p.position.z() + p.radius);
  }
  const cv::Mat colour = cv::imread(png.string(), cv::IMREAD_COLOR);  // BGR
  cv::Mat mask, labels, stats, centroids;
  cv::inRange(colour, cv::Scalar(140.4 - 2.5, 144.6 - 2.5, 32.5 - 2.5),
              cv::Scalar(140.4 + 2.5, 144.6 + 2.5, 32.5 + 2.5), mask);
  cv::dilate(mask, mask, cv::Mat(), cv::Point(-1, -1), 1);
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
  int best = 0;
  for (int k = 1; k < n; ++k)
    if (best == 0 || stats.at<int>(k, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA))
      best = k;
  ASSERT_GT(best, 0);
  // dilation adds a pixel on each side
  const double w = stats.at<int>(best, cv::CC_STAT_WIDTH) - 2.0;
  const double h = stats.at<int>(best, cv::CC_STAT_HEIGHT) - 2.0;
  const double ratio = (hi_x - lo_x) / (hi_z - lo_z);
  std::printf("discs: %.0f x %.0f px, aspect %.4f (spheres' box %.4f)\n", w, h, w / h, ratio);
  EXPECT_GT(w, 300.0);
  EXPECT_NEAR(w / h, ratio, ratio * (2.0 / w + 2.0 / h));
  // Bad inputs to figures.
  expect_rejected(
      run("figures " + (dir / "nope.h5").string() + " -o " + (dir / "f2").string(), dir.path),
      (dir / "nope.h5").string());
  expect_rejected(
      run("figures " + (kData / "packing_small.csv").string() + " -o " + (dir / "f2").string(),
          dir.path),
      (kData / "packing_small.csv").string());
}

// Exact answer: an option value of the wrong type, an unknown option and a missing subcommand
// are each one line "error: …" on stderr, exit code 2, nothing on stdout (the rule of every CLI
// path; CLI11 alone prints two lines without the prefix).
TEST(Cli, UsageErrorsAreOneLine) {
  gs::test::ScratchDir dir("cli_usage");
  for (const char* args : {"render x.h5 --bits abc", "info --no-such-option x.h5", ""}) {
    const auto r = gs::test::run_cli(args, dir.path);
    EXPECT_EQ(r.rc, 2) << args;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
  }
}
