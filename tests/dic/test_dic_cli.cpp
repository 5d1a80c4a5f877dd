// `granoscope dic` end to end on small synthetic 8-bit images, and its bad-input errors.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "speckle_synthetic.hpp"

namespace fs = std::filesystem;
using namespace gs::dic;

namespace {

struct CliRun {
  int rc;
  std::string err;
};

CliRun granoscope(const std::string& args, const fs::path& dir) {
  const std::string err_file = (dir / "stderr.txt").string();
  const std::string cmd = std::string(GS_BINARY_DIR) + "/bin/granoscope " + args + " > " +
                          (dir / "stdout.txt").string() + " 2> " + err_file;
  const int status = std::system(cmd.c_str());
  std::ifstream is(err_file);
  std::stringstream ss;
  ss << is.rdbuf();
  return {WEXITSTATUS(status), ss.str()};
}

class DicCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("gs_dic_cli_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
    const SpecklePattern pat(-10, -10, 90, 90, SpeckleParams{});
    RenderParams rp;
    rp.noise_sigma = 1.0;
    rp.quantize_8bit = true;
    cv::Mat ref = render_speckle(
        pat, 72, 80, [](const Eigen::Vector2d& x) { return x; }, rp);
    rp.noise_seed = 8;
    cv::Mat def = render_speckle(
        pat, 72, 80,
        [](const Eigen::Vector2d& x) { return Eigen::Vector2d(x.x() - 1.3, x.y() - 0.4); }, rp);
    ref.convertTo(ref, CV_8U);
    def.convertTo(def, CV_8U);
    cv::imwrite((dir / "ref.png").string(), ref);
    cv::imwrite((dir / "def.png").string(), def);
  }
  void TearDown() override { fs::remove_all(dir); }
  std::string p(const char* name) const { return (dir / name).string(); }
  fs::path dir;
};

void expect_one_line_error(const CliRun& r, const std::string& fragment) {
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
}

}  // namespace

TEST_F(DicCli, WritesHdf5CsvAndVtk) {
  const CliRun r =
      granoscope("dic " + p("ref.png") + " " + p("def.png") + " " + p("def.png") + " -o " +
                     p("out.h5") + " --subset 21 --step 4 --strain-window 5 --incremental",
                 dir);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "out.h5"));
  EXPECT_TRUE(fs::exists(dir / "out_0001.vti"));
  EXPECT_TRUE(fs::exists(dir / "out_0002.vti"));
  std::ifstream csv(dir / "out_0001.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "x,y,u,v,exx,eyy,exy,zncc,valid");
  int rows = 0, near = 0;
  while (std::getline(csv, line)) {
    ++rows;
    double x, y, u, v;
    char c;
    std::stringstream ls(line);
    ls >> x >> c >> y >> c >> u >> c >> v;
    near += std::abs(u - 1.3) < 0.05 && std::abs(v - 0.4) < 0.05;
  }
  // Grid: x = 10..66 step 4 (15), y = 10..58 step 4 (13).
  EXPECT_EQ(rows, 15 * 13);
  EXPECT_GT(near, rows * 2 / 3);
  // Incremental: the third image equals the second, so the accumulated displacement stays.
  std::ifstream csv2(dir / "out_0002.csv");
  std::getline(csv2, line);
  int near2 = 0;
  while (std::getline(csv2, line)) {
    double x, y, u, v;
    char c;
    std::stringstream ls(line);
    ls >> x >> c >> y >> c >> u >> c >> v;
    near2 += std::abs(u - 1.3) < 0.05 && std::abs(v - 0.4) < 0.05;
  }
  EXPECT_GT(near2, rows / 2);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
}

TEST_F(DicCli, BadInputsGiveOneLineErrors) {
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("missing.png") + " -o " + p("o.h5"), dir),
      "missing.png: no such image file");
  cv::imwrite(p("small.png"), cv::Mat(40, 40, CV_8U, cv::Scalar(3)));
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("small.png") + " -o " + p("o.h5"), dir),
      "image size differs from the reference");
  cv::imwrite(p("flat.png"), cv::Mat(72, 80, CV_8U, cv::Scalar(128)));
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("flat.png") + " -o " + p("o.h5"), dir),
      "no texture");
  cv::imwrite(p("roi.png"), cv::Mat(72, 80, CV_8U, cv::Scalar(0)));
  expect_one_line_error(granoscope("dic " + p("ref.png") + " " + p("def.png") + " --roi " +
                                       p("roi.png") + " -o " + p("o.h5"),
                                   dir),
                        "ROI contains no point of interest");
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("def.png") + " --subset 30 -o " + p("o.h5"), dir),
      "--subset: must be an odd number");
  EXPECT_FALSE(fs::exists(dir / "o.h5"));
}
