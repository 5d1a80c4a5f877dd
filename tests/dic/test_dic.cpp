// DIC against exact answers on synthetic Boolean-model speckle (small images; the full accuracy
// tables are in bench/bench_dic.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "bspline_interpolation.hpp"
#include "dic_sequence.hpp"
#include "dic_strain.hpp"
#include "errors.hpp"
#include "icgn.hpp"
#include "image_io.hpp"
#include "reliability_guided.hpp"
#include "speckle_synthetic.hpp"

using namespace gs::dic;

namespace {

cv::Mat render(const SpecklePattern& pat, int n, const InverseMap& inv, double noise = 2.55,
               std::uint64_t seed = 7) {
  RenderParams rp;
  rp.noise_sigma = noise;
  rp.noise_seed = seed;
  return render_speckle(pat, n, n, inv, rp);
}

InverseMap identity() {
  return [](const Eigen::Vector2d& x) { return x; };
}

}  // namespace

TEST(BSpline, InterpolatesExactlyAtNodes) {
  cv::Mat img(17, 23, CV_64F);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> d(0.0, 255.0);
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c) img.at<double>(r, c) = d(rng);
  const BSplineImage s(img);
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c) ASSERT_NEAR(s.value(c, r), img.at<double>(r, c), 1e-9);
}

TEST(BSpline, ReproducesCubicPolynomialsAwayFromBorder) {
  auto p = [](double x, double y) {
    return 3.0 + 0.7 * x - 0.05 * x * x + 0.002 * x * x * x + 0.4 * y - 0.01 * y * y * x +
           0.001 * y * y * y;
  };
  auto px = [](double x, double y) { return 0.7 - 0.1 * x + 0.006 * x * x - 0.01 * y * y; };
  auto py = [](double x, double y) { return 0.4 - 0.02 * y * x + 0.003 * y * y; };
  const int n = 64;
  cv::Mat img(n, n, CV_64F);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) img.at<double>(r, c) = p(c, r);
  const BSplineImage s(img);
  for (double y = 24.0; y <= 40.0; y += 0.37)
    for (double x = 24.0; x <= 40.0; x += 0.41) {
      const Sample v = s.sample(x, y);
      ASSERT_NEAR(v.value, p(x, y), 1e-6) << x << "," << y;
      ASSERT_NEAR(v.dx, px(x, y), 1e-6);
      ASSERT_NEAR(v.dy, py(x, y), 1e-6);
    }
}

TEST(Icgn, RecoversSubPixelTranslations) {
  const int n = 96;
  const SpecklePattern pat(-10, -10, n + 10, n + 10, SpeckleParams{});
  const cv::Mat ref = render(pat, n, identity());
  for (const double t : {0.1, 0.5, 0.8}) {
    const double tx = t, ty = -0.6 * t;
    const cv::Mat def = render(
        pat, n, [&](const Eigen::Vector2d& x) { return Eigen::Vector2d(x.x() - tx, x.y() - ty); },
        2.55, 11);
    const BSplineImage spline(def);
    const IcgnSolver solver(ref, spline, 15);
    double su = 0.0, sv = 0.0;
    int count = 0;
    for (int y = 30; y <= 66; y += 12)
      for (int x = 30; x <= 66; x += 12) {
        const IcgnResult r = solver.solve(x, y, Shape::Zero());
        ASSERT_TRUE(r.ok);
        EXPECT_TRUE(r.converged);
        EXPECT_GT(r.zncc, 0.99);
        EXPECT_NEAR(r.p[0], tx, 0.03);
        EXPECT_NEAR(r.p[3], ty, 0.03);
        su += r.p[0] - tx;
        sv += r.p[3] - ty;
        ++count;
      }
    EXPECT_LT(std::abs(su / count), 0.01) << "mean bias in u at shift " << t;
    EXPECT_LT(std::abs(sv / count), 0.01) << "mean bias in v at shift " << t;
  }
}

TEST(Icgn, Avx2AndGenericBuildsGiveTheSameBits) {
  // The IC-GN loop is compiled twice (icgn.cpp); neither build contracts to FMA, so the AVX2 one
  // must reproduce the generic one exactly, iteration counts included.
  const int n = 96;
  const SpecklePattern pat(-10, -10, n + 10, n + 10, SpeckleParams{});
  const cv::Mat ref = render(pat, n, identity());
  const cv::Mat def = render(
      pat, n,
      [](const Eigen::Vector2d& x) {
        return Eigen::Vector2d(x.x() - 0.37 - 0.004 * (x.x() - 48), x.y() + 0.61);
      },
      2.55, 11);
  const BSplineImage spline(def);
  for (const int order : {1, 2}) {
    IcgnOptions opt;
    opt.order = order;
    IcgnSolver solver(ref, spline, 15, opt);
    if (!solver.avx2()) GTEST_SKIP() << "this CPU has no AVX2: only the generic build runs";
    int checked = 0;
    for (int y = 20; y <= 76; y += 7)
      for (int x = 20; x <= 76; x += 7) {
        solver.use_avx2(true);
        const IcgnResult a = solver.solve(x, y, Shape::Zero());
        solver.use_avx2(false);
        const IcgnResult g = solver.solve(x, y, Shape::Zero());
        ASSERT_TRUE(a.ok);
        for (int k = 0; k < 12; ++k)
          EXPECT_EQ(a.p[k], g.p[k]) << x << "," << y << " p" << k << " order " << order;
        EXPECT_EQ(a.zncc, g.zncc);
        EXPECT_EQ(a.iterations, g.iterations);
        ++checked;
      }
    EXPECT_EQ(checked, 81);
  }
}

TEST(Icgn, ShiftShapeIsExactForQuadraticFields) {
  // u(X) = 0.3 + 2e-3 X - 1e-3 Y + 4e-4 X^2/2 - 3e-4 X Y + 1e-4 Y^2/2 (and a v): the shape at
  // the origin shifted by (ddx, ddy) is the shape of the same field at (ddx, ddy).
  const auto at = [](double X, double Y) {
    Shape p;
    p << 0.3 + 2e-3 * X - 1e-3 * Y + 2e-4 * X * X - 3e-4 * X * Y + 0.5e-4 * Y * Y,
        2e-3 + 4e-4 * X - 3e-4 * Y, -1e-3 - 3e-4 * X + 1e-4 * Y,
        -0.7 + 5e-3 * X + 3e-3 * Y + 1e-4 * X * X + 2e-4 * X * Y - 3e-4 * Y * Y,
        5e-3 + 2e-4 * X + 2e-4 * Y, 3e-3 + 2e-4 * X - 6e-4 * Y, 4e-4, -3e-4, 1e-4, 2e-4, 2e-4,
        -6e-4;
    return p;
  };
  const Shape shifted = shift_shape(at(0, 0), 6.0, -4.0);
  const Shape exact = at(6.0, -4.0);
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(shifted[k], exact[k], 1e-15) << k;
  // First order: gradients unchanged, u moved along them.
  Shape a = Shape::Zero();
  a.head<6>() << 0.5, 0.01, -0.02, 0.1, 0.003, 0.004;
  const Shape b = shift_shape(a, 2.0, 2.0);
  EXPECT_EQ(b[0], 0.5 + (0.01 * 2.0 + -0.02 * 2.0));
  EXPECT_EQ(b[3], 0.1 + (0.003 * 2.0 + 0.004 * 2.0));
  EXPECT_EQ(b.segment<2>(1), a.segment<2>(1));
  EXPECT_EQ(b.tail<8>(), a.tail<8>());
}

// A smooth speckle image: Gaussian blobs (sigma 1.5-2.5 px) sampled exactly at the pixel
// centres of g(x) = f(X(x)), no area sampling, so two images differ only by the motion: the
// B-spline's own error stays far below the tolerances of the shape-function tests.
cv::Mat gaussian_speckle(int n, const InverseMap& inverse) {
  struct Blob {
    double x, y, s, a;
  };
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> pos(-10.0, n + 10.0), sig(1.5, 2.5), amp(60.0, 120.0);
  std::vector<Blob> blobs(static_cast<std::size_t>((n + 20) * (n + 20) / 14));
  for (auto& b : blobs) b = {pos(rng), pos(rng), sig(rng), amp(rng)};
  cv::Mat img(n, n, CV_64F);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const Eigen::Vector2d X = inverse(Eigen::Vector2d(c, r));
      double v = 40.0;
      for (const auto& b : blobs) {
        const double d2 = (X.x() - b.x) * (X.x() - b.x) + (X.y() - b.y) * (X.y() - b.y);
        if (d2 < 25.0 * b.s * b.s) v += b.a * std::exp(-0.5 * d2 / (b.s * b.s));
      }
      img.at<double>(r, c) = v;
    }
  return img;
}

TEST(Icgn, QuadraticSubsetsFollowCurvedDisplacements) {
  // x = X + u(X): u = 0.4 + k (X - c)^2 / 2, v = -0.3 + k (X - c)(Y - c) / 2 with k = 8e-4/px.
  // Over a 31 px subset an affine shape misses the mean of the quadratic term (k/2 <dx^2> =
  // 4e-4 * 80 = 0.032 px at the centre); the quadratic shape recovers u, v and the curvatures.
  const int n = 112;
  const double c = 56.0, k = 8e-4;
  const auto u = [&](double X, double Y) {
    return Eigen::Vector2d(0.4 + 0.5 * k * (X - c) * (X - c), -0.3 + 0.5 * k * (X - c) * (Y - c));
  };
  const cv::Mat ref = gaussian_speckle(n, identity());
  const cv::Mat def = gaussian_speckle(n, [&](const Eigen::Vector2d& x) {
    Eigen::Vector2d X = x;  // fixed point of X = x - u(X): |grad u| < 0.05 contracts
    for (int i = 0; i < 60; ++i) X = x - u(X.x(), X.y());
    return X;
  });
  const BSplineImage spline(def);
  IcgnOptions o1, o2;
  o2.order = 2;
  const IcgnSolver affine(ref, spline, 15, o1), quadratic(ref, spline, 15, o2);
  double worst1 = 0.0, worst2 = 0.0;
  for (int y = 36; y <= 76; y += 20)
    for (int x = 36; x <= 76; x += 20) {
      const Eigen::Vector2d t = u(x, y);
      const IcgnResult r1 = affine.solve(x, y, Shape::Zero());
      const IcgnResult r2 = quadratic.solve(x, y, Shape::Zero());
      ASSERT_TRUE(r1.ok && r2.ok);
      EXPECT_TRUE(r2.converged);
      worst1 = std::max(worst1, std::abs(r1.p[0] - t.x()));
      worst2 = std::max({worst2, std::abs(r2.p[0] - t.x()), std::abs(r2.p[3] - t.y())});
      EXPECT_NEAR(r2.p[1], k * (x - c), 1e-4);             // ux
      EXPECT_NEAR(r2.p[4], 0.5 * k * (y - c), 1e-4);       // vx
      EXPECT_NEAR(r2.p[5], 0.5 * k * (x - c), 1e-4);       // vy
      EXPECT_NEAR(r2.p[6], k, 3e-5);                       // uxx
      EXPECT_NEAR(r2.p[7], 0.0, 3e-5);                     // uxy
      EXPECT_NEAR(r2.p[8], 0.0, 3e-5);                     // uyy
      EXPECT_NEAR(r2.p[9], 0.0, 3e-5);                     // vxx
      EXPECT_NEAR(r2.p[10], 0.5 * k, 3e-5);                // vxy
      EXPECT_NEAR(r2.p[11], 0.0, 3e-5);                    // vyy
      EXPECT_EQ(r1.p.tail<6>(), Shape::Zero().tail<6>());  // affine: no second-order terms
    }
  EXPECT_GT(worst1, 0.025);  // the affine subset's bias, 4e-4 <dx^2> = 0.032 px
  EXPECT_LT(worst2, 1e-3);
}

TEST(BSpline, PrefilterDoesNotDependOnTheThreadCount) {
  // Columns are filtered in blocks of 64 spread over the threads: 150 columns make a partial
  // block, 7 rows take the short-line (full mirror sum) branch of the initialisation.
  for (const cv::Size size : {cv::Size(150, 90), cv::Size(150, 7)}) {
    cv::Mat img(size, CV_64F);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> grey(0.0, 255.0);
    for (int r = 0; r < img.rows; ++r)
      for (int c = 0; c < img.cols; ++c) img.at<double>(r, c) = grey(rng);
    const cv::Mat one = bspline_prefilter(img, 1);
    const cv::Mat three = bspline_prefilter(img, 3);
    EXPECT_EQ(cv::norm(one, three, cv::NORM_INF), 0.0) << size;
    const BSplineImage spline(img, 3);
    for (int r = 0; r < img.rows; ++r)
      for (int c = 0; c < img.cols; ++c)
        ASSERT_NEAR(spline.value(c, r), img.at<double>(r, c), 1e-9) << size << r << "," << c;
  }
}

TEST(DicStrain, PlaneFitIsExactOnAffineFieldsWithHolesAndBorders) {
  // u, v affine in (x, y): the least-squares plane of any window with enough valid POIs is the
  // field itself, whatever POIs are missing and wherever the window is clipped by the border.
  PoiGrid grid;
  grid.nx = 37;
  grid.ny = 23;
  grid.x0 = 15;
  grid.y0 = 15;
  grid.step = 3;
  grid.in_roi.assign(static_cast<std::size_t>(grid.size()), 1);
  const double ux = 2.5e-3, uy = -1.2e-3, vx = 0.7e-3, vy = -4.1e-3;
  std::vector<double> u(static_cast<std::size_t>(grid.size())), v(u.size());
  std::vector<std::uint8_t> valid(u.size(), 1);
  std::mt19937_64 rng(3);
  std::bernoulli_distribution hole(0.2);
  for (int i = 0; i < grid.size(); ++i) {
    const auto c = static_cast<std::size_t>(i);
    valid[c] = hole(rng) ? 0 : 1;
    u[c] = valid[c] ? 0.31 + ux * grid.x(i) + uy * grid.y(i)
                    : std::numeric_limits<double>::quiet_NaN();
    v[c] = valid[c] ? -1.7 + vx * grid.x(i) + vy * grid.y(i)
                    : std::numeric_limits<double>::quiet_NaN();
  }
  const int m = 4;
  const StrainField s = plane_fit_strain(grid, u, v, valid, m, 21);
  int fitted = 0, border = 0;
  for (int i = 0; i < grid.size(); ++i) {
    const auto c = static_cast<std::size_t>(i);
    // Expected validity: a valid POI with at least (2m+1)^2/2 valid POIs in its clipped window.
    int count = 0;
    const int gi = i % grid.nx, gj = i / grid.nx;
    for (int jj = std::max(0, gj - m); jj <= std::min(grid.ny - 1, gj + m); ++jj)
      for (int ii = std::max(0, gi - m); ii <= std::min(grid.nx - 1, gi + m); ++ii)
        count += valid[static_cast<std::size_t>(jj * grid.nx + ii)];
    const bool expect = valid[c] && count >= (2 * m + 1) * (2 * m + 1) / 2;
    ASSERT_EQ(s.valid[c] != 0, expect) << i;
    if (!expect) {
      EXPECT_TRUE(std::isnan(s.exx[c]));
      continue;
    }
    EXPECT_NEAR(s.ux[c], ux, 1e-15);
    EXPECT_NEAR(s.uy[c], uy, 1e-15);
    EXPECT_NEAR(s.vx[c], vx, 1e-15);
    EXPECT_NEAR(s.vy[c], vy, 1e-15);
    EXPECT_NEAR(s.exx[c], ux + 0.5 * (ux * ux + vx * vx), 1e-15);
    ++fitted;
    border += (gi < m || gj < m || gi >= grid.nx - m || gj >= grid.ny - m) ? 1 : 0;
  }
  EXPECT_GT(fitted, grid.size() / 2);
  EXPECT_GT(border, 50);  // clipped windows were fitted too
}

TEST(Dic, UniformStrainAndLargeShiftFromSeeds) {
  // x = X + t + E X about the centre: exx = 0.5%, eyy = -0.3%, plus a 7.4 px shift that only
  // the ZNCC seed search can find.
  const int n = 128;
  const double c0 = 64.0, exx = 0.005, eyy = -0.003, tx = 7.4, ty = -3.2;
  const SpecklePattern pat(-20, -20, n + 20, n + 20, SpeckleParams{});
  const cv::Mat ref = render(pat, n, identity());
  const cv::Mat def = render(
      pat, n,
      [&](const Eigen::Vector2d& x) {
        return Eigen::Vector2d(c0 + (x.x() - c0 - tx) / (1.0 + exx),
                               c0 + (x.y() - c0 - ty) / (1.0 + eyy));
      },
      2.55, 12);
  DicOptions opt;
  opt.radius = 12;
  opt.search = 12;
  const PoiGrid grid = make_grid(n, n, opt.radius, 4);
  const DicField f = correlate(ref, def, grid, opt);
  std::vector<double> u(f.p.size()), v(f.p.size());
  int nvalid = 0;
  for (std::size_t i = 0; i < f.p.size(); ++i) {
    u[i] = f.p[i][0];
    v[i] = f.p[i][3];
    if (!f.valid[i]) continue;
    ++nvalid;
    const int idx = static_cast<int>(i);
    const double X = grid.x(idx), Y = grid.y(idx);
    // Skip the subsets that see the outside of the rendered pattern after the shift.
    if (X + tx + 12 * 1.01 > n - 1) continue;
    EXPECT_NEAR(u[i], tx + exx * (X - c0), 0.05) << X << "," << Y;
    EXPECT_NEAR(v[i], ty + eyy * (Y - c0), 0.05) << X << "," << Y;
  }
  EXPECT_GT(nvalid, grid.size() * 3 / 4);
  const int m = 5;
  const StrainField s = plane_fit_strain(grid, u, v, f.valid, m, 2 * opt.radius + 1);
  EXPECT_DOUBLE_EQ(s.vsg_px, 2 * m * 4 + 25);
  // RMS and mean error over the POIs with a full window of valid POIs.
  const double gl_xx = exx + 0.5 * exx * exx, gl_yy = eyy + 0.5 * eyy * eyy;
  double sq = 0.0, mean_xx = 0.0;
  int count = 0;
  for (int j = m; j < grid.ny - m; ++j)
    for (int i = m; i < grid.nx - m; ++i) {
      bool full = true;
      for (int jj = j - m; jj <= j + m; ++jj)
        for (int ii = i - m; ii <= i + m; ++ii)
          full = full && f.valid[static_cast<std::size_t>(jj * grid.nx + ii)];
      if (!full) continue;
      const auto c = static_cast<std::size_t>(j * grid.nx + i);
      ASSERT_TRUE(s.valid[c]);
      sq += std::pow(s.exx[c] - gl_xx, 2) + std::pow(s.eyy[c] - gl_yy, 2) + std::pow(s.exy[c], 2);
      mean_xx += s.exx[c] - gl_xx;
      ++count;
    }
  ASSERT_GT(count, 50);
  EXPECT_LT(std::sqrt(sq / (3.0 * count)), 5e-4);
  EXPECT_LT(std::abs(mean_xx / count), 2e-4);
  // Small strain differs from Green–Lagrange by the quadratic terms.
  const auto c = static_cast<std::size_t>((grid.ny / 2) * grid.nx + grid.nx / 2);
  EXPECT_NEAR(s.exx[c] - s.sxx[c], 0.5 * (s.ux[c] * s.ux[c] + s.vx[c] * s.vx[c]), 1e-15);
}

TEST(Dic, ThreadCountDoesNotChangeResults) {
  const int n = 80;
  const SpecklePattern pat(-10, -10, n + 10, n + 10, SpeckleParams{});
  const cv::Mat ref = render(pat, n, identity());
  const cv::Mat def = render(
      pat, n,
      [](const Eigen::Vector2d& x) {
        return Eigen::Vector2d(x.x() - 0.3 - 0.01 * (x.y() - 40), x.y() + 0.2);
      },
      2.55, 5);
  DicOptions opt;
  opt.radius = 10;
  const PoiGrid grid = make_grid(n, n, opt.radius, 3);
  opt.threads = 1;
  const DicField a = correlate(ref, def, grid, opt);
  opt.threads = 2;
  const DicField b = correlate(ref, def, grid, opt);
  ASSERT_EQ(a.p.size(), b.p.size());
  for (std::size_t i = 0; i < a.p.size(); ++i) {
    ASSERT_EQ(a.valid[i], b.valid[i]);
    for (int k = 0; k < 6; ++k) ASSERT_EQ(a.p[i][k], b.p[i][k]);
    ASSERT_EQ(a.zncc[i], b.zncc[i]);
  }
}

TEST(Dic, DecorrelatedRegionIsMarkedInvalidNotGuessed) {
  const int n = 96;
  const SpecklePattern pat(-10, -10, n + 10, n + 10, SpeckleParams{});
  const cv::Mat ref = render(pat, n, identity());
  cv::Mat def =
      render(pat, n, [](const Eigen::Vector2d& x) { return Eigen::Vector2d(x.x() - 0.4, x.y()); });
  // Replace the right third by a different speckle pattern.
  SpeckleParams other;
  other.seed = 99;
  const SpecklePattern pat2(-10, -10, n + 10, n + 10, other);
  const cv::Mat junk = render(pat2, n, identity());
  junk(cv::Rect(64, 0, 32, n)).copyTo(def(cv::Rect(64, 0, 32, n)));
  DicOptions opt;
  opt.radius = 8;
  const PoiGrid grid = make_grid(n, n, opt.radius, 4);
  const DicField f = correlate(ref, def, grid, opt);
  int good_left = 0, left = 0;
  for (int i = 0; i < grid.size(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    if (grid.x(i) - opt.radius >= 64) {
      EXPECT_FALSE(f.valid[u]) << grid.x(i);
    }
    const bool border = grid.y(i) - opt.radius == 0 || grid.y(i) + opt.radius == n - 1 ||
                        grid.x(i) - opt.radius == 0;
    if (grid.x(i) + opt.radius < 60 && !border) {
      ++left;
      good_left += f.valid[u] && std::abs(f.p[u][0] - 0.4) < 0.05;
    }
  }
  EXPECT_EQ(good_left, left);
}

TEST(Dic, BadInputsGiveClearErrors) {
  const int n = 64;
  const SpecklePattern pat(-10, -10, n + 10, n + 10, SpeckleParams{});
  const cv::Mat ref = render(pat, n, identity());
  DicOptions opt;
  opt.radius = 8;
  const PoiGrid grid = make_grid(n, n, opt.radius, 4);
  // Different sizes.
  const cv::Mat small = ref(cv::Rect(0, 0, 60, 64)).clone();
  EXPECT_THROW(correlate(ref, small, grid, opt), std::invalid_argument);
  // Empty ROI.
  const cv::Mat roi = cv::Mat::zeros(n, n, CV_8U);
  EXPECT_THROW(make_grid(n, n, 8, 4, roi), std::invalid_argument);
  // ROI of another size.
  EXPECT_THROW(make_grid(n, n, 8, 4, cv::Mat::ones(10, 10, CV_8U)), std::invalid_argument);
  // Uniform images: no texture, no seed.
  const cv::Mat flat(n, n, CV_64F, cv::Scalar(128.0));
  EXPECT_THROW(correlate(flat, flat, grid, opt), std::runtime_error);
  // Missing image file.
  EXPECT_THROW(read_grey_image("/nonexistent/ref.png"), gs::InputError);
}

TEST(DicSequence, IncrementalAccumulatesLikeCumulative) {
  // Two steps of a shear-free stretch + translation; both modes must give the exact motion.
  const int n = 96;
  const double c0 = 48.0;
  const SpecklePattern pat(-20, -20, n + 20, n + 20, SpeckleParams{});
  auto motion = [&](double s) {
    return [=](const Eigen::Vector2d& x) {
      return Eigen::Vector2d(c0 + (x.x() - c0 - 0.7 * s) / (1.0 + 0.004 * s), x.y() - 0.45 * s);
    };
  };
  const std::vector<cv::Mat> images{render(pat, n, identity()),
                                    render(pat, n, motion(1.0), 2.55, 21),
                                    render(pat, n, motion(2.0), 2.55, 22)};
  SequenceOptions opt;
  opt.dic.radius = 10;
  opt.step = 4;
  opt.strain_window_radius = 3;
  const SequenceResult cum = correlate_sequence(images, {}, opt);
  opt.incremental = true;
  const SequenceResult inc = correlate_sequence(images, {}, opt);
  ASSERT_EQ(cum.frames.size(), 2u);
  ASSERT_EQ(inc.frames.size(), 2u);
  int checked = 0;
  for (int i = 0; i < cum.grid.size(); ++i) {
    const auto c = static_cast<std::size_t>(i);
    const double X = cum.grid.x(i);
    if (X > 80) continue;  // subsets that see past the moved pattern's right edge
    for (const SequenceResult* r : {&cum, &inc}) {
      const FrameResult& f = r->frames[1];
      if (!f.valid[c]) continue;
      EXPECT_NEAR(f.u[c], 1.4 + 0.008 * (X - c0), 0.05) << X;
      EXPECT_NEAR(f.v[c], 0.9, 0.05);
      ++checked;
    }
  }
  EXPECT_GT(checked, cum.grid.size());
  EXPECT_THROW(correlate_sequence({images[0]}, {}, opt), std::invalid_argument);
}

// An image correlated with itself: every POI of the grid is valid, the first and last rows and
// columns included (their subsets touch the image border), with u = v = 0 to 1e-9 px and
// ZNCC = 1 to 1e-12. Before the `inside` tolerance the border rows were lost: warps composed in
// floating point put their samples at -1e-17 px.
TEST(Dic, ZeroMotionKeepsThePoisWhoseSubsetsTouchTheBorder) {
  const int n = 64;
  const SpecklePattern pat(-10, -10, n + 10, n + 10, SpeckleParams{});
  const cv::Mat img = render(pat, n, identity());
  DicOptions opt;
  opt.radius = 8;
  const PoiGrid grid = make_grid(n, n, opt.radius, 4);
  const DicField f = correlate(img, img, grid, opt);
  ASSERT_EQ(grid.size(), 12 * 12);
  for (int i = 0; i < grid.size(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    EXPECT_TRUE(f.valid[u]) << grid.x(i) << "," << grid.y(i);
    EXPECT_NEAR(f.p[u][0], 0.0, 1e-9);
    EXPECT_NEAR(f.p[u][3], 0.0, 1e-9);
    EXPECT_NEAR(f.zncc[u], 1.0, 1e-12);
  }
  const BSplineImage s(img);
  EXPECT_TRUE(s.inside(-1e-17, 0.0));
  EXPECT_TRUE(s.inside(n - 1.0 + 1e-12, n - 1.0));
  EXPECT_FALSE(s.inside(-1e-3, 0.0));
  EXPECT_FALSE(s.inside(0.0, n - 1.0 + 1e-3));
  EXPECT_NEAR(s.value(-1e-7, 5.0), img.at<double>(5, 0), 1e-4);
}
