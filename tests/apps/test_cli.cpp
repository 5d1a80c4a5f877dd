// End-to-end tests of the `granoscope` executable: counts, conversions, bad input, figures.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
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

std::vector<std::string> listing(const std::filesystem::path& dir) {
  std::vector<std::string> v;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    v.push_back(e.path().filename().string());
  std::sort(v.begin(), v.end());
  return v;
}

}  // namespace

TEST(Cli, InfoReportsFixtureCounts) {
  gs::test::ScratchDir dir("cli_info");
  Result r =
      run("info " + (kData / "yade" / "yade_export-spheres-00000000.vtk").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("particles:    40 (first frame)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("contacts:     74 (first frame)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("d50:"), std::string::npos);
  r = run("info " + (kData / "liggghts" / "dump.atoms").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("frames:       2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("particles:    60 (first frame), 60 (last frame)"), std::string::npos);
  EXPECT_NE(r.out.find("contacts:     11 (first frame), 54 (last frame)"), std::string::npos);
  EXPECT_NE(r.out.find("steps 10000 .. 20000"), std::string::npos);
  EXPECT_NE(r.out.find("d50:          0.006 m"), std::string::npos);
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

TEST(Cli, BadInputGivesOneLineAndExitCode2AndNoOutput) {
  gs::test::ScratchDir dir("cli_bad");
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
  for (const auto& [file, what] : cases) {
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
  // Bad inputs to figures.
  expect_rejected(
      run("figures " + (dir / "nope.h5").string() + " -o " + (dir / "f2").string(), dir.path),
      (dir / "nope.h5").string());
  expect_rejected(
      run("figures " + (kData / "packing_small.csv").string() + " -o " + (dir / "f2").string(),
          dir.path),
      (kData / "packing_small.csv").string());
}
