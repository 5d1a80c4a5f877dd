#include "icgn.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

namespace gs::dic {

IcgnSolver::IcgnSolver(const cv::Mat& reference, const BSplineImage& deformed, int radius,
                       IcgnOptions options)
    : def_(deformed), radius_(radius), options_(options) {
  use_avx2(true);
  if (radius < 1) throw std::invalid_argument("IcgnSolver: subset radius must be >= 1");
  if (options.order != 1 && options.order != 2)
    throw std::invalid_argument("IcgnSolver: shape function order must be 1 or 2");
  reference.convertTo(ref_, CV_64F);
  if (ref_.rows != deformed.rows() || ref_.cols != deformed.cols())
    throw std::invalid_argument("IcgnSolver: reference and deformed images differ in size");
  const BSplineImage spline(ref_, options.threads);
  gx_.create(ref_.rows, ref_.cols, CV_64F);
  gy_.create(ref_.rows, ref_.cols, CV_64F);
#pragma omp parallel for schedule(static) num_threads(std::max(1, options.threads))
  for (int r = 0; r < ref_.rows; ++r)
    for (int c = 0; c < ref_.cols; ++c) {
      const Sample s = spline.sample(c, r);
      gx_.at<double>(r, c) = s.dx;
      gy_.at<double>(r, c) = s.dy;
    }
}

#if defined(__x86_64__) && defined(__GNUC__)
#define GS_DIC_X86 1
#endif

void IcgnSolver::use_avx2(bool on) {
#ifdef GS_DIC_X86
  avx2_ = on && __builtin_cpu_supports("avx2");
#else
  avx2_ = false;
  (void)on;
#endif
}

namespace {

using Shape1 = Eigen::Matrix<double, 6, 1>;  // the affine part: (u, ux, uy, v, vx, vy)

template <class P>
Eigen::Matrix3d to_matrix(const P& p) {
  Eigen::Matrix3d M;
  M << 1.0 + p[1], p[2], p[0], p[4], 1.0 + p[5], p[3], 0.0, 0.0, 1.0;
  return M;
}

// Sums over a subset of a product q(dx, dy) times the six components of the steepest-descent
// image J = (gx, gx dx, gx dy, gy, gy dx, gy dy). Accumulated per row as the x-moments of
// q gx and q gy (sum, sum dx), then weighted with dy: the per-pixel work is four products.
struct RowMoments {
  double x0 = 0.0, x1 = 0.0, y0 = 0.0, y1 = 0.0;  // sum q gx, sum q gx dx, sum q gy, sum q gy dx
};
// The reference subset of radius R centred at (x0, y0), none when it is not inside the image:
// grey levels and B-spline gradients as contiguous arrays, row after row, in this thread's
// scratch buffer; the pixel count and the mean grey level.
struct SubsetArrays {
  double* f;
  const double* gx;
  const double* gy;
  double n;
  double fmean;
};
std::optional<SubsetArrays> load_subset(const cv::Mat& ref, const cv::Mat& gx, const cv::Mat& gy,
                                        int x0, int y0, int R) {
  if (x0 - R < 0 || y0 - R < 0 || x0 + R >= ref.cols || y0 + R >= ref.rows) return std::nullopt;
  const int side = 2 * R + 1;
  const auto n = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  thread_local std::vector<double> scratch;
  scratch.resize(3 * n);
  double* const f = scratch.data();
  double* const gxs = f + n;
  double* const gys = gxs + n;
  double fsum = 0.0;
  for (int dy = -R, k = 0; dy <= R; ++dy) {
    const double* fr = ref.ptr<double>(y0 + dy) + x0 - R;
    const double* gxr = gx.ptr<double>(y0 + dy) + x0 - R;
    const double* gyr = gy.ptr<double>(y0 + dy) + x0 - R;
    for (int i = 0; i < side; ++i, ++k) {
      f[k] = fr[i];
      gxs[k] = gxr[i];
      gys[k] = gyr[i];
      fsum += fr[i];
    }
  }
  const double nd = static_cast<double>(n);
  return SubsetArrays{f, gxs, gys, nd, fsum / nd};
}

// Four samples g of the deformed subset at (xs, ys), the reference gradients of the same four
// pixels, and the subset sums of g, g^2 and f~ g updated (both IC-GN orders, inner loop).
using v4d = BSplineImage::v4d;
[[gnu::always_inline]] inline void sample4(const BSplineImage& def, const double (&xs)[4],
                                           const double (&ys)[4], const double* f, const double* gx,
                                           const double* gy, v4d& g, v4d& gxv, v4d& gyv, v4d& vsum,
                                           v4d& vsq, v4d& vfg) {
  def.value4(xs, ys, g);
  v4d fv;
  __builtin_memcpy(&fv, f, sizeof fv);
  __builtin_memcpy(&gxv, gx, sizeof gxv);
  __builtin_memcpy(&gyv, gy, sizeof gyv);
  vsum += g;
  vsq += g * g;
  vfg += fv * g;
}

inline void add_row(Shape1& sum, const RowMoments& m, double dy) {
  sum[0] += m.x0;
  sum[1] += m.x1;
  sum[2] += m.x0 * dy;
  sum[3] += m.y0;
  sum[4] += m.y1;
  sum[5] += m.y0 * dy;
}

}  // namespace

// IC-GN with the ZNSSD criterion (Pan, Li & Tong 2013, eqs 4-9): the Hessian H = sum J J^T of
// the reference subset is fixed; each iteration needs b = sum J (f~ - (|f~|/|g~|) g~), with
// f~ = f - f_mean and g~ = g - g_mean. Expanding g~, b = JF - ratio (JG - g_mean JS) with the
// constants JF = sum J f~ and JS = sum J, so one pass over the deformed subset accumulates
// everything: sum g, sum g^2, sum f~ g and JG = sum J g.
[[gnu::always_inline]] inline IcgnResult IcgnSolver::solve_impl(int x0, int y0,
                                                                const Shape& guess) const {
  IcgnResult res;
  res.p = guess;
  const auto sub = load_subset(ref_, gx_, gy_, x0, y0, radius_);
  if (!sub) return res;  // the subset is not inside the reference image
  const auto [f, gxs, gys, nd, fmean] = *sub;
  const int R = radius_;
  // H from the moments of gx^2, gx gy, gy^2 over (1, dx, dy, dx^2, dx dy, dy^2); JF; JS.
  // h[q][.]: moments (1, dx, dy, dx^2, dx dy, dy^2) of q = gx^2, gx gy, gy^2.
  double h[3][6] = {};
  double fss = 0.0;
  Shape1 JF = Shape1::Zero();
  Shape1 JS = Shape1::Zero();
  for (int dy = -R, k = 0; dy <= R; ++dy) {
    double m[3][3] = {};  // x-moments 0, 1, 2 of gx^2, gx gy, gy^2 along this row
    RowMoments mf, ms;
    for (int dx = -R; dx <= R; ++dx, ++k) {
      const double fk = f[k] - fmean;
      f[k] = fk;
      fss += fk * fk;
      const double gx = gxs[k];
      const double gy = gys[k];
      const double q[3] = {gx * gx, gx * gy, gy * gy};
      for (int i = 0; i < 3; ++i) {
        m[i][0] += q[i];
        m[i][1] += q[i] * dx;
        m[i][2] += q[i] * dx * dx;
      }
      mf.x0 += gx * fk;
      mf.x1 += gx * fk * dx;
      mf.y0 += gy * fk;
      mf.y1 += gy * fk * dx;
      ms.x0 += gx;
      ms.x1 += gx * dx;
      ms.y0 += gy;
      ms.y1 += gy * dx;
    }
    const double dyd = dy;
    for (int i = 0; i < 3; ++i) {
      h[i][0] += m[i][0];
      h[i][1] += m[i][1];
      h[i][2] += m[i][0] * dyd;
      h[i][3] += m[i][2];
      h[i][4] += m[i][1] * dyd;
      h[i][5] += m[i][0] * dyd * dyd;
    }
    add_row(JF, mf, dyd);
    add_row(JS, ms, dyd);
  }
  const double df = std::sqrt(fss);
  // Textureless subset: grey-level std below 0.1% of a 255 range is noise, not speckle.
  if (df < 0.255 * std::sqrt(nd)) return res;
  // H blocks: (gx-gx), (gx-gy), (gy-gy), each over the moment matrix of (1, dx, dy).
  Eigen::Matrix<double, 6, 6> H;
  const auto block = [](const double* m) {
    Eigen::Matrix3d B;
    B << m[0], m[1], m[2], m[1], m[3], m[4], m[2], m[4], m[5];
    return B;
  };
  H.block<3, 3>(0, 0) = block(h[0]);
  H.block<3, 3>(0, 3) = block(h[1]);
  H.block<3, 3>(3, 0) = block(h[1]);
  H.block<3, 3>(3, 3) = block(h[2]);
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> Hinv(H);
  if (Hinv.info() != Eigen::Success || !Hinv.isPositive()) return res;

  Eigen::Matrix3d W = to_matrix(res.p.head<6>());
  const double R2 = static_cast<double>(R) * R;
  const double Rd = R;
  for (int it = 1; it <= options_.max_iterations; ++it) {
    res.iterations = it;
    // The warp is affine, so the subset's image is a parallelogram: it lies inside the image
    // when its four corners do.
    for (const double cy : {-Rd, Rd})
      for (const double cx : {-Rd, Rd})
        if (!def_.inside(x0 + W(0, 2) + W(0, 0) * cx + W(0, 1) * cy,
                         y0 + W(1, 2) + W(1, 0) * cx + W(1, 1) * cy))
          return res;
    // Four pixels at a time in 4-vectors (the accumulators too), the row's remainder one by one.
    v4d vsum{}, vsq{}, vfg{};
    double gsum = 0.0, gsq = 0.0, fg = 0.0;
    Shape1 JG = Shape1::Zero();
    const v4d lane = {0.0, 1.0, 2.0, 3.0};
    for (int dy = -R, k = 0; dy <= R; ++dy) {
      const double bx = x0 + W(0, 2) + W(0, 1) * dy;
      const double by = y0 + W(1, 2) + W(1, 1) * dy;
      v4d mx0{}, mx1{}, my0{}, my1{};
      int dx = -R;
      for (; dx + 3 <= R; dx += 4, k += 4) {
        const v4d dxv = dx + lane;
        double xs[4], ys[4];
        for (int i = 0; i < 4; ++i) {
          xs[i] = bx + W(0, 0) * dxv[i];
          ys[i] = by + W(1, 0) * dxv[i];
        }
        v4d g, gxv, gyv;
        sample4(def_, xs, ys, f + k, gxs + k, gys + k, g, gxv, gyv, vsum, vsq, vfg);
        const v4d gxg = gxv * g;
        const v4d gyg = gyv * g;
        mx0 += gxg;
        mx1 += gxg * dxv;
        my0 += gyg;
        my1 += gyg * dxv;
      }
      RowMoments mg;
      for (; dx <= R; ++dx, ++k) {
        const double g = def_.value(bx + W(0, 0) * dx, by + W(1, 0) * dx);
        gsum += g;
        gsq += g * g;
        fg += f[k] * g;
        const double gxg = gxs[k] * g;
        const double gyg = gys[k] * g;
        mg.x0 += gxg;
        mg.x1 += gxg * dx;
        mg.y0 += gyg;
        mg.y1 += gyg * dx;
      }
      const auto hsum = [](const v4d& v) { return (v[0] + v[1]) + (v[2] + v[3]); };
      mg.x0 += hsum(mx0);
      mg.x1 += hsum(mx1);
      mg.y0 += hsum(my0);
      mg.y1 += hsum(my1);
      add_row(JG, mg, dy);
    }
    const auto hsum = [](const v4d& v) { return (v[0] + v[1]) + (v[2] + v[3]); };
    gsum += hsum(vsum);
    gsq += hsum(vsq);
    fg += hsum(vfg);
    const double gmean = gsum / nd;
    const double gss = gsq - gsum * gmean;  // sum (g - g_mean)^2
    // sum f~ (g - g_mean) = sum f~ g, since sum f~ = 0.
    if (!(gss > 0.0)) return res;
    const double dg = std::sqrt(gss);
    res.zncc = fg / (df * dg);
    const double ratio = df / dg;
    const Shape1 b = JF - ratio * (JG - gmean * JS);
    const Shape1 dp = -Hinv.solve(b);
    // W <- W o W(dp)^-1
    W = W * to_matrix(dp).inverse();
    const double norm =
        std::sqrt(dp[0] * dp[0] + dp[3] * dp[3] +
                  R2 * (dp[1] * dp[1] + dp[2] * dp[2] + dp[4] * dp[4] + dp[5] * dp[5]));
    if (!std::isfinite(norm)) return res;
    if (norm < options_.tolerance) {
      res.converged = true;
      break;
    }
  }
  res.p.setZero();
  res.p.head<6>() << W(0, 2), W(0, 0) - 1.0, W(0, 1), W(1, 2), W(1, 0), W(1, 1) - 1.0;
  res.ok = true;
  return res;
}

Shape shift_shape(const Shape& p, double ddx, double ddy) {
  Shape q = p;
  // u(d) = u + ux d_x + uy d_y + uxx d_x^2/2 + uxy d_x d_y + uyy d_y^2/2, and its gradient.
  for (const int a : {0, 3}) {
    const int s = a == 0 ? 6 : 9;  // second-order block of this component
    q[a] += (p[a + 1] * ddx + p[a + 2] * ddy) +
            (0.5 * p[s] * ddx * ddx + p[s + 1] * ddx * ddy + 0.5 * p[s + 2] * ddy * ddy);
    q[a + 1] += p[s] * ddx + p[s + 1] * ddy;
    q[a + 2] += p[s + 1] * ddx + p[s + 2] * ddy;
  }
  return q;
}

namespace {

// Second-order warps as 6 x 6 matrices (Gao, Pan et al. 2015): the matrix maps the monomials
// xi(d) = (dx^2, dx dy, dy^2, dx, dy, 1) of a reference offset d to those of its image
// w(d) = d + (U, V), products truncated at degree 2. Composition and inversion of warps become
// matrix products and inverses (exact for affine warps, second-order accurate otherwise).
using Quad = Eigen::Matrix<double, 6, 1>;  // coefficients over xi
using Warp2 = Eigen::Matrix<double, 6, 6>;

Quad quad_mul(const Quad& P, const Quad& Q) {  // P Q up to degree 2
  Quad r;
  r << P[0] * Q[5] + P[5] * Q[0] + P[3] * Q[3],
      P[1] * Q[5] + P[5] * Q[1] + P[3] * Q[4] + P[4] * Q[3],
      P[2] * Q[5] + P[5] * Q[2] + P[4] * Q[4], P[3] * Q[5] + P[5] * Q[3], P[4] * Q[5] + P[5] * Q[4],
      P[5] * Q[5];
  return r;
}

Warp2 to_warp2(const Shape& p) {
  Quad X, Y;  // dx + U and dy + V over xi
  X << 0.5 * p[6], p[7], 0.5 * p[8], 1.0 + p[1], p[2], p[0];
  Y << 0.5 * p[9], p[10], 0.5 * p[11], p[4], 1.0 + p[5], p[3];
  Warp2 M;
  M.row(0) = quad_mul(X, X).transpose();
  M.row(1) = quad_mul(X, Y).transpose();
  M.row(2) = quad_mul(Y, Y).transpose();
  M.row(3) = X.transpose();
  M.row(4) = Y.transpose();
  M.row(5) << 0.0, 0.0, 0.0, 0.0, 0.0, 1.0;
  return M;
}

Shape from_warp2(const Warp2& M) {
  Shape p;
  p << M(3, 5), M(3, 3) - 1.0, M(3, 4), M(4, 5), M(4, 3), M(4, 4) - 1.0, 2.0 * M(3, 0), M(3, 1),
      2.0 * M(3, 2), 2.0 * M(4, 0), M(4, 1), 2.0 * M(4, 2);
  return p;
}

// Parameter k of the shape is c_k times the monomial dx^px_k dy^py_k of component comp_k
// (0: U, 1: V); its steepest-descent image is J_k = c_k g_comp dx^px dy^py.
constexpr int kComp[12] = {0, 0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1};
constexpr int kPx[12] = {0, 1, 0, 0, 1, 0, 2, 1, 0, 2, 1, 0};
constexpr int kPy[12] = {0, 0, 1, 0, 0, 1, 0, 1, 2, 0, 1, 2};
constexpr double kCoef[12] = {1, 1, 1, 1, 1, 1, 0.5, 1, 0.5, 0.5, 1, 0.5};

}  // namespace

// Second-order IC-GN: the same ZNSSD algebra as solve_impl (b = JF - ratio (JG - g_mean JS)),
// with 12 parameters. Every sum over the subset is a moment sum q dx^i dy^j: per row the
// x-moments, then weighted with powers of dy.
[[gnu::always_inline]] inline IcgnResult IcgnSolver::solve_impl2(int x0, int y0,
                                                                 const Shape& guess) const {
  using Vec12 = Eigen::Matrix<double, 12, 1>;
  const int R = radius_;
  IcgnResult res;
  res.p = guess;
  const auto sub = load_subset(ref_, gx_, gy_, x0, y0, R);
  if (!sub) return res;  // the subset is not inside the reference image
  const auto [f, gxs, gys, nd, fmean] = *sub;
  // Mq[q][i][j] = sum q dx^i dy^j (i + j <= 4) for q = gx^2, gx gy, gy^2; MF[c][i][j] = sum
  // g_c f~ dx^i dy^j and MS[c][i][j] = sum g_c dx^i dy^j (i + j <= 2).
  double Mq[3][5][5] = {};
  double MF[2][3][3] = {};
  double MS[2][3][3] = {};
  double fss = 0.0;
  for (int dy = -R, k = 0; dy <= R; ++dy) {
    double xq[3][5] = {}, xf[2][3] = {}, xs[2][3] = {};
    for (int dx = -R; dx <= R; ++dx, ++k) {
      const double fk = f[k] - fmean;
      f[k] = fk;
      fss += fk * fk;
      const double g[2] = {gxs[k], gys[k]};
      const double q[3] = {g[0] * g[0], g[0] * g[1], g[1] * g[1]};
      const double pw[5] = {1.0, 1.0 * dx, 1.0 * dx * dx, 1.0 * dx * dx * dx,
                            1.0 * dx * dx * dx * dx};
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < 5; ++i) xq[a][i] += q[a] * pw[i];
      for (int c = 0; c < 2; ++c)
        for (int i = 0; i < 3; ++i) {
          xf[c][i] += g[c] * fk * pw[i];
          xs[c][i] += g[c] * pw[i];
        }
    }
    const double py[5] = {1.0, 1.0 * dy, 1.0 * dy * dy, 1.0 * dy * dy * dy,
                          1.0 * dy * dy * dy * dy};
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < 5; ++i)
        for (int j = 0; i + j < 5; ++j) Mq[a][i][j] += xq[a][i] * py[j];
    for (int c = 0; c < 2; ++c)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; i + j < 3; ++j) {
          MF[c][i][j] += xf[c][i] * py[j];
          MS[c][i][j] += xs[c][i] * py[j];
        }
  }
  const double df = std::sqrt(fss);
  if (df < 0.255 * std::sqrt(nd)) return res;  // textureless, as in solve_impl
  Eigen::Matrix<double, 12, 12> H;
  Vec12 JF, JS;
  for (int k = 0; k < 12; ++k) {
    for (int l = 0; l < 12; ++l) {
      const int q = kComp[k] + kComp[l];  // 0: gx gx, 1: gx gy, 2: gy gy
      H(k, l) = kCoef[k] * kCoef[l] * Mq[q][kPx[k] + kPx[l]][kPy[k] + kPy[l]];
    }
    JF[k] = kCoef[k] * MF[kComp[k]][kPx[k]][kPy[k]];
    JS[k] = kCoef[k] * MS[kComp[k]][kPx[k]][kPy[k]];
  }
  const Eigen::LDLT<Eigen::Matrix<double, 12, 12>> Hinv(H);
  if (Hinv.info() != Eigen::Success || !Hinv.isPositive()) return res;

  Warp2 W = to_warp2(res.p);
  Shape p = res.p;
  const double R2 = static_cast<double>(R) * R;
  for (int it = 1; it <= options_.max_iterations; ++it) {
    res.iterations = it;
    // Row dy of the subset maps to x = ax + bx dx + cx dx^2, y = ay + by dx + cy dx^2.
    const auto row = [&](int dy, double c[6]) {
      c[0] = x0 + p[0] + p[2] * dy + 0.5 * p[8] * dy * dy;
      c[1] = 1.0 + p[1] + p[7] * dy;
      c[2] = 0.5 * p[6];
      c[3] = y0 + dy + p[3] + p[5] * dy + 0.5 * p[11] * dy * dy;
      c[4] = p[4] + p[10] * dy;
      c[5] = 0.5 * p[9];
    };
    // The image of the subset is inside when its boundary is (a quadratic warp bends the
    // edges, so every boundary pixel is checked, not only the corners).
    bool inside = true;
    for (int dy = -R; dy <= R && inside; ++dy) {
      double c[6];
      row(dy, c);
      const int step = (dy == -R || dy == R) ? 1 : 2 * R;
      for (int dx = -R; dx <= R; dx += step)
        inside = inside &&
                 def_.inside(c[0] + c[1] * dx + c[2] * dx * dx, c[3] + c[4] * dx + c[5] * dx * dx);
    }
    if (!inside) return res;
    v4d vsum{}, vsq{}, vfg{};
    double gsum = 0.0, gsq = 0.0, fg = 0.0;
    double MG[2][3][3] = {};
    const v4d lane = {0.0, 1.0, 2.0, 3.0};
    const auto hsum = [](const v4d& v) { return (v[0] + v[1]) + (v[2] + v[3]); };
    for (int dy = -R, k = 0; dy <= R; ++dy) {
      double c[6];
      row(dy, c);
      v4d mx[2][3] = {};
      int dx = -R;
      for (; dx + 3 <= R; dx += 4, k += 4) {
        const v4d dxv = dx + lane;
        double xs[4], ys[4];
        for (int i = 0; i < 4; ++i) {
          xs[i] = c[0] + c[1] * dxv[i] + c[2] * dxv[i] * dxv[i];
          ys[i] = c[3] + c[4] * dxv[i] + c[5] * dxv[i] * dxv[i];
        }
        v4d g, gxv, gyv;
        sample4(def_, xs, ys, f + k, gxs + k, gys + k, g, gxv, gyv, vsum, vsq, vfg);
        const v4d gg[2] = {gxv * g, gyv * g};
        for (int a = 0; a < 2; ++a) {
          mx[a][0] += gg[a];
          mx[a][1] += gg[a] * dxv;
          mx[a][2] += gg[a] * dxv * dxv;
        }
      }
      double xm[2][3] = {};
      for (; dx <= R; ++dx, ++k) {
        const double g =
            def_.value(c[0] + c[1] * dx + c[2] * dx * dx, c[3] + c[4] * dx + c[5] * dx * dx);
        gsum += g;
        gsq += g * g;
        fg += f[k] * g;
        const double gg[2] = {gxs[k] * g, gys[k] * g};
        for (int a = 0; a < 2; ++a) {
          xm[a][0] += gg[a];
          xm[a][1] += gg[a] * dx;
          xm[a][2] += gg[a] * dx * dx;
        }
      }
      const double py[3] = {1.0, 1.0 * dy, 1.0 * dy * dy};
      for (int a = 0; a < 2; ++a)
        for (int i = 0; i < 3; ++i) {
          const double m = xm[a][i] + hsum(mx[a][i]);
          for (int j = 0; i + j < 3; ++j) MG[a][i][j] += m * py[j];
        }
    }
    gsum += hsum(vsum);
    gsq += hsum(vsq);
    fg += hsum(vfg);
    const double gmean = gsum / nd;
    const double gss = gsq - gsum * gmean;
    if (!(gss > 0.0)) return res;
    const double dg = std::sqrt(gss);
    res.zncc = fg / (df * dg);
    const double ratio = df / dg;
    Vec12 b;
    for (int k = 0; k < 12; ++k)
      b[k] = JF[k] - ratio * (kCoef[k] * MG[kComp[k]][kPx[k]][kPy[k]] - gmean * JS[k]);
    const Vec12 dp = -Hinv.solve(b);
    W = W * to_warp2(dp).inverse();  // W <- W o W(dp)^-1
    p = from_warp2(W);
    const double norm =
        std::sqrt(dp[0] * dp[0] + dp[3] * dp[3] +
                  R2 * (dp[1] * dp[1] + dp[2] * dp[2] + dp[4] * dp[4] + dp[5] * dp[5]) +
                  R2 * R2 *
                      (0.25 * (dp[6] * dp[6] + dp[8] * dp[8] + dp[9] * dp[9] + dp[11] * dp[11]) +
                       dp[7] * dp[7] + dp[10] * dp[10]));
    if (!std::isfinite(norm)) return res;
    if (norm < options_.tolerance) {
      res.converged = true;
      break;
    }
  }
  res.p = p;
  res.ok = true;
  return res;
}

// The same loop compiled twice: for AVX2 (the B-spline's 4-vectors in one register) and for
// the baseline instruction set. Neither contracts to FMA, so both give the same bits.
#ifdef GS_DIC_X86
__attribute__((target("avx2"))) IcgnResult IcgnSolver::solve_avx2(int x0, int y0,
                                                                  const Shape& guess) const {
  return options_.order == 2 ? solve_impl2(x0, y0, guess) : solve_impl(x0, y0, guess);
}
#else
IcgnResult IcgnSolver::solve_avx2(int x0, int y0, const Shape& guess) const {
  return options_.order == 2 ? solve_impl2(x0, y0, guess) : solve_impl(x0, y0, guess);
}
#endif

IcgnResult IcgnSolver::solve_generic(int x0, int y0, const Shape& guess) const {
  return options_.order == 2 ? solve_impl2(x0, y0, guess) : solve_impl(x0, y0, guess);
}

IcgnResult IcgnSolver::solve(int x0, int y0, const Shape& guess) const {
  return avx2_ ? solve_avx2(x0, y0, guess) : solve_generic(x0, y0, guess);
}

}  // namespace gs::dic
