// `granoscope figures` runs every shipped figure script that no other test runs (fig_dic,
// fig_strain for strain and void cells, fig_history, fig_labcurve; fig_positions through the
// default trajectory set) on small inputs made here, through the real CLI and --type. Each PNG
// must be a complete PNG of the size its figure's tight bounding box predicts at 150 dpi, and
// what it plots must be the input: the interpreter is wrapped (GRANOSCOPE_PYTHON) by a probe
// that records, beside each PNG, the data of every artist (lines, images, collections, bars,
// texts, titles) at the moment the script saves it, and the test compares those numbers with
// the HDF5 / CSV input. Without a Python that imports matplotlib, numpy and h5py the tests skip.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../dic/h5_read.hpp"
#include "field_output.hpp"
#include "hdf5_trajectory.hpp"
#include "speckle_synthetic.hpp"

namespace fs = std::filesystem;
namespace h5 = gs::test::h5;

namespace {

const std::string kExe = std::string(GS_BINARY_DIR) + "/bin/granoscope";
const fs::path kData = GS_TEST_DATA_DIR;

std::string slurp(const fs::path& p) {
  std::ifstream is(p, std::ios::binary);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

struct CliRun {
  int rc;
  std::string out, err;
};

// The interpreter the project would use (GRANOSCOPE_PYTHON, /usr/bin/python3, python3), if one
// imports matplotlib, numpy and h5py; empty otherwise.
std::string find_python() {
  std::vector<std::string> c;
  if (const char* e = std::getenv("GRANOSCOPE_PYTHON"); e && *e) c.emplace_back(e);
  c.emplace_back("/usr/bin/python3");
  c.emplace_back("python3");
  for (const auto& py : c) {
    if (py.find('\'') != std::string::npos) continue;
    const std::string cmd = "'" + py + "' -c 'import matplotlib, numpy, h5py' >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return py;
  }
  return {};
}

// Runs the figure script with figutil.save wrapped: before each save, `<png>.plotted.txt`
// records the figure. Line format: `<tag> <axes> <index> <count> <values...>` for numbers (repr,
// exact), `<tag> <axes> <index> <text>` for text; axes -1 is the figure.
const char* kProbe = R"PY(
import os, runpy, sys
script = sys.argv[1]
sys.argv = sys.argv[1:]
sys.path.insert(0, os.path.dirname(os.path.abspath(script)))
import numpy as np
import figutil
from matplotlib.collections import PolyCollection
from matplotlib.quiver import Quiver

def nums(out, tag, ax, k, values):
    a = np.ma.filled(np.ma.asarray(values, dtype=float), np.nan).ravel()
    out.append("%s %d %d %d %s" % (tag, ax, k, a.size, " ".join(repr(float(v)) for v in a)))

def text(out, tag, ax, k, s):
    out.append("%s %d %d %s" % (tag, ax, k, str(s).replace("\n", "\\n")))

def dump(fig, path, dpi):
    out = []
    saved = fig.dpi
    fig.set_dpi(dpi)
    bb = fig.get_tightbbox(fig.canvas.get_renderer()).padded(0.1)
    fig.set_dpi(saved)
    w, h = fig.get_size_inches()
    nums(out, "figsize", -1, 0, [w * dpi, h * dpi])
    nums(out, "tight", -1, 0, [bb.width * dpi, bb.height * dpi])
    for i, ax in enumerate(fig.axes):
        text(out, "title", i, 0, ax.get_title())
        text(out, "xlabel", i, 0, ax.get_xlabel())
        text(out, "ylabel", i, 0, ax.get_ylabel())
        for k, l in enumerate(ax.get_lines()):
            text(out, "line_label", i, k, l.get_label())
            nums(out, "line_x", i, k, l.get_xdata())
            nums(out, "line_y", i, k, l.get_ydata())
        for k, im in enumerate(ax.get_images()):
            a = im.get_array()
            nums(out, "image_shape", i, k, a.shape)
            nums(out, "image", i, k, a)
            nums(out, "image_extent", i, k, im.get_extent())
            nums(out, "image_clim", i, k, im.get_clim())
        for k, c in enumerate(ax.collections):
            text(out, "coll_type", i, k, type(c).__name__)
            nums(out, "coll_offsets", i, k, c.get_offsets())
            arr = c.get_array()
            if arr is not None:
                nums(out, "coll_array", i, k, arr)
                nums(out, "coll_clim", i, k, c.get_clim())
            if isinstance(c, PolyCollection):
                nums(out, "coll_path_sizes", i, k, [len(p.vertices) for p in c.get_paths()])
                nums(out, "coll_paths", i, k, np.concatenate([p.vertices for p in c.get_paths()])
                     if c.get_paths() else [])
            if isinstance(c, Quiver):
                nums(out, "quiver_uv", i, k, np.column_stack([c.U, c.V]))
        for k, p in enumerate(ax.patches):
            if hasattr(p, "get_height"):
                nums(out, "bar", i, k, [p.get_x(), p.get_width(), p.get_height()])
        for k, t in enumerate(ax.texts):
            text(out, "text", i, k, t.get_text())
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")

_save = figutil.save
def save(fig, out_dir, name, dpi=150):
    dump(fig, os.path.join(out_dir, name + ".plotted.txt"), dpi)
    return _save(fig, out_dir, name, dpi)
figutil.save = save
runpy.run_path(script, run_name="__main__")
)PY";

// What a figure plots, as recorded by the probe.
struct Plotted {
  std::map<std::string, std::string> entry;  // "tag axes index" -> rest of the line
  static std::string key(const std::string& tag, int ax, int k) {
    return tag + " " + std::to_string(ax) + " " + std::to_string(k);
  }
  bool has(const std::string& tag, int ax, int k = 0) const {
    return entry.count(key(tag, ax, k)) > 0;
  }
  std::string text(const std::string& tag, int ax, int k = 0) const {
    const auto it = entry.find(key(tag, ax, k));
    return it == entry.end() ? std::string("<missing " + key(tag, ax, k) + ">") : it->second;
  }
  std::vector<double> nums(const std::string& tag, int ax, int k = 0) const {
    std::vector<double> v;
    const auto it = entry.find(key(tag, ax, k));
    if (it == entry.end()) {
      ADD_FAILURE() << "nothing plotted under " << key(tag, ax, k);
      return v;
    }
    std::istringstream s(it->second);
    std::size_t n = 0;
    s >> n;
    std::string tok;
    while (s >> tok) v.push_back(std::strtod(tok.c_str(), nullptr));
    EXPECT_EQ(v.size(), n) << key(tag, ax, k);
    return v;
  }
  /// Index of the axes with this title (-1 if none).
  int axes(const std::string& title) const {
    for (int i = 0; has("title", i); ++i)
      if (text("title", i) == title) return i;
    return -1;
  }
  int count(const std::string& tag, int ax) const {
    int k = 0;
    while (has(tag, ax, k)) ++k;
    return k;
  }
};

Plotted read_plotted(const fs::path& png) {
  Plotted p;
  std::ifstream in(png.string() + ".plotted.txt");
  EXPECT_TRUE(in.good()) << "no probe record for " << png;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag, rest;
    int ax = 0, k = 0;
    s >> tag >> ax >> k;
    std::getline(s, rest);
    if (!rest.empty() && rest.front() == ' ') rest.erase(0, 1);
    p.entry[Plotted::key(tag, ax, k)] = rest;
  }
  return p;
}

std::uint32_t be32(const std::string& s, std::size_t at) {
  return (std::uint32_t(static_cast<unsigned char>(s[at])) << 24) |
         (std::uint32_t(static_cast<unsigned char>(s[at + 1])) << 16) |
         (std::uint32_t(static_cast<unsigned char>(s[at + 2])) << 8) |
         std::uint32_t(static_cast<unsigned char>(s[at + 3]));
}

// A complete PNG (signature, IHDR first, IEND last, decodable) whose size is the one the
// figure's tight bounding box at 150 dpi predicts (to 2 px: matplotlib rounds the box), inside
// [0.5, 1.3] x the figure size, and not blank.
void expect_valid_png(const fs::path& png, const Plotted& p) {
  const std::string b = slurp(png);
  ASSERT_GT(b.size(), 100u) << png;
  EXPECT_EQ(b.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)), 0) << png;
  EXPECT_EQ(be32(b, 8), 13u);
  EXPECT_EQ(b.compare(12, 4, "IHDR"), 0) << png;
  EXPECT_EQ(b.compare(b.size() - 12, 12, std::string("\0\0\0\0IEND\xae\x42\x60\x82", 12)), 0)
      << png << ": truncated";
  const double w = be32(b, 16), h = be32(b, 20);
  const auto tight = p.nums("tight", -1), size = p.nums("figsize", -1);
  ASSERT_EQ(tight.size(), 2u);
  EXPECT_NEAR(w, tight[0], 2.0) << png;
  EXPECT_NEAR(h, tight[1], 2.0) << png;
  EXPECT_GT(w, 0.5 * size[0]) << png;
  EXPECT_LT(w, 1.3 * size[0]) << png;
  EXPECT_GT(h, 0.5 * size[1]) << png;
  EXPECT_LT(h, 1.3 * size[1]) << png;
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(img.empty()) << png;
  EXPECT_EQ(img.cols, static_cast<int>(w));
  EXPECT_EQ(img.rows, static_cast<int>(h));
  cv::Scalar mean, sd;
  cv::meanStdDev(img, mean, sd);
  EXPECT_GT(sd[0], 10.0) << png << ": blank";
}

// Exact equality of two arrays, NaN matching NaN.
void expect_same(const std::vector<double>& got, const std::vector<double>& want,
                 const std::string& what, double tol = 0.0) {
  ASSERT_EQ(got.size(), want.size()) << what;
  std::size_t bad = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const bool both_nan = std::isnan(got[i]) && std::isnan(want[i]);
    if (!both_nan && !(std::abs(got[i] - want[i]) <= tol)) {
      if (bad++ < 5) ADD_FAILURE() << what << "[" << i << "]: " << got[i] << " vs " << want[i];
    }
  }
  EXPECT_EQ(bad, 0u) << what;
}

// numpy.percentile (linear interpolation) of |finite values|.
double abs_percentile(const std::vector<double>& v, double q) {
  std::vector<double> a;
  for (double x : v)
    if (std::isfinite(x)) a.push_back(std::abs(x));
  std::sort(a.begin(), a.end());
  const double r = q / 100.0 * static_cast<double>(a.size() - 1);
  const auto i = static_cast<std::size_t>(std::floor(r));
  const std::size_t j = std::min(i + 1, a.size() - 1);
  return a[i] + (r - static_cast<double>(i)) * (a[j] - a[i]);
}

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

// CSV with a header row, numeric cells ("nan" allowed).
std::map<std::string, std::vector<double>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> head;
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) head.push_back(c);
  std::map<std::string, std::vector<double>> col;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::size_t k = 0;
    for (std::string c; std::getline(ls, c, ','); ++k)
      col[head.at(k)].push_back(std::strtod(c.c_str(), nullptr));
  }
  return col;
}

class Figures : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("gs_figures_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string py = find_python();
    if (py.empty()) GTEST_SKIP() << "no Python 3 with matplotlib, numpy and h5py";
    std::ofstream(dir / "probe.py") << kProbe;
    wrapper = dir / "python";
    std::ofstream(wrapper) << "#!/bin/sh\nif [ \"$1\" = -c ]; then exec '" << py
                           << "' \"$@\"; fi\nexec '" << py << "' '" << (dir / "probe.py").string()
                           << "' \"$@\"\n";
    fs::permissions(wrapper, fs::perms::owner_all);
  }
  void TearDown() override {  // GS_KEEP=1 keeps inputs and figures
    if (!std::getenv("GS_KEEP")) fs::remove_all(dir);
  }
  std::string p(const std::string& name) const { return (dir / name).string(); }
  /// lab.h5: one frame of one particle, beside which a test writes curve.csv (fig_labcurve).
  void write_lab_trajectory() const {
    gs::Trajectory t;
    gs::Frame f;
    gs::Particle q;
    q.id = 1;
    q.radius = 1e-3;
    f.particles.push_back(q);
    t.frames = {f};
    gs::write_hdf5_trajectory(dir / "lab.h5", t);
  }
  CliRun run(const std::string& args, bool probe = true) const {
    const auto o = dir / "stdout.txt", e = dir / "stderr.txt";
    const std::string env = probe ? "GRANOSCOPE_PYTHON='" + wrapper.string() + "' " : "";
    const std::string cmd =
        env + kExe + " " + args + " > " + o.string() + " 2> " + e.string() + " < /dev/null";
    const int status = std::system(cmd.c_str());
    CliRun r{WIFEXITED(status) ? WEXITSTATUS(status) : 128, slurp(o), slurp(e)};
    fs::remove(o);
    fs::remove(e);
    return r;
  }
  std::vector<std::string> pngs(const fs::path& d) const {
    std::vector<std::string> v;
    if (!fs::is_directory(d)) return v;
    for (const auto& e : fs::directory_iterator(d)) {
      EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
      if (e.path().extension() == ".png") v.push_back(e.path().filename().string());
    }
    std::sort(v.begin(), v.end());
    return v;
  }
  fs::path dir, wrapper;
};

cv::Mat speckle(const gs::dic::SpecklePattern& pat, int n,
                const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& inverse,
                std::uint64_t seed) {
  gs::dic::RenderParams rp;
  rp.noise_sigma = 1.0;
  rp.noise_seed = seed;
  rp.quantize_8bit = true;
  cv::Mat img = gs::dic::render_speckle(pat, n, n, inverse, rp);
  img.convertTo(img, CV_8U);
  return img;
}

}  // namespace

// fig_dic (--type dic, --frame): u, v, Exx, Eyy, Exy maps of `granoscope dic` over the reference
// image. Exact answers: one PNG per field named dic_<field>_<image>.png; the reference image
// plotted is ref.png / 255; each field image is the HDF5 field of the chosen frame with NaN where
// invalid, on the extent [x0 - s/2, x1 + s/2, y1 + s/2, y0 - s/2] of the POI grid, colour limits
// +-(99th percentile of |field|); the title names the field, image, subset and VSG. The plotted
// values are the imposed motion: frame 0 a (1.3, 0.4) px translation (u to 0.04 px), frame 1
// x = c + F (X - c), F = R(0.05) diag(1.01, 0.995) (u, v to 0.05 px of (F - I)(X - c), mean
// Exx 0.01005 to 2e-4, mean Exy 0 to 2e-4).
class DicFigures : public Figures {
 protected:
  // d.h5: `granoscope dic` of ref.png against d1.png (translation) and d2.png (affine).
  void SetUp() override {
    Figures::SetUp();
    if (IsSkipped()) return;
    const double th = 0.05;
    F << std::cos(th) * 1.01, -std::sin(th) * 0.995, std::sin(th) * 1.01, std::cos(th) * 0.995;
    const Eigen::Matrix2d Finv = F.inverse();
    const gs::dic::SpecklePattern pat(-20, -20, n + 20, n + 20, gs::dic::SpeckleParams{});
    const auto id = [](const Eigen::Vector2d& x) { return x; };
    cv::imwrite(p("ref.png"), speckle(pat, n, id, 7));
    cv::imwrite(
        p("d1.png"),
        speckle(
            pat, n,
            [](const Eigen::Vector2d& x) { return Eigen::Vector2d(x.x() - 1.3, x.y() - 0.4); }, 8));
    cv::imwrite(p("d2.png"), speckle(
                                 pat, n,
                                 [&](const Eigen::Vector2d& x) {
                                   const Eigen::Vector2d c(c0, c0);
                                   return Eigen::Vector2d(c + Finv * (x - c));
                                 },
                                 9));
    ASSERT_EQ(run("dic " + p("ref.png") + " " + p("d1.png") + " " + p("d2.png") +
                      " --subset 21 --step 4 --strain-window 5 --no-vtk -o " + p("d.h5"),
                  false)
                  .rc,
              0);
  }
  // Runs `figures d.h5 --type dic` for one frame and checks the five maps.
  void check_maps(int frame) {
    const fs::path h = dir / "d.h5";
    const auto x = h5::read(h, "/x"), y = h5::read(h, "/y"), valid = h5::read(h, "/valid");
    const std::size_t nx = x.size(), ny = y.size(), plane = nx * ny;
    const cv::Mat ref = cv::imread(p("ref.png"), cv::IMREAD_GRAYSCALE);
    std::vector<double> ref01;
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) ref01.push_back(ref.at<std::uint8_t>(r, c) / 255.0);
    const std::vector<std::pair<std::string, std::string>> fields = {{"u", "u (px)"},
                                                                     {"v", "v (px)"},
                                                                     {"exx", "$E_{xx}$"},
                                                                     {"eyy", "$E_{yy}$"},
                                                                     {"exy", "$E_{xy}$"}};
    const std::string out = "f" + std::to_string(frame);
    const CliRun r = run("figures " + p("d.h5") + " -o " + p(out) + " --type dic" +
                         (frame == 0 ? " --frame 0" : ""));  // default --frame -1: the last
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(r.err, "");
    const std::string image = std::to_string(frame + 1);
    std::vector<std::string> want, printed;
    for (const auto& [name, label] : fields)
      want.push_back("dic_" + name + "_000" + image + ".png");
    std::sort(want.begin(), want.end());
    EXPECT_EQ(pngs(dir / out), want);
    for (const auto& l : lines_of(r.out)) printed.push_back(fs::path(l).filename().string());
    std::sort(printed.begin(), printed.end());
    EXPECT_EQ(printed, want);
    for (const auto& [name, label] : fields) {
      const fs::path png = dir / out / ("dic_" + name + "_000" + image + ".png");
      const Plotted pl = read_plotted(png);
      expect_valid_png(png, pl);
      EXPECT_EQ(pl.text("title", 0), label + ", image " + image + " (subset 21 px, VSG 37 px)");
      ASSERT_EQ(pl.count("image_shape", 0), 2) << name;
      expect_same(pl.nums("image_shape", 0, 0), {double(n), double(n)}, name + " background");
      expect_same(pl.nums("image", 0, 0), ref01, name + " background", 1e-7);
      const auto field = h5::read(h, "/" + name);
      std::vector<double> want_field(field.v.begin() + static_cast<long>(frame * plane),
                                     field.v.begin() + static_cast<long>((frame + 1) * plane));
      for (std::size_t k = 0; k < plane; ++k)
        if (valid[frame * plane + k] != 1.0) want_field[k] = std::nan("");
      expect_same(pl.nums("image_shape", 0, 1), {double(ny), double(nx)}, name);
      const auto plotted = pl.nums("image", 0, 1);
      expect_same(plotted, want_field, name + " field");
      expect_same(pl.nums("image_extent", 0, 1),
                  {x[0] - 2.0, x[nx - 1] + 2.0, y[ny - 1] + 2.0, y[0] - 2.0}, name + " extent");
      const double lim = abs_percentile(want_field, 99.0);
      expect_same(pl.nums("image_clim", 0, 1), {-lim, lim}, name + " clim", 1e-15);
      // The plotted numbers are the imposed motion.
      double worst = 0.0, sum = 0.0;
      int cnt = 0;
      for (std::size_t k = 0; k < plane; ++k) {
        if (!std::isfinite(plotted[k])) continue;
        const Eigen::Vector2d X(x[k % nx], y[k / nx]), c(c0, c0);
        const Eigen::Vector2d disp =
            frame == 0 ? Eigen::Vector2d(1.3, 0.4)
                       : Eigen::Vector2d((F - Eigen::Matrix2d::Identity()) * (X - c));
        if (name == "u") worst = std::max(worst, std::abs(plotted[k] - disp.x()));
        if (name == "v") worst = std::max(worst, std::abs(plotted[k] - disp.y()));
        sum += plotted[k];
        ++cnt;
      }
      ASSERT_GT(cnt, 300) << name;
      if (name == "u" || name == "v") {
        EXPECT_LT(worst, frame == 0 ? 0.04 : 0.05) << name;
      }
      if (frame == 1 && name == "exx") {
        EXPECT_NEAR(sum / cnt, 0.5 * (F.col(0).squaredNorm() - 1), 2e-4);
      }
      if (frame == 1 && name == "exy") {
        EXPECT_NEAR(sum / cnt, 0.0, 2e-4);
      }
    }
  }
  const int n = 96;
  const double c0 = 0.5 * (n - 1);
  Eigen::Matrix2d F;
};

TEST_F(DicFigures, DefaultFrameIsTheLastImage) {
  check_maps(1);
}

// --frame 0 plots the first deformed image; a frame out of range or a type the input has no
// figure for is one error line, exit 2, no figure.
TEST_F(DicFigures, FrameOptionAndBadInput) {
  check_maps(0);
  // Bad frame and type: one line, exit 2, no figure.
  const CliRun bad = run("figures " + p("d.h5") + " -o " + p("bad") + " --type dic --frame 5");
  EXPECT_EQ(bad.rc, 2);
  EXPECT_EQ(bad.err, "error: " + p("d.h5") + ": fig_dic: frame index out of range (5 of 2)\n");
  EXPECT_TRUE(pngs(dir / "bad").empty());
  const CliRun type = run("figures " + p("d.h5") + " -o " + p("bad") + " --type positions");
  EXPECT_EQ(type.rc, 2);
  EXPECT_EQ(type.err,
            "error: " + p("d.h5") + ": figure type not available for granoscope-dic (positions)\n");
}

// fig_strain on `analyze strain` (2D, --type strain): a homogeneous motion x -> x + h x,
// h = [[0.01, 0.004], [-0.002, -0.006]]. Exact answers: the maps scatter every valid particle at
// its position with the volumetric strain tr h = 0.004 and the equivalent shear strain
// sqrt(|dev sym h|^2 / 2) = sqrt(6.5e-5) (to 1e-12), colour limits +-0.004 and [0, 0.0080623];
// the histogram counts every valid particle in one bar; the triangle alpha map draws every
// non-sliver triangle (3 vertices each, at the particle positions) with alpha clipped to [0, 1]
// as in the HDF5.
TEST_F(Figures, StrainMapsPlotTheImposedHomogeneousStrain) {
  gs::Frame a;
  a.two_d = true;
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 0.01);
  for (int i = 0; i < 120; ++i) {
    gs::Particle q;
    q.id = i + 1;
    q.position = Eigen::Vector3d(u(rng), u(rng), 0.0);
    q.radius = 2e-4;
    a.particles.push_back(q);
  }
  Eigen::Matrix3d hm = Eigen::Matrix3d::Zero();
  hm.topLeftCorner<2, 2>() << 0.01, 0.004, -0.002, -0.006;
  gs::Frame b = a;
  b.time = 1.0;
  for (auto& q : b.particles) q.position += hm * q.position;
  gs::Trajectory t;
  t.frames = {a, b};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  ASSERT_EQ(run("analyze strain " + p("run.h5") + " --to 1 -o " + p("s.h5"), false).rc, 0);
  const CliRun r = run("figures " + p("s.h5") + " -o " + p("f") + " --type strain");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(pngs(dir / "f"),
            (std::vector<std::string>{"strain_maps.png", "strain_shear_histogram.png",
                                      "strain_triangles_alpha.png", "strain_triangles_w.png"}));
  const fs::path s = dir / "s.h5";
  const auto pos = h5::read(s, "/particles/position"), valid = h5::read(s, "/particles/valid"),
             vol = h5::read(s, "/particles/volumetric_strain"),
             shear = h5::read(s, "/particles/equivalent_shear_strain");
  const double vol_exact = 0.004, shear_exact = std::sqrt(6.5e-5);
  std::vector<double> offsets, vols, shears;
  for (std::size_t i = 0; i < valid.size(); ++i) {
    if (valid[i] != 1.0) continue;
    offsets.push_back(pos[3 * i]);
    offsets.push_back(pos[3 * i + 1]);
    vols.push_back(vol[i]);
    shears.push_back(shear[i]);
  }
  ASSERT_GT(vols.size(), 60u);
  const fs::path maps = dir / "f" / "strain_maps.png";
  const Plotted pm = read_plotted(maps);
  expect_valid_png(maps, pm);
  const int av = pm.axes("volumetric strain"), as = pm.axes("equivalent shear strain");
  ASSERT_GE(av, 0);
  ASSERT_GE(as, 0);
  EXPECT_EQ(pm.text("xlabel", av), "x (m)");
  expect_same(pm.nums("coll_offsets", av), offsets, "volumetric offsets");
  expect_same(pm.nums("coll_array", av), std::vector<double>(vols.size(), vol_exact),
              "volumetric strain", 1e-12);
  expect_same(pm.nums("coll_clim", av), {-vol_exact, vol_exact}, "volumetric clim", 1e-12);
  expect_same(pm.nums("coll_offsets", as), offsets, "shear offsets");
  expect_same(pm.nums("coll_array", as), std::vector<double>(shears.size(), shear_exact),
              "shear strain", 1e-12);
  expect_same(pm.nums("coll_clim", as), {0.0, shear_exact}, "shear clim", 1e-12);
  const fs::path hist = dir / "f" / "strain_shear_histogram.png";
  const Plotted ph = read_plotted(hist);
  expect_valid_png(hist, ph);
  ASSERT_EQ(ph.count("bar", 0), 60);
  double total = 0.0, lo = 1e300, hi = -1e300;
  for (int k = 0; k < 60; ++k) {
    const auto bar = ph.nums("bar", 0, k);  // x, width, height
    total += bar.at(2);
    lo = std::min(lo, bar[0]);
    hi = std::max(hi, bar[0] + bar[1]);
  }
  EXPECT_EQ(total, static_cast<double>(vols.size()));
  EXPECT_NEAR(lo, shear_exact, 0.5 + 1e-9);  // numpy widens a zero range by +-0.5
  EXPECT_LE(lo, shear_exact);
  EXPECT_GE(hi, shear_exact);
  const fs::path alpha = dir / "f" / "strain_triangles_alpha.png";
  const Plotted pa = read_plotted(alpha);
  expect_valid_png(alpha, pa);
  const auto tri = h5::read(s, "/simplices/vertices"), sliver = h5::read(s, "/simplices/sliver"),
             al = h5::read(s, "/simplices/alpha");
  std::vector<double> sizes, verts, clipped;
  for (std::size_t k = 0; k < sliver.size(); ++k) {
    if (sliver[k] != 0.0) continue;
    sizes.push_back(4);  // matplotlib closes each polygon: the first vertex again
    for (int c = 0; c <= 3; ++c) {
      const auto v = static_cast<std::size_t>(tri[3 * k + static_cast<std::size_t>(c % 3)]);
      verts.push_back(pos[3 * v]);
      verts.push_back(pos[3 * v + 1]);
    }
    clipped.push_back(std::clamp(al[k], 0.0, 1.0));
  }
  ASSERT_GT(sizes.size(), 100u);
  EXPECT_EQ(pa.text("title", 0).rfind("alignment alpha (eq 18)", 0), 0u) << pa.text("title", 0);
  expect_same(pa.nums("coll_path_sizes", 0), sizes, "triangles");
  expect_same(pa.nums("coll_paths", 0), verts, "triangle vertices");
  expect_same(pa.nums("coll_array", 0), clipped, "alpha");
  expect_valid_png(dir / "f" / "strain_triangles_w.png",
                   read_plotted(dir / "f" / "strain_triangles_w.png"));
}

// fig_strain on `analyze voidcells` (--type strain): a 6 x 6 square lattice, contacts between
// lattice neighbours, velocities v = L x. Exact answers: the alpha and w maps draw the 25 square
// void cells with the HDF5 polygons, alpha clipped to [0, 1], w shaded tanh(w / median |w|) (to
// 1e-12); the arrows start at the active particles with their relative velocities.
TEST_F(Figures, VoidCellMapsPlotEveryCell) {
  gs::Frame f;
  f.two_d = true;
  const double d = 1e-3;
  Eigen::Matrix2d L;
  L << 0.0, 0.02, -0.01, 0.005;
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i) {
      gs::Particle q;
      q.id = j * 6 + i;
      q.position = Eigen::Vector3d(i * d, j * d, 0.0);
      q.radius = 0.5 * d;
      q.velocity.head<2>() = L * q.position.head<2>();
      f.particles.push_back(q);
      for (const auto& [di, dj] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (i + di > 5 || j + dj > 5) continue;
        gs::Contact c;
        c.id1 = q.id;
        c.id2 = (j + dj) * 6 + i + di;
        c.normal = Eigen::Vector3d(di, dj, 0);
        c.point = q.position + 0.5 * d * c.normal;
        f.contacts.push_back(c);
      }
    }
  gs::Trajectory t;
  t.frames = {f};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  const CliRun a = run("analyze voidcells " + p("run.h5") + " -o " + p("v.h5"), false);
  ASSERT_EQ(a.rc, 0) << a.err;
  const CliRun r = run("figures " + p("v.h5") + " -o " + p("f") + " --type strain");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(pngs(dir / "f"),
            (std::vector<std::string>{"voidcells_alpha.png", "voidcells_relative_velocity.png",
                                      "voidcells_w.png"}));
  const fs::path v = dir / "v.h5";
  const auto off = h5::read(v, "/cells/offsets"), poly = h5::read(v, "/cells/polygon"),
             alpha = h5::read(v, "/cells/alpha"), w = h5::read(v, "/cells/w");
  ASSERT_EQ(off.size(), 26u);  // 25 cells
  std::vector<double> sizes, verts, clipped, shade;
  std::vector<double> absw;
  for (std::size_t i = 0; i < w.size(); ++i) absw.push_back(std::abs(w[i]));
  std::sort(absw.begin(), absw.end());
  const double med = absw.size() % 2 ? absw[absw.size() / 2]
                                     : 0.5 * (absw[absw.size() / 2 - 1] + absw[absw.size() / 2]);
  for (std::size_t c = 0; c + 1 < off.size(); ++c) {
    const auto b = static_cast<std::size_t>(off[c]), e = static_cast<std::size_t>(off[c + 1]);
    EXPECT_EQ(e - b, 4u) << "cell " << c << " is not a square";
    sizes.push_back(static_cast<double>(e - b + 1));  // closed by matplotlib
    for (std::size_t k = b; k <= e; ++k) {
      const std::size_t q = k == e ? b : k;
      verts.push_back(poly[2 * q]);
      verts.push_back(poly[2 * q + 1]);
    }
    clipped.push_back(std::clamp(alpha[c], 0.0, 1.0));
    shade.push_back(med > 0 ? std::tanh(w[c] / med) : 0.0);
  }
  const fs::path pa_png = dir / "f" / "voidcells_alpha.png";
  const Plotted pa = read_plotted(pa_png);
  expect_valid_png(pa_png, pa);
  expect_same(pa.nums("coll_path_sizes", 0), sizes, "cells");
  expect_same(pa.nums("coll_paths", 0), verts, "cell vertices");
  expect_same(pa.nums("coll_array", 0), clipped, "alpha");
  const fs::path pw_png = dir / "f" / "voidcells_w.png";
  const Plotted pw = read_plotted(pw_png);
  expect_valid_png(pw_png, pw);
  expect_same(pw.nums("coll_array", 0), shade, "w shade", 1e-12);
  expect_same(pw.nums("coll_clim", 0), {-1.0, 1.0}, "w clim");
  const fs::path pv_png = dir / "f" / "voidcells_relative_velocity.png";
  const Plotted pv = read_plotted(pv_png);
  expect_valid_png(pv_png, pv);
  const auto pos = h5::read(v, "/particles/position"), active = h5::read(v, "/particles/active"),
             vrel = h5::read(v, "/particles/relative_velocity");
  std::vector<double> at, uv;
  for (std::size_t k = 0; k < active.size(); ++k) {
    if (active[k] != 1.0) continue;
    at.insert(at.end(), {pos[2 * k], pos[2 * k + 1]});
    uv.insert(uv.end(), {vrel[2 * k], vrel[2 * k + 1]});
  }
  ASSERT_GT(at.size(), 0u);
  int quiver = -1;
  for (int k = 0; k < pv.count("coll_type", 0); ++k)
    if (pv.text("coll_type", 0, k) == "Quiver") quiver = k;
  ASSERT_GE(quiver, 0);
  expect_same(pv.nums("coll_offsets", 0, quiver), at, "arrow positions");
  expect_same(pv.nums("quiver_uv", 0, quiver), uv, "relative velocities");
}

// The default figures of a `granoscope simulate` run (no --type): fig_positions, fig_history
// (history.csv beside the trajectory) and fig_labcurve (curve.csv, preparation.csv). Exact
// answers: positions scatters the last frame's particles at (x, z), far ones first (descending
// y), coloured by radius in mm; history draws one |force| line per wall, in sorted name order,
// against time in ms, and the seven energy columns of history.csv, value for value.
TEST_F(Figures, RunDefaultsPositionsAndHistoryPlotTheRun) {
  ASSERT_EQ(
      run("simulate " + (kData / "scenes" / "drop.toml").string() + " -q -o " + p("drop"), false)
          .rc,
      0);
  const fs::path h5file = dir / "drop" / "drop.h5";
  const CliRun r = run("figures " + h5file.string() + " -o " + p("f"));
  ASSERT_EQ(r.rc, 0) << r.err;
  const gs::TrajectoryReader reader(h5file);
  const std::size_t last = reader.frame_count() - 1;
  char pos_name[64];
  std::snprintf(pos_name, sizeof pos_name, "drop_positions_front_%06zu.png", last);
  EXPECT_EQ(pngs(dir / "f"), (std::vector<std::string>{"drop_history.png", pos_name}));
  EXPECT_EQ(lines_of(r.out).size(), 2u) << r.out;
  // Positions.
  const gs::Frame f = reader.frame(last);
  std::vector<std::size_t> order(f.particles.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    return f.particles[i].position.y() > f.particles[j].position.y();
  });
  std::vector<double> xz, rmm;
  for (auto i : order) {
    xz.push_back(f.particles[i].position.x());
    xz.push_back(f.particles[i].position.z());
    rmm.push_back(f.particles[i].radius * 1e3);
  }
  const fs::path pp = dir / "f" / pos_name;
  const Plotted pl = read_plotted(pp);
  expect_valid_png(pp, pl);
  EXPECT_EQ(pl.text("title", 0).rfind("frame " + std::to_string(last) + ", t = ", 0), 0u);
  EXPECT_NE(pl.text("title", 0).find(std::to_string(f.particles.size()) + " particles"),
            std::string::npos);
  expect_same(pl.nums("coll_offsets", 0), xz, "positions");
  expect_same(pl.nums("coll_array", 0), rmm, "radius (mm)", 1e-15);
  // History.
  auto hist = read_csv(dir / "drop" / "history.csv");
  const fs::path hp = dir / "f" / "drop_history.png";
  const Plotted ph = read_plotted(hp);
  expect_valid_png(hp, ph);
  const int ax = ph.axes("drop.h5");
  ASSERT_EQ(ax, 0);
  EXPECT_EQ(ph.text("ylabel", 0), "|wall force| (N)");
  std::vector<double> t_ms;
  for (double t : hist.at("time_s")) t_ms.push_back(t * 1e3);
  ASSERT_GT(t_ms.size(), 50u);
  const std::vector<std::string> walls = {"floor", "x+", "x-", "y+", "y-"};
  ASSERT_EQ(ph.count("line_y", 0), 5);
  for (int k = 0; k < 5; ++k) {
    const std::string& w = walls[static_cast<std::size_t>(k)];
    EXPECT_EQ(ph.text("line_label", 0, k), w);
    expect_same(ph.nums("line_x", 0, k), t_ms, w + " time");
    std::vector<double> norm;
    for (std::size_t i = 0; i < t_ms.size(); ++i)
      norm.push_back(
          Eigen::Vector3d(hist.at(w + "_fx_N")[i], hist.at(w + "_fy_N")[i], hist.at(w + "_fz_N")[i])
              .norm());
    expect_same(ph.nums("line_y", 0, k), norm, w + " |force|", 1e-12);
  }
  const auto floor = ph.nums("line_y", 0, 0);
  EXPECT_GT(*std::max_element(floor.begin(), floor.end()), 0.0);  // the grains land on it
  const std::vector<std::pair<std::string, std::string>> energy = {
      {"kinetic_J", "kinetic"},
      {"elastic_J", "elastic"},
      {"friction_dissipation_J", "friction dissipation"},
      {"damping_dissipation_J", "damping dissipation"},
      {"gravity_work_J", "work of gravity"},
      {"wall_work_J", "work of walls"},
      {"energy_residual_J", "ledger residual"}};
  ASSERT_EQ(ph.count("line_y", 1), 7);
  EXPECT_EQ(ph.text("xlabel", 1), "time (ms)");
  for (int k = 0; k < 7; ++k) {
    const auto& [col, label] = energy[static_cast<std::size_t>(k)];
    EXPECT_EQ(ph.text("line_label", 1, k), label);
    expect_same(ph.nums("line_x", 1, k), t_ms, label + " time");
    expect_same(ph.nums("line_y", 1, k), hist.at(col), label);
  }
  // No history.csv beside the file (an imported trajectory): --type history writes nothing.
  fs::copy_file(h5file, dir / "alone.h5");
  const CliRun none = run("figures " + p("alone.h5") + " -o " + p("g") + " --type history");
  EXPECT_EQ(none.rc, 0) << none.err;
  EXPECT_EQ(none.out, "");
  EXPECT_TRUE(pngs(dir / "g").empty());
}

// fig_labcurve (--type labcurve) on the curves `granoscope simulate` writes (headers as
// TriaxialCompression, PlaneStrainCompression and SpecimenPreparation write them; values
// made up so that the answers are exact). Exact answers: triaxial and plane strain: phi against
// 100 eps1 with the peak marked at its maximum (35.5 deg at eps1 = 3 %), sigma1/sigma3 on the
// twin axis, 100 eps_v below; preparation: whole-box and core void ratio, friction on the twin
// axis, against steps.
TEST_F(Figures, LabCurvesOfCompressionTestsPlotTheCurveColumns) {
  write_lab_trajectory();
  const int n = 7;
  const double e1[n] = {0, 0.005, 0.01, 0.02, 0.03, 0.04, 0.05},
               phi[n] = {10, 20, 28, 33, 35.5, 34, 32}, s3 = 1e5,
               ev[n] = {0, -0.001, -0.002, 0.0, 0.004, 0.008, 0.011};
  auto write_triaxial = [&](bool plane) {
    std::ofstream o(dir / "curve.csv");
    o << (plane ? "step,time_s,eps1_shortening,eps_v_dilation,sigma1_Pa,sigma2_Pa,sigma3_Pa,p_Pa,"
                  "q_Pa,sin_phi,phi_deg,void_ratio,core_void_ratio,width_m,coordination,"
                  "inertial_number,unbalanced_force,membrane_particles,top_shift_m\n"
                : "step,time_s,eps1_shortening,eps2_shortening,eps3_shortening,eps_v_dilation,"
                  "sigma1_Pa,sigma2_Pa,sigma3_Pa,p_Pa,q_Pa,sin_phi,phi_deg,void_ratio,"
                  "core_void_ratio,coordination,inertial_number,unbalanced_force\n");
    o.precision(17);
    for (int i = 0; i < n; ++i) {
      const double s = std::sin(phi[i] * std::numbers::pi / 180), s1 = s3 * (1 + s) / (1 - s);
      if (plane)
        o << i * 100 << "," << i * 0.1 << "," << e1[i] << "," << ev[i] << "," << s1 << "," << s3
          << "," << s3 << ",0,0," << s << "," << phi[i] << ",0.7,0.7,0.01,4,1e-4,0.01,20,0\n";
      else
        o << i * 100 << "," << i * 0.1 << "," << e1[i] << ",0,0," << ev[i] << "," << s1 << "," << s3
          << "," << s3 << ",0,0," << s << "," << phi[i] << ",0.7,0.7,4,1e-4,0.01\n";
    }
  };
  {
    std::ofstream o(dir / "preparation.csv");
    o << "step,time_s,stage,friction_deg,void_ratio,core_void_ratio,unbalanced_force,kinetic_J\n";
    for (int i = 0; i < 5; ++i)
      o << i * 50 << "," << i * 0.01 << ",1," << 18 - 3 * i << "," << 1.2 - 0.1 * i << ","
        << 1.0 - 0.08 * i << ",0.1,0\n";
  }
  for (bool plane : {false, true}) {
    write_triaxial(plane);
    if (plane) fs::remove(dir / "preparation.csv");  // the curve alone this time
    const std::string out = plane ? "ps" : "tx";
    const CliRun r = run("figures " + p("lab.h5") + " -o " + p(out) + " --type labcurve");
    ASSERT_EQ(r.rc, 0) << r.err;
    const std::vector<std::string> want =
        plane ? std::vector<std::string>{"lab_curve.png"}
              : std::vector<std::string>{"lab_curve.png", "lab_preparation.png"};
    EXPECT_EQ(pngs(dir / out), want);
    const auto c = read_csv(dir / "curve.csv");
    const fs::path png = dir / out / "lab_curve.png";
    const Plotted pc = read_plotted(png);
    expect_valid_png(png, pc);
    const int a1 = pc.axes(plane ? "lab: plane strain" : "lab: triaxial");
    ASSERT_GE(a1, 0);
    std::vector<double> e1pct, ratio, evpct;
    for (int i = 0; i < n; ++i) {
      e1pct.push_back(100 * c.at("eps1_shortening")[static_cast<std::size_t>(i)]);
      ratio.push_back(c.at("sigma1_Pa")[static_cast<std::size_t>(i)] /
                      c.at("sigma3_Pa")[static_cast<std::size_t>(i)]);
      evpct.push_back(100 * c.at("eps_v_dilation")[static_cast<std::size_t>(i)]);
    }
    expect_same(pc.nums("line_x", a1, 0), e1pct, "eps1 %");
    expect_same(pc.nums("line_y", a1, 0), std::vector<double>(phi, phi + n), "phi");
    expect_same(pc.nums("line_x", a1, 1), {e1pct[4]}, "peak eps1");
    expect_same(pc.nums("line_y", a1, 1), {35.5}, "peak phi");
    EXPECT_EQ(pc.text("text", a1, 0), "peak 35.5° at ε1 = 3.0 %");
    int ratio_axes = -1, ev_axes = -1;
    for (int i = 0; pc.has("title", i); ++i) {
      if (pc.text("ylabel", i) == "σ1/σ3") ratio_axes = i;
      if (pc.text("ylabel", i) == "volumetric strain εv (%, dilation +)") ev_axes = i;
    }
    ASSERT_GE(ratio_axes, 0);
    ASSERT_GE(ev_axes, 0);
    expect_same(pc.nums("line_y", ratio_axes, 0), ratio, "sigma1/sigma3");
    expect_same(pc.nums("line_x", ev_axes, 0), e1pct, "eps1 % (lower)");
    expect_same(pc.nums("line_y", ev_axes, 0), evpct, "eps_v %");
    EXPECT_EQ(pc.text("xlabel", ev_axes), "axial strain ε1 (%)");
    if (plane) continue;
    // Preparation.
    const fs::path pp = dir / out / "lab_preparation.png";
    const Plotted pr = read_plotted(pp);
    expect_valid_png(pp, pr);
    const auto prep = read_csv(dir / "preparation.csv");
    const int ap = pr.axes("lab: preparation");
    ASSERT_GE(ap, 0);
    EXPECT_EQ(pr.text("line_label", ap, 0), "whole box");
    EXPECT_EQ(pr.text("line_label", ap, 1), "core");
    expect_same(pr.nums("line_x", ap, 0), prep.at("step"), "steps");
    expect_same(pr.nums("line_y", ap, 0), prep.at("void_ratio"), "void ratio");
    expect_same(pr.nums("line_y", ap, 1), prep.at("core_void_ratio"), "core void ratio");
    int fric = -1;
    for (int i = 0; pr.has("title", i); ++i)
      if (pr.text("ylabel", i) == "friction during compaction (°)") fric = i;
    ASSERT_GE(fric, 0);
    expect_same(pr.nums("line_y", fric, 0), prep.at("friction_deg"), "friction");
  }
}

// fig_labcurve (--type labcurve) on a direct-shear curve (header as DirectShear writes it).
// Exact answers: tau/sigma_n against 1000 u (mm), and the only figure is the curve (no
// preparation.csv); a curve of neither kind is one error line naming it, exit 2, no figure.
TEST_F(Figures, LabCurveDirectShearAndBadCurve) {
  write_lab_trajectory();
  const int n = 7;
  const double ev[n] = {0, -0.001, -0.002, 0.0, 0.004, 0.008, 0.011};
  {
    std::ofstream o(dir / "curve.csv");
    o << "step,time_s,u_m,tau_Pa,sigma_n_Pa,tau_over_sigma_n,dh_m,eps_v_dilation,void_ratio,"
         "coordination,particles_outside\n";
    for (int i = 0; i < n; ++i)
      o << i << "," << i * 0.01 << "," << 2.5e-4 * i << "," << 1e4 * i << ",1e5," << 0.1 * i
        << ",0," << ev[i] << ",0.7,4,0\n";
  }
  const CliRun ds = run("figures " + p("lab.h5") + " -o " + p("ds") + " --type labcurve");
  ASSERT_EQ(ds.rc, 0) << ds.err;
  EXPECT_EQ(pngs(dir / "ds"), (std::vector<std::string>{"lab_curve.png"}));
  const Plotted pd = read_plotted(dir / "ds" / "lab_curve.png");
  expect_valid_png(dir / "ds" / "lab_curve.png", pd);
  const int ad = pd.axes("lab: direct shear");
  ASSERT_GE(ad, 0);
  const auto c = read_csv(dir / "curve.csv");
  std::vector<double> umm, evpct;
  for (int i = 0; i < n; ++i) {
    umm.push_back(1e3 * c.at("u_m")[static_cast<std::size_t>(i)]);
    evpct.push_back(100 * ev[i]);
  }
  expect_same(pd.nums("line_x", ad, 0), umm, "u (mm)");
  expect_same(pd.nums("line_y", ad, 0), c.at("tau_over_sigma_n"), "tau/sigma_n");
  EXPECT_EQ(pd.text("ylabel", ad), "τ/σn");
  // Neither kind of curve.
  std::ofstream(dir / "curve.csv") << "step,time_s,something\n0,0,1\n";
  const CliRun bad = run("figures " + p("lab.h5") + " -o " + p("bad") + " --type labcurve");
  EXPECT_EQ(bad.rc, 2);
  EXPECT_EQ(bad.err, "error: " + p("lab.h5") + ": fig_labcurve: " + p("curve.csv") +
                         ": not a laboratory-test curve\n");
  EXPECT_TRUE(pngs(dir / "bad").empty());
}

// fig_labcurve on an interface-shear curve and on a silo curve (headers as InterfaceShear and
// SiloFlow write them). Exact answers: φs and εv (%) against 1000 u (mm); P/G against the
// bottom's travel (mm) in the quasi-static mode.
TEST_F(Figures, LabCurveInterfaceShearAndSilo) {
  write_lab_trajectory();
  const std::size_t n = 6;
  {
    std::ofstream o(dir / "curve.csv");
    o << "step,time_s,u_m,u_over_L,T_N,P_N,tau_Pa,sigma_n_Pa,mu_eff,phi_s_deg,surface_T_N,"
         "surface_P_N,surface_mu,dh_m,eps_v,void_ratio,coordination,particles_outside,"
         "inertial_number\n";
    for (std::size_t i = 0; i < n; ++i)
      o << i << ",0," << 1e-3 * i << ",0,1,2,1,2," << 0.1 * i << "," << 5.0 * i << ",1,2,0.5,0,"
        << 0.002 * i << ",0.7,4,0,1e-4\n";
  }
  const CliRun is = run("figures " + p("lab.h5") + " -o " + p("is") + " --type labcurve");
  ASSERT_EQ(is.rc, 0) << is.err;
  const Plotted pi = read_plotted(dir / "is" / "lab_curve.png");
  const int ai = pi.axes("lab: interface shear");
  ASSERT_GE(ai, 0);
  const auto c = read_csv(dir / "curve.csv");
  std::vector<double> umm, phi, evpct;
  for (std::size_t i = 0; i < n; ++i) {
    umm.push_back(1e3 * c.at("u_m")[i]);
    phi.push_back(c.at("phi_s_deg")[i]);
    evpct.push_back(100 * c.at("eps_v")[i]);
  }
  expect_same(pi.nums("line_x", ai, 0), umm, "u (mm)");
  expect_same(pi.nums("line_y", ai, 0), phi, "phi_s");
  int aev = -1;
  for (int i = 0; pi.has("title", i); ++i)
    if (pi.text("ylabel", i) == "volumetric strain εv (%, dilation +)") aev = i;
  ASSERT_GE(aev, 0);
  expect_same(pi.nums("line_y", aev, 0), evpct, "eps_v (%)");
  {
    std::ofstream o(dir / "curve.csv");
    o << "time_s,flow_time_s,u_m,G_N,P_N,T_left_N,T_right_N,N_left_N,N_right_N,P_G,T_left_G,"
         "T_right_G,N_left_G,N_right_G,balance_G,phi_w_left_deg,phi_w_right_deg,"
         "discharged_kg,discharged_fraction,inertial_number,void_ratio\n";
    for (std::size_t i = 0; i < n; ++i)
      o << i << ",0," << 1e-3 * i << ",10,5,2,2,4,4," << 0.5 + 0.01 * i
        << ",0.2,0.2,0.4,0.4,1,26,26,0,0,1e-5,0.6\n";
  }
  const CliRun si = run("figures " + p("lab.h5") + " -o " + p("si") + " --type labcurve");
  ASSERT_EQ(si.rc, 0) << si.err;
  const Plotted ps = read_plotted(dir / "si" / "lab_curve.png");
  const int as = ps.axes("lab: silo");
  ASSERT_GE(as, 0);
  const auto cs = read_csv(dir / "curve.csv");
  std::vector<double> smm;
  for (std::size_t i = 0; i < n; ++i) smm.push_back(1e3 * cs.at("u_m")[i]);
  expect_same(ps.nums("line_x", as, 0), smm, "u (mm)");
  expect_same(ps.nums("line_y", as, 0), cs.at("P_G"), "P/G");
}

// Files of the right format with malformed datasets: one line `error: FILE: fig_x: what`, exit
// 2, no figure, never a Python traceback (fig_dic used to crash in imshow on a 2-D field).
TEST_F(Figures, MalformedInputsAreOneErrorLine) {
  {
    gs::H5FieldFile h(dir / "dic.h5", "granoscope-dic");
    h.write("/x", std::vector<double>{10, 14, 18});
    h.write("/y", std::vector<double>{10, 14});
    for (const char* n : {"/u", "/v", "/exx", "/eyy", "/exy"})
      h.write(n, std::vector<double>(5, 0.0), {1, 5});
    h.write("/valid", std::vector<std::uint8_t>(6, 1), {1, 2, 3});
    h.commit();
  }
  {
    gs::H5FieldFile h(dir / "strain.h5", "granoscope-strain");
    h.write("/particles/position", std::vector<double>(12, 0.0), {4, 3});
    h.write("/particles/valid", std::vector<std::uint8_t>(4, 1));
    h.write("/particles/volumetric_strain", std::vector<double>(4, 0.0));
    h.write("/particles/equivalent_shear_strain", std::vector<double>(4, 0.0));
    h.write("/simplices/vertices", std::vector<std::int32_t>{0, 1, 9}, {1, 3});
    h.write("/simplices/sliver", std::vector<std::uint8_t>{0});
    h.write("/simplices/alpha", std::vector<double>{1});
    h.write("/simplices/w", std::vector<double>{0});
    h.commit();
  }
  {
    gs::H5FieldFile h(dir / "cells.h5", "granoscope-voidcells");
    h.write("/cells/offsets", std::vector<std::int64_t>{0, 3, 2});
    h.write("/cells/polygon", std::vector<double>(6, 0.0), {3, 2});
    h.commit();
  }
  for (const auto& [file, what] : std::vector<std::pair<std::string, std::string>>{
           {"dic.h5", "fig_dic: dataset u has shape (1, 5), expected (frames, 2, 3)"},
           {"strain.h5", "fig_strain: simplices/vertices index a particle out of range"},
           {"cells.h5", "fig_strain: cells/offsets do not partition cells/polygon"}}) {
    const CliRun r = run("figures " + p(file) + " -o " + p(file + "_figs"), false);
    EXPECT_EQ(r.rc, 2) << file;
    EXPECT_EQ(r.err, "error: " + p(file) + ": " + what + "\n");
    EXPECT_TRUE(pngs(dir / (file + "_figs")).empty()) << file;
  }
}

// `figures` of an `analyze silo` report: the forces over the weight are the report's series,
// and the void ratio across a simple cubic packing is 6/π − 1 in every box (exact answer: the
// boxes are aligned with the lattice cells), the rose of the left half is drawn for each state.
TEST_F(Figures, SiloReportForcesVoidRatioAndRose) {
  const double r = 1e-3;
  gs::Trajectory t;
  for (int k = 0; k < 3; ++k) {
    gs::Frame f;
    f.time = 0.1 * k;
    auto wall = [&](std::int64_t id, Eigen::Vector3d a, Eigen::Vector3d b, Eigen::Vector3d F) {
      gs::Wall w;
      w.id = id;
      w.a = a;
      w.b = b;
      w.force = F;
      return w;
    };
    const double s = 1e-3 * (1 + k);  // (the side walls' load grows frame by frame)
    f.walls = {wall(1000, {0, 0, 0}, {1, 0, 0}, {-s, 0, -0.5 * s}),
               wall(1001, {20 * r, 0, 0}, {-1, 0, 0}, {s, 0, -0.5 * s}),
               wall(1002, {0, 0, 0}, {0, 0, 1}, {0, 0, -0.01})};
    std::int64_t id = 0;
    for (int i = 0; i < 10; ++i)
      for (int j = 0; j < 2; ++j)
        for (int m = 0; m < 20; ++m) {
          gs::Particle q;
          q.id = id++;
          q.position = Eigen::Vector3d((2 * i + 1) * r, (2 * j + 1) * r, (2 * m + 1) * r);
          q.radius = r;
          q.mass = 1e-5;
          f.particles.push_back(q);
        }
    auto contact = [&](std::int64_t a, std::int64_t b, Eigen::Vector3d pt, Eigen::Vector3d n,
                       Eigen::Vector3d F) {
      gs::Contact c;
      c.id1 = a;
      c.id2 = b;
      c.point = pt;
      c.normal = n.normalized();
      c.normal_force = F;
      return c;
    };
    f.contacts = {contact(1000, 0, {0, r, r}, {1, 0, 0}, {s, 0, 0.5 * s}),
                  contact(1001, 399, {20 * r, r, 39 * r}, {-1, 0, 0}, {-s, 0, 0.5 * s}),
                  contact(0, 1, {r, 2 * r, r}, {0, 0, 1}, {0, 0, 0.1}),
                  contact(2, 3, {3 * r, 2 * r, 5 * r}, {1, 0, 1}, {0.1, 0, 0.1})};
    t.frames.push_back(f);
  }
  gs::write_hdf5_trajectory(dir / "silo.h5", t);
  const CliRun a = run("analyze silo " + p("silo.h5") + " -o " + p("report.h5") +
                           " --layer-bin-d50 1 --layer-band-d50 2",
                       false);
  ASSERT_EQ(a.rc, 0) << a.err;
  const CliRun r2 = run("figures " + p("report.h5") + " -o " + p("f"));
  ASSERT_EQ(r2.rc, 0) << r2.err;
  EXPECT_EQ(pngs(dir / "f"),
            (std::vector<std::string>{"silo_fabric.png", "silo_forces.png", "silo_profiles.png"}));
  const Plotted forces = read_plotted(dir / "f" / "silo_forces.png");
  const int af = forces.axes("silo: forces over the weight");
  ASSERT_GE(af, 0);
  expect_same(forces.nums("line_y", af, 0), gs::test::h5::read(dir / "report.h5", "/series/P_G").v,
              "P/G");
  expect_same(forces.nums("line_y", af, 3),
              gs::test::h5::read(dir / "report.h5", "/series/N_left_G").v, "N/G left");
  const Plotted fab = read_plotted(dir / "f" / "silo_fabric.png");
  const int ae = fab.axes("silo: void ratio across");
  ASSERT_GE(ae, 0);
  const auto e = fab.nums("line_y", ae, 0);
  ASSERT_EQ(e.size(), 10u);
  for (const double v : e) EXPECT_NEAR(v, 6 / M_PI - 1, 1e-6);
  EXPECT_GE(fab.axes("silo: left half contact normals (0 deg = wall normal)"), 0);
}

// `figures RUN.h5 --type layers` (on request only): the front view of the reference frame and
// of later frames, every grain drawn at its (x, z); a frame the run does not have is an error.
TEST_F(Figures, LayersOnRequest) {
  gs::Trajectory t;
  for (int k = 0; k < 4; ++k) {
    gs::Frame f;
    f.time = 0.5 * k;
    for (int i = 0; i < 20; ++i) {
      gs::Particle q;
      q.id = i;
      q.radius = 1e-3;
      q.position = Eigen::Vector3d(0.003 * (i % 5), 0, 0.002 * i - 1e-4 * k * (i % 5));
      f.particles.push_back(q);
    }
    t.frames.push_back(f);
  }
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  const CliRun r = run("figures " + p("run.h5") + " -o " + p("f") + " --type layers --frame 1");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(pngs(dir / "f"), std::vector<std::string>{"run_layers_000001.png"});
  const Plotted pl = read_plotted(dir / "f" / "run_layers_000001.png");
  for (const int k : {1, 2, 3}) {
    const int a = pl.axes("layers: frame " + std::to_string(k) + ", t = " +
                          (k == 1   ? "0.5"
                           : k == 2 ? "1"
                                    : "1.5") +
                          " s");
    ASSERT_GE(a, 0) << k;
    std::vector<double> xz;
    for (const auto& q : t.frames[static_cast<std::size_t>(k)].particles) {
      xz.push_back(q.position.x());
      xz.push_back(q.position.z());
    }
    expect_same(pl.nums("coll_offsets", a, 0), xz, "offsets");
  }
  const CliRun def = run("figures " + p("run.h5") + " -o " + p("g"));
  ASSERT_EQ(def.rc, 0) << def.err;
  for (const auto& png : pngs(dir / "g")) EXPECT_EQ(png.find("layers"), std::string::npos);
  const CliRun bad = run("figures " + p("run.h5") + " -o " + p("h") + " --type layers --frame 9");
  EXPECT_EQ(bad.rc, 2);
  EXPECT_NE(bad.err.find("no such frame (9 of 4)"), std::string::npos) << bad.err;
}

// `figures RUN.h5 --type rotation` (on request only): each grain coloured by its rotation about
// +y since the reference frame, the scale symmetric at the 98th percentile of |rotation|; a grain
// the reference frame does not hold is masked (grey).
TEST_F(Figures, RotationMapOnRequest) {
  gs::Trajectory t;
  for (int k = 0; k < 4; ++k) {
    gs::Frame f;
    f.time = 0.5 * k;
    for (int i = 0; i < 20; ++i) {
      if (k == 0 && i == 19) continue;  // grain 19 enters after the reference frame
      gs::Particle q;
      q.id = i;
      q.radius = 1e-3;
      q.position = Eigen::Vector3d(0.003 * (i % 5), 0, 0.002 * i);
      q.rotation = Eigen::Vector3d(0.3, 0.1 * i * k - 0.05 * i * i * k, -0.2);
      f.particles.push_back(q);
    }
    t.frames.push_back(f);
  }
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  const CliRun r = run("figures " + p("run.h5") + " -o " + p("f") + " --type rotation");
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(pngs(dir / "f"), std::vector<std::string>{"run_rotation_000000.png"});
  const Plotted pl = read_plotted(dir / "f" / "run_rotation_000000.png");
  std::vector<double> all;
  for (const int k : {1, 2, 3}) {
    const int a = pl.axes("rotation: frame " + std::to_string(k) + ", t = " +
                          (k == 1   ? "0.5"
                           : k == 2 ? "1"
                                    : "1.5") +
                          " s");
    ASSERT_GE(a, 0) << k;
    const auto w = pl.nums("coll_array", a, 0);
    ASSERT_EQ(w.size(), 20u);
    for (int i = 0; i < 19; ++i) {
      const double expected = (0.1 * i - 0.05 * i * i) * k;  // rotation_y(k) - rotation_y(0)
      EXPECT_NEAR(w[static_cast<std::size_t>(i)], expected, 1e-12) << k << " " << i;
      all.push_back(std::abs(expected));
    }
    EXPECT_TRUE(std::isnan(w[19])) << "a grain missing from the reference frame is masked";
  }
  std::sort(all.begin(), all.end());  // numpy's percentile: linear between the order statistics
  const double pos = 0.98 * static_cast<double>(all.size() - 1);
  const auto lo = static_cast<std::size_t>(pos);
  const double top = all[lo] + (pos - static_cast<double>(lo)) * (all[lo + 1] - all[lo]);
  const auto clim = pl.nums("coll_clim", pl.axes("rotation: frame 3, t = 1.5 s"), 0);
  ASSERT_EQ(clim.size(), 2u);
  EXPECT_NEAR(clim[0], -top, 1e-12);
  EXPECT_NEAR(clim[1], top, 1e-12);
  const CliRun bad = run("figures " + p("run.h5") + " -o " + p("h") + " --type rotation --frame 4");
  EXPECT_EQ(bad.rc, 2);
  EXPECT_NE(bad.err.find("no such frame (4 of 4)"), std::string::npos) << bad.err;
}
