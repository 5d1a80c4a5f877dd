// `granoscope dic` end to end on synthetic 8-bit speckle images with exactly known motion: the
// HDF5, CSV and VTK outputs are read back and compared with the imposed displacement and strain;
// --strain, --zncc-min and --search each change the result as documented; bad input gives one
// line `error: FILE: what (value)` and exit code 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkXMLImageDataReader.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "h5_read.hpp"
#include "speckle_synthetic.hpp"

namespace fs = std::filesystem;
using namespace gs::dic;
namespace h5 = gs::test::h5;

namespace {

struct CliRun {
  int rc;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream is(p);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

CliRun granoscope(const std::string& args, const fs::path& dir) {
  const std::string out_file = (dir / "stdout.txt").string(),
                    err_file = (dir / "stderr.txt").string();
  const std::string cmd = std::string(GS_BINARY_DIR) + "/bin/granoscope " + args + " > " +
                          out_file + " 2> " + err_file + " < /dev/null";
  const int status = std::system(cmd.c_str());
  CliRun r{WIFEXITED(status) ? WEXITSTATUS(status) : 128, slurp(out_file), slurp(err_file)};
  fs::remove(out_file);
  fs::remove(err_file);
  return r;
}

// One CSV table written by `granoscope dic` (x,y,u,v,exx,eyy,exy,zncc,valid; "nan" allowed).
struct Table {
  std::vector<std::string> header;
  std::map<std::string, std::vector<double>> col;
  std::size_t rows = 0;
  const std::vector<double>& operator[](const std::string& c) const { return col.at(c); }
};

Table read_csv(const fs::path& p) {
  std::ifstream in(p);
  Table t;
  std::string line;
  if (!std::getline(in, line)) return t;
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) t.header.push_back(c);
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::size_t k = 0;
    for (std::string c; std::getline(ls, c, ','); ++k)
      t.col[t.header.at(k)].push_back(std::strtod(c.c_str(), nullptr));
    EXPECT_EQ(k, t.header.size()) << line;
    ++t.rows;
  }
  return t;
}

using Map = std::function<Eigen::Vector2d(const Eigen::Vector2d&)>;

// 8-bit speckle image (Boolean discs r = 2.5 px, 5x5 supersampling, blur 0.6 px), Gaussian noise
// `noise` grey levels, seen through the inverse map `inverse` (current -> reference point).
cv::Mat speckle(const SpecklePattern& pat, int rows, int cols, const Map& inverse, double noise,
                std::uint64_t noise_seed) {
  RenderParams rp;
  rp.noise_sigma = noise;
  rp.noise_seed = noise_seed;
  rp.quantize_8bit = true;
  cv::Mat img = render_speckle(pat, rows, cols, inverse, rp);
  img.convertTo(img, CV_8U);
  return img;
}

Eigen::Vector2d identity(const Eigen::Vector2d& x) {
  return x;
}

class DicCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("gs_dic_cli_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override {  // GS_KEEP=1 keeps the images and outputs
    if (!std::getenv("GS_KEEP")) fs::remove_all(dir);
  }
  std::string p(const char* name) const { return (dir / name).string(); }
  // ref.png and def.png: 80 x 72 px, def = ref translated by (+1.3, +0.4) px, noise 1 grey level.
  void translation_pair() {
    const SpecklePattern pat(-10, -10, 90, 90, SpeckleParams{});
    cv::imwrite(p("ref.png"), speckle(pat, 72, 80, identity, 1.0, 7));
    cv::imwrite(p("def.png"), speckle(
                                  pat, 72, 80,
                                  [](const Eigen::Vector2d& x) {
                                    return Eigen::Vector2d(x.x() - 1.3, x.y() - 0.4);
                                  },
                                  1.0, 8));
  }
  fs::path dir;
};

void expect_one_line_error(const CliRun& r, const std::string& fragment) {
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
}

std::vector<double> vti_array(const fs::path& file, const char* name, int dims[3], double origin[3],
                              double spacing[3]) {
  vtkNew<vtkXMLImageDataReader> r;
  r->SetFileName(file.c_str());
  r->Update();
  vtkImageData* img = r->GetOutput();
  img->GetDimensions(dims);
  img->GetOrigin(origin);
  img->GetSpacing(spacing);
  vtkDataArray* a = img->GetPointData()->GetArray(name);
  std::vector<double> v;
  if (!a) return v;
  for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i) v.push_back(a->GetComponent(i, 0));
  return v;
}

}  // namespace

// Exact answers: the POI grid (x = 10..66, y = 10..58 step 4: 15 x 13) and VSG = 2*2*4 + 21 =
// 37 px in every output; u = 1.3 px, v = 0.4 px at every POI to 0.025 px, RMS 0.008 px
// (measured: worst 0.0151 px, RMS 0.0057 px); the HDF5, CSV and VTI files hold the same numbers;
// the third image equals the second, so the incremental accumulation adds an increment of zero
// (frame 2 = frame 1 to 1e-6 px, measured 0).
TEST_F(DicCli, WritesHdf5CsvAndVtk) {
  translation_pair();
  const CliRun r =
      granoscope("dic " + p("ref.png") + " " + p("def.png") + " " + p("def.png") + " -o " +
                     p("out.h5") + " --subset 21 --step 4 --strain-window 5 --incremental",
                 dir);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("195/195 valid POIs"), std::string::npos) << r.out;
  // HDF5: attributes and shapes.
  const fs::path h = dir / "out.h5";
  EXPECT_EQ(h5::attr_string(h, "format"), "granoscope-dic");
  EXPECT_EQ(h5::attr_number(h, "subset_px"), 21);
  EXPECT_EQ(h5::attr_number(h, "step_px"), 4);
  EXPECT_EQ(h5::attr_number(h, "strain_window_points"), 5);
  EXPECT_EQ(h5::attr_number(h, "vsg_px"), 37);
  EXPECT_EQ(h5::attr_number(h, "image_rows"), 72);
  EXPECT_EQ(h5::attr_number(h, "image_cols"), 80);
  EXPECT_EQ(h5::attr_string(h, "mode"), "incremental");
  EXPECT_EQ(h5::attr_string(h, "shape_function"), "affine");
  EXPECT_EQ(h5::attr_string(h, "images"), p("ref.png") + "\n" + p("def.png") + "\n" + p("def.png"));
  const auto x = h5::read(h, "/x"), y = h5::read(h, "/y");
  ASSERT_EQ(x.size(), 15u);
  ASSERT_EQ(y.size(), 13u);
  for (std::size_t i = 0; i < 15; ++i) EXPECT_EQ(x[i], 10.0 + 4.0 * static_cast<double>(i));
  for (std::size_t j = 0; j < 13; ++j) EXPECT_EQ(y[j], 10.0 + 4.0 * static_cast<double>(j));
  const auto u = h5::read(h, "/u"), v = h5::read(h, "/v"), valid = h5::read(h, "/valid"),
             exx = h5::read(h, "/exx");
  ASSERT_EQ(u.dims, (std::vector<hsize_t>{2, 13, 15}));
  const std::size_t n = 15 * 13;
  double worst = 0.0, worst_strain = 0.0, sum2 = 0.0;
  for (std::size_t k = 0; k < 2 * n; ++k) {
    ASSERT_EQ(valid[k], 1.0) << k;
    worst = std::max({worst, std::abs(u[k] - 1.3), std::abs(v[k] - 0.4)});
    sum2 += (u[k] - 1.3) * (u[k] - 1.3) + (v[k] - 0.4) * (v[k] - 0.4);
    if (std::isfinite(exx[k])) worst_strain = std::max(worst_strain, std::abs(exx[k]));
  }
  EXPECT_LT(worst, 0.025);
  EXPECT_LT(std::sqrt(sum2 / static_cast<double>(4 * n)), 0.008);
  EXPECT_LT(worst_strain, 2e-3);  // a translation has no strain (measured 1.1e-3 at worst)
  RecordProperty("worst_displacement_error_px", std::to_string(worst));
  RecordProperty("rms_displacement_error_px", std::to_string(std::sqrt(sum2 / (4.0 * n))));
  for (std::size_t k = 0; k < n; ++k) EXPECT_NEAR(u[n + k], u[k], 1e-6);
  // CSV: the same grid and numbers (10 significant digits).
  for (int frame = 1; frame <= 2; ++frame) {
    const Table t = read_csv(dir / ("out_000" + std::to_string(frame) + ".csv"));
    EXPECT_EQ(t.header,
              (std::vector<std::string>{"x", "y", "u", "v", "exx", "eyy", "exy", "zncc", "valid"}));
    ASSERT_EQ(t.rows, n);
    const std::size_t off = static_cast<std::size_t>(frame - 1) * n;
    for (std::size_t k = 0; k < n; ++k) {
      EXPECT_EQ(t["x"][k], x[k % 15]);
      EXPECT_EQ(t["y"][k], y[k / 15]);
      EXPECT_NEAR(t["u"][k], u[off + k], 1e-9);
      EXPECT_NEAR(t["v"][k], v[off + k], 1e-9);
      EXPECT_EQ(t["valid"][k], 1.0);
    }
  }
  // VTI: origin = first POI, spacing = step, the same u.
  int dims[3];
  double origin[3], spacing[3];
  const auto vu = vti_array(dir / "out_0001.vti", "u", dims, origin, spacing);
  EXPECT_EQ(dims[0], 15);
  EXPECT_EQ(dims[1], 13);
  EXPECT_EQ(dims[2], 1);
  EXPECT_EQ(origin[0], 10.0);
  EXPECT_EQ(origin[1], 10.0);
  EXPECT_EQ(spacing[0], 4.0);
  EXPECT_EQ(spacing[1], 4.0);
  ASSERT_EQ(vu.size(), n);
  for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(vu[k], u[k]);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
}

// --strain small|green on a homogeneous deformation with a rigid rotation, F = R(0.05 rad) U,
// U = diag(1.01, 0.995), about the image centre. Exact answers: Green–Lagrange (F^T F - I)/2 =
// (0.01005, -0.0049875, 0) whatever the rotation; small strain (F11 - 1, F22 - 1, (F12+F21)/2) =
// (0.0087378, -0.0062435, 0.00037484). The CSV/VTI strain columns follow --strain, the HDF5
// holds both; mean over the valid strain POIs within 2e-4 of the exact value (measured worst
// mean error 8.2e-5, in eyy), while the two measures differ by 1.3e-3 in exx and eyy.
TEST_F(DicCli, StrainOptionSelectsGreenLagrangeOrSmallStrain) {
  const int n = 128;
  const double th = 0.05, a = 0.01, b = -0.005, c0 = 0.5 * (n - 1);
  Eigen::Matrix2d F;
  F << std::cos(th) * (1 + a), -std::sin(th) * (1 + b), std::sin(th) * (1 + a),
      std::cos(th) * (1 + b);
  const Eigen::Matrix2d Finv = F.inverse();
  const SpecklePattern pat(-20, -20, n + 20, n + 20, SpeckleParams{});
  cv::imwrite(p("ref.png"), speckle(pat, n, n, identity, 1.0, 7));
  cv::imwrite(p("def.png"), speckle(
                                pat, n, n,
                                [&](const Eigen::Vector2d& x) {
                                  const Eigen::Vector2d c(c0, c0);
                                  return Eigen::Vector2d(c + Finv * (x - c));
                                },
                                1.0, 8));
  const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
  const Eigen::Vector3d green(E(0, 0), E(1, 1), E(0, 1));
  const Eigen::Vector3d small(F(0, 0) - 1, F(1, 1) - 1, 0.5 * (F(0, 1) + F(1, 0)));
  ASSERT_NEAR(green[0], 0.01005, 1e-12);
  ASSERT_NEAR(green[2], 0.0, 1e-12);
  ASSERT_GT(green[0] - small[0], 1.3e-3);
  const std::string common = "dic " + p("ref.png") + " " + p("def.png") +
                             " --subset 21 --step 4 --strain-window 7 --threads 2 -o ";
  ASSERT_EQ(granoscope(common + p("g.h5"), dir).rc, 0);  // default: green
  ASSERT_EQ(granoscope(common + p("s.h5") + " --strain small", dir).rc, 0);
  ASSERT_EQ(granoscope(common + p("e.h5") + " --strain green", dir).rc, 0);
  EXPECT_EQ(h5::attr_string(dir / "g.h5", "strain_csv_vtk"), "green-lagrange");
  EXPECT_EQ(h5::attr_string(dir / "s.h5", "strain_csv_vtk"), "small");
  const char* names[3] = {"exx", "eyy", "exy"};
  for (const auto& [stem, expect] : std::vector<std::pair<std::string, Eigen::Vector3d>>{
           {"g", green}, {"s", small}, {"e", green}}) {
    const Table t = read_csv(dir / (stem + "_0001.csv"));
    const fs::path h = dir / (stem + ".h5");
    const bool is_small = stem == "s";
    for (int k = 0; k < 3; ++k) {
      const auto ref = h5::read(h, std::string("/") + names[k] + (is_small ? "_small" : ""));
      double sum = 0.0;
      int cnt = 0;
      for (std::size_t i = 0; i < t.rows; ++i) {
        const double e = t[names[k]][i];
        if (!std::isfinite(e)) continue;
        EXPECT_NEAR(e, ref[i], 1e-12 + 1e-9 * std::abs(ref[i]));  // CSV = HDF5 to 10 digits
        sum += e;
        ++cnt;
      }
      ASSERT_GT(cnt, 500) << stem;  // of 27 x 27 POIs
      EXPECT_NEAR(sum / cnt, expect[k], 2e-4) << stem << " " << names[k];
      RecordProperty(stem + "_" + names[k] + "_mean_error", std::to_string(sum / cnt - expect[k]));
    }
  }
  // The VTI strain array follows --strain too.
  int dims[3];
  double origin[3], spacing[3];
  const auto vs = vti_array(dir / "s_0001.vti", "exx", dims, origin, spacing);
  const auto hs = h5::read(dir / "s.h5", "/exx_small");
  ASSERT_EQ(vs.size(), hs.size());
  for (std::size_t i = 0; i < vs.size(); ++i)
    if (std::isfinite(hs[i])) {
      EXPECT_EQ(vs[i], hs[i]);
    }
  // Bad value.
  expect_one_line_error(granoscope(common + p("x.h5") + " --strain log", dir),
                        "--strain: must be green or small (log)");
}

// --zncc-min: the right 36 px of the deformed image are replaced by an unrelated speckle
// pattern. Exact answers: in every run a POI is valid only if its ZNCC >= the threshold; at the
// default 0.9 every POI whose subset lies wholly left of the band is valid with u = 1.3 px (to
// 0.04 px; measured worst 0.023 px) and every POI whose subset is at least half in the band is
// invalid (u = NaN); at 0.5 more POIs are valid (measured 1024 against 858), every extra one with
// 0.5 <= ZNCC < 0.9 and a subset reaching into the band.
TEST_F(DicCli, ZnccMinRejectsPointsBelowTheThreshold) {
  const int rows = 72, cols = 120, band = 84;
  const SpecklePattern pat(-10, -10, cols + 10, rows + 10, SpeckleParams{});
  SpeckleParams other;
  other.seed = 99;
  const SpecklePattern junk(-10, -10, cols + 10, rows + 10, other);
  cv::imwrite(p("ref.png"), speckle(pat, rows, cols, identity, 1.0, 7));
  cv::Mat def = speckle(
      pat, rows, cols,
      [](const Eigen::Vector2d& x) { return Eigen::Vector2d(x.x() - 1.3, x.y() - 0.4); }, 1.0, 8);
  speckle(junk, rows, cols, identity, 1.0, 9)(cv::Rect(band, 0, cols - band, rows))
      .copyTo(def(cv::Rect(band, 0, cols - band, rows)));
  cv::imwrite(p("def.png"), def);
  const std::string common =
      "dic " + p("ref.png") + " " + p("def.png") + " --subset 21 --step 2 -o ";
  ASSERT_EQ(granoscope(common + p("d.h5"), dir).rc, 0);  // default --zncc-min 0.9
  ASSERT_EQ(granoscope(common + p("l.h5") + " --zncc-min 0.5", dir).rc, 0);
  const Table d = read_csv(dir / "d_0001.csv"), l = read_csv(dir / "l_0001.csv");
  ASSERT_EQ(d.rows, l.rows);
  int left = 0, inside = 0, extra = 0, valid_d = 0, valid_l = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < d.rows; ++i) {
    const double x = d["x"][i];
    for (const auto* t : {&d, &l}) {
      const double zmin = t == &d ? 0.9 : 0.5;
      if ((*t)["valid"][i] == 1.0) {
        EXPECT_GE((*t)["zncc"][i], zmin) << x;
        EXPECT_TRUE(std::isfinite((*t)["u"][i]));
      } else {
        EXPECT_TRUE(std::isnan((*t)["u"][i])) << x;
      }
    }
    valid_d += d["valid"][i] == 1.0;
    valid_l += l["valid"][i] == 1.0;
    if (x + 10 < band) {  // subset wholly left of the band
      ++left;
      EXPECT_EQ(d["valid"][i], 1.0) << x;
      EXPECT_NEAR(d["u"][i], 1.3, 0.04) << x;
      worst = std::max(worst, std::abs(d["u"][i] - 1.3));
    }
    if (x >= band) {  // at least 11 of the 21 columns in the band
      ++inside;
      EXPECT_EQ(d["valid"][i], 0.0) << x;
    }
    if (l["valid"][i] == 1.0 && d["valid"][i] == 0.0) {
      ++extra;
      EXPECT_LT(l["zncc"][i], 0.9) << x;
      EXPECT_GT(x + 10, band) << "an extra valid POI away from the band edge";
    }
  }
  EXPECT_GT(left, 0);
  EXPECT_GT(inside, 0);
  EXPECT_GT(extra, 0);
  EXPECT_EQ(valid_l - valid_d, extra);  // every POI valid at 0.9 is valid at 0.5
  RecordProperty("valid_at_0.9", valid_d);
  RecordProperty("valid_at_0.5", valid_l);
  RecordProperty("worst_u_error_left_px", std::to_string(worst));
  expect_one_line_error(granoscope(common + p("x.h5") + " --zncc-min 1.5", dir),
                        "--zncc-min: must be in (-1, 1) (1.5)");
}

// --search: a (12, 0.4) px translation. Exact answers: with the default search (30 px) and with
// 14 px the 304 POIs whose deformed subset stays in the image are valid with u = 12 px, v = 0.4
// px (to 0.04 px; measured worst 0.030 px over this test); with 4 px the integer seeds cannot
// reach it, no seed correlates, and the command fails with one line naming the reference image,
// exit 2, no output. A (0.4, 0.3) px motion needs no search at all (--search 0).
TEST_F(DicCli, SearchRangeTooSmallFailsToFindALargeMotion) {
  const int n = 96;
  const SpecklePattern pat(-30, -10, n + 10, n + 10, SpeckleParams{});
  cv::imwrite(p("ref.png"), speckle(pat, n, n, identity, 1.0, 7));
  cv::imwrite(p("big.png"), speckle(
                                pat, n, n,
                                [](const Eigen::Vector2d& x) {
                                  return Eigen::Vector2d(x.x() - 12.0, x.y() - 0.4);
                                },
                                1.0, 8));
  cv::imwrite(p("tiny.png"), speckle(
                                 pat, n, n,
                                 [](const Eigen::Vector2d& x) {
                                   return Eigen::Vector2d(x.x() - 0.4, x.y() - 0.3);
                                 },
                                 1.0, 8));
  const std::string common = " --subset 21 --step 4 -o ";
  double worst = 0.0;
  for (const char* search : {"", " --search 14"}) {
    ASSERT_EQ(
        granoscope("dic " + p("ref.png") + " " + p("big.png") + search + common + p("b.h5"), dir)
            .rc,
        0);
    const Table t = read_csv(dir / "b_0001.csv");
    int valid = 0;
    for (std::size_t i = 0; i < t.rows; ++i) {
      if (t["valid"][i] != 1.0) continue;
      ++valid;
      EXPECT_NEAR(t["u"][i], 12.0, 0.04) << search;
      EXPECT_NEAR(t["v"][i], 0.4, 0.04) << search;
      worst = std::max({worst, std::abs(t["u"][i] - 12.0), std::abs(t["v"][i] - 0.4)});
    }
    // 19 x 19 POIs (x, y = 10..82); the deformed subset stays inside the image for x + 22 <= 95,
    // i.e. 16 columns: 16 x 19 = 304.
    EXPECT_EQ(valid, 304) << search;
    fs::remove(dir / "b.h5");
  }
  const CliRun fail = granoscope(
      "dic " + p("ref.png") + " " + p("big.png") + " --search 4" + common + p("f.h5"), dir);
  expect_one_line_error(
      fail, p("ref.png") + ": correlation failed (image 2: no seed reached the ZNCC threshold");
  EXPECT_FALSE(fs::exists(dir / "f.h5"));
  EXPECT_FALSE(fs::exists(dir / "f_0001.csv"));
  ASSERT_EQ(
      granoscope("dic " + p("ref.png") + " " + p("tiny.png") + " --search 0" + common + p("t.h5"),
                 dir)
          .rc,
      0);
  const Table t = read_csv(dir / "t_0001.csv");
  for (std::size_t i = 0; i < t.rows; ++i) {
    EXPECT_EQ(t["valid"][i], 1.0);
    EXPECT_NEAR(t["u"][i], 0.4, 0.04);
    EXPECT_NEAR(t["v"][i], 0.3, 0.04);
    worst = std::max({worst, std::abs(t["u"][i] - 0.4), std::abs(t["v"][i] - 0.3)});
  }
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("tiny.png") + " --search -1" + common + p("x.h5"),
                 dir),
      "--search: must be >= 0 px (-1)");
  RecordProperty("worst_error_px", std::to_string(worst));
}

TEST_F(DicCli, QuadraticShapeRecoversTheTranslationToo) {
  // --shape quadratic on the translation pair: the same motion within the same bounds, and the
  // choice recorded in the file.
  translation_pair();
  const CliRun r = granoscope("dic " + p("ref.png") + " " + p("def.png") + " -o " + p("q.h5") +
                                  " --subset 21 --step 4 --strain-window 5 --shape quadratic",
                              dir);
  ASSERT_EQ(r.rc, 0) << r.err;
  const fs::path h = dir / "q.h5";
  EXPECT_EQ(h5::attr_string(h, "shape_function"), "quadratic");
  const auto u = h5::read(h, "/u"), v = h5::read(h, "/v"), valid = h5::read(h, "/valid");
  double worst = 0.0;
  for (std::size_t k = 0; k < u.size(); ++k) {
    ASSERT_EQ(valid[k], 1.0) << k;
    worst = std::max({worst, std::abs(u[k] - 1.3), std::abs(v[k] - 0.4)});
  }
  EXPECT_LT(worst, 0.05);
  RecordProperty("worst_displacement_error_px", std::to_string(worst));
}

TEST_F(DicCli, BadInputsGiveOneLineErrors) {
  translation_pair();
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("missing.png") + " -o " + p("o.h5"), dir),
      p("missing.png") + ": no such image file");
  cv::imwrite(p("small.png"), cv::Mat(40, 40, CV_8U, cv::Scalar(3)));
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("small.png") + " -o " + p("o.h5"), dir),
      p("small.png") + ": image size differs from the reference (40x40 vs 80x72)");
  cv::imwrite(p("flat.png"), cv::Mat(72, 80, CV_8U, cv::Scalar(128)));
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("flat.png") + " -o " + p("o.h5"), dir),
      p("flat.png") + ": image has no texture (uniform grey level)");
  cv::imwrite(p("roi.png"), cv::Mat(72, 80, CV_8U, cv::Scalar(0)));
  expect_one_line_error(granoscope("dic " + p("ref.png") + " " + p("def.png") + " --roi " +
                                       p("roi.png") + " -o " + p("o.h5"),
                                   dir),
                        p("roi.png") + ": ROI contains no point of interest");
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("def.png") + " --subset 30 -o " + p("o.h5"), dir),
      "--subset: must be an odd number of px >= 5 (30)");
  expect_one_line_error(
      granoscope("dic " + p("ref.png") + " " + p("def.png") + " --shape cubic -o " + p("o.h5"),
                 dir),
      "--shape: must be affine or quadratic (cubic)");
  // Issue 15: a plane-fit window wider than the 15 x 13 POI grid gave all-NaN strains, exit 0.
  const auto wide = granoscope("dic " + p("ref.png") + " " + p("def.png") +
                                   " --subset 21 --step 4 --strain-window 15 -o " + p("o.h5"),
                               dir);
  EXPECT_EQ(wide.rc, 2);
  EXPECT_EQ(wide.err, "error: --strain-window: larger than the POI grid (15 POIs; grid 15 x 13)\n");
  EXPECT_FALSE(fs::exists(dir / "o.h5"));
}

// --help documents every option with the defaults of docs/dic.md (exact option lines as CLI11
// prints them), exit code 0, nothing on stderr.
TEST_F(DicCli, HelpListsTheOptionsWithTheirDefaults) {
  const CliRun dic = granoscope("dic --help", dir);
  EXPECT_EQ(dic.rc, 0);
  EXPECT_EQ(dic.err, "");
  for (const char* opt :
       {"--subset INT=31", "--step INT=2", "--roi TEXT", "--incremental", "--strain-window INT=15",
        "--strain TEXT=green", "--zncc-min FLOAT=0.9", "--search INT=30",
        "--threads INT:INT in [0 - 1024]=0", "--no-csv", "--no-vtk", "--shape TEXT=affine"})
    EXPECT_NE(dic.out.find(opt), std::string::npos) << opt << "\n" << dic.out;
  const CliRun render = granoscope("render --help", dir);
  EXPECT_EQ(render.rc, 0);
  EXPECT_EQ(render.err, "");
  for (const char* opt :
       {"--view TEXT=front", "--px-per-d50 FLOAT=25", "--margin FLOAT=0.5", "--supersample INT=3",
        "--noise FLOAT=0", "--bits INT=8", "--format TEXT=png", "--seed UINT=1"})
    EXPECT_NE(render.out.find(opt), std::string::npos) << opt << "\n" << render.out;
}
