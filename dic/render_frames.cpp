#include "render_frames.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <unordered_map>

#include "errors.hpp"

namespace gs::dic {

View parse_view(const std::string& name) {
  if (name == "front") return View::Front;
  if (name == "back") return View::Back;
  if (name == "left") return View::Left;
  if (name == "right") return View::Right;
  if (name == "top") return View::Top;
  if (name == "bottom") return View::Bottom;
  throw InputError("--view", "must be front, back, left, right, top or bottom", name);
}

namespace {

void axes(View v, Eigen::Vector3d& right, Eigen::Vector3d& up, Eigen::Vector3d& dir) {
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(),
                        Z = Eigen::Vector3d::UnitZ();
  switch (v) {
    case View::Front:
      right = X, up = Z, dir = Y;
      break;
    case View::Back:
      right = -X, up = Z, dir = -Y;
      break;
    case View::Left:
      right = -Y, up = Z, dir = X;
      break;
    case View::Right:
      right = Y, up = Z, dir = -X;
      break;
    case View::Top:
      right = X, up = Y, dir = -Z;
      break;
    case View::Bottom:
      right = X, up = -Y, dir = Z;
      break;
  }
}

// Ray caster over one frame: spheres binned on the image plane.
class Scene {
 public:
  Scene(const Frame& f, const Camera& cam) : frame_(f), cam_(cam) {
    double rmax = 0.0;
    for (const auto& p : f.particles) rmax = std::max(rmax, p.radius);
    cell_ = std::max(2.0 * rmax, 1e-300);
    double amin = std::numeric_limits<double>::max(), bmin = amin, amax = -amin, bmax = -amin;
    for (const auto& p : f.particles) {
      amin = std::min(amin, p.position.dot(cam.right) - p.radius);
      amax = std::max(amax, p.position.dot(cam.right) + p.radius);
      bmin = std::min(bmin, p.position.dot(cam.up) - p.radius);
      bmax = std::max(bmax, p.position.dot(cam.up) + p.radius);
    }
    amin_ = amin;
    bmin_ = bmin;
    na_ = std::max(1, static_cast<int>(std::ceil((amax - amin) / cell_)) + 1);
    nb_ = std::max(1, static_cast<int>(std::ceil((bmax - bmin) / cell_)) + 1);
    cells_.resize(static_cast<std::size_t>(na_) * static_cast<std::size_t>(nb_));
    for (int i = 0; i < static_cast<int>(f.particles.size()); ++i) {
      const auto& p = f.particles[static_cast<std::size_t>(i)];
      const double a = p.position.dot(cam.right), b = p.position.dot(cam.up);
      const int a0 = cell_of(a - p.radius, amin_, na_), a1 = cell_of(a + p.radius, amin_, na_);
      const int b0 = cell_of(b - p.radius, bmin_, nb_), b1 = cell_of(b + p.radius, bmin_, nb_);
      for (int cb = b0; cb <= b1; ++cb)
        for (int ca = a0; ca <= a1; ++ca) cells_[index(ca, cb)].push_back(i);
    }
  }
  /// First sphere hit by the ray through plane point (a, b); -1 if none. Hit point in `hit`.
  int cast(double a, double b, Eigen::Vector3d& hit) const {
    const int ca = static_cast<int>(std::floor((a - amin_) / cell_));
    const int cb = static_cast<int>(std::floor((b - bmin_) / cell_));
    if (ca < 0 || cb < 0 || ca >= na_ || cb >= nb_) return -1;
    int best = -1;
    double best_depth = std::numeric_limits<double>::max();
    for (const int i : cells_[index(ca, cb)]) {
      const auto& p = frame_.particles[static_cast<std::size_t>(i)];
      const double da = p.position.dot(cam_.right) - a, db = p.position.dot(cam_.up) - b;
      const double h2 = p.radius * p.radius - da * da - db * db;
      if (h2 < 0.0) continue;
      const double depth = p.position.dot(cam_.dir) - std::sqrt(h2);
      if (depth < best_depth || (depth == best_depth && i < best)) {
        best_depth = depth;
        best = i;
      }
    }
    if (best >= 0) hit = a * cam_.right + b * cam_.up + best_depth * cam_.dir;
    return best;
  }

 private:
  int cell_of(double v, double lo, int n) const {
    return std::clamp(static_cast<int>(std::floor((v - lo) / cell_)), 0, n - 1);
  }
  std::size_t index(int ca, int cb) const {
    return static_cast<std::size_t>(cb) * static_cast<std::size_t>(na_) +
           static_cast<std::size_t>(ca);
  }
  const Frame& frame_;
  const Camera& cam_;
  double cell_ = 1.0, amin_ = 0.0, bmin_ = 0.0;
  int na_ = 1, nb_ = 1;
  std::vector<std::vector<int>> cells_;
};

// Grain texture: base grey level and spots (spherical caps) fixed in the body frame.
struct Texture {
  double base = 0.0;
  std::vector<Eigen::Vector3d> spot_dir;
  std::vector<double> spot_cos;
  std::vector<double> spot_level;
  double at(const Eigen::Vector3d& body_dir) const {
    double v = base;
    for (std::size_t k = 0; k < spot_dir.size(); ++k)
      if (body_dir.dot(spot_dir[k]) > spot_cos[k]) v = spot_level[k];
    return v;
  }
};

Texture make_texture(std::int64_t id, std::uint64_t seed) {
  std::seed_seq seq{static_cast<std::uint64_t>(id), seed, std::uint64_t{0x9e3779b97f4a7c15ULL}};
  std::mt19937_64 rng(seq);
  std::uniform_real_distribution<double> base(70.0, 200.0), ang(0.12, 0.3), off(25.0, 60.0);
  std::normal_distribution<double> g(0.0, 1.0);
  Texture t;
  t.base = base(rng);
  constexpr int kSpots = 70;
  for (int k = 0; k < kSpots; ++k) {
    Eigen::Vector3d d(g(rng), g(rng), g(rng));
    t.spot_dir.push_back(d.normalized());
    t.spot_cos.push_back(std::cos(ang(rng)));
    const double o = off(rng) * ((k % 2) ? 1.0 : -1.0);
    t.spot_level.push_back(std::clamp(t.base + o, 5.0, 250.0));
  }
  return t;
}

Eigen::Matrix3d body_to_lab(const Particle& p) {
  return p.orientation.normalized().toRotationMatrix();
}

}  // namespace

Camera make_camera(const Frame& frame, View view, double px_per_d50, double margin_d50,
                   const std::string& source) {
  if (frame.particles.empty()) throw InputError(source, "frame has no particles");
  if (!(px_per_d50 > 0.0)) throw InputError("--px-per-d50", "must be > 0", value_str(px_per_d50));
  Camera cam;
  axes(view, cam.right, cam.up, cam.dir);
  std::vector<double> d;
  for (const auto& p : frame.particles) d.push_back(2.0 * p.radius);
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  const double d50 = d[d.size() / 2];
  cam.px_per_m = px_per_d50 / d50;
  double amin = std::numeric_limits<double>::max(), bmin = amin, amax = -amin, bmax = -amin;
  for (const auto& p : frame.particles) {
    amin = std::min(amin, p.position.dot(cam.right) - p.radius);
    amax = std::max(amax, p.position.dot(cam.right) + p.radius);
    bmin = std::min(bmin, p.position.dot(cam.up) - p.radius);
    bmax = std::max(bmax, p.position.dot(cam.up) + p.radius);
  }
  const double m = margin_d50 * d50;
  cam.a0 = amin - m;
  cam.b0 = bmax + m;
  cam.cols = static_cast<int>(std::ceil((amax - amin + 2 * m) * cam.px_per_m)) + 1;
  cam.rows = static_cast<int>(std::ceil((bmax - bmin + 2 * m) * cam.px_per_m)) + 1;
  if (static_cast<double>(cam.cols) * cam.rows > 2.5e8)
    throw InputError(source, "rendered image would be too large",
                     std::to_string(cam.cols) + "x" + std::to_string(cam.rows));
  return cam;
}

cv::Mat render_frame(const Frame& frame, const Camera& camera, const RenderOptions& options) {
  const Scene scene(frame, camera);
  std::vector<Texture> tex;
  std::vector<Eigen::Matrix3d> rot;
  for (const auto& p : frame.particles) {
    tex.push_back(make_texture(p.id, options.seed));
    rot.push_back(body_to_lab(p));
  }
  cv::Mat img(camera.rows, camera.cols, CV_64F);
  const int s = std::max(1, options.supersample);
#pragma omp parallel for schedule(dynamic, 4)
  for (int r = 0; r < camera.rows; ++r)
    for (int c = 0; c < camera.cols; ++c) {
      double acc = 0.0;
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) {
          const double x = c - 0.5 + (i + 0.5) / s, y = r - 0.5 + (j + 0.5) / s;
          const double a = camera.a0 + x / camera.px_per_m, b = camera.b0 - y / camera.px_per_m;
          Eigen::Vector3d hit = Eigen::Vector3d::Zero();
          const int g = scene.cast(a, b, hit);
          if (g < 0) {
            acc += options.background;
            continue;
          }
          const auto gi = static_cast<std::size_t>(g);
          const Eigen::Vector3d body = rot[gi].transpose() * (hit - frame.particles[gi].position);
          acc += tex[gi].at(body.normalized());
        }
      img.at<double>(r, c) = acc / (s * s);
    }
  if (options.noise_sigma > 0.0) {
    std::mt19937_64 rng(options.seed * 7919u + static_cast<std::uint64_t>(frame.step));
    std::normal_distribution<double> n(0.0, options.noise_sigma);
    for (int r = 0; r < img.rows; ++r)
      for (int c = 0; c < img.cols; ++c) img.at<double>(r, c) += n(rng);
  }
  return img;
}

GroundTruth ground_truth(const Frame& reference, const Frame& current, const Camera& camera) {
  const Scene ref_scene(reference, camera);
  const Scene cur_scene(current, camera);
  std::unordered_map<std::int64_t, int> cur_index;
  for (int i = 0; i < static_cast<int>(current.particles.size()); ++i)
    cur_index[current.particles[static_cast<std::size_t>(i)].id] = i;
  GroundTruth gt;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  gt.u = cv::Mat(camera.rows, camera.cols, CV_64F, cv::Scalar(nan));
  gt.v = cv::Mat(camera.rows, camera.cols, CV_64F, cv::Scalar(nan));
  gt.visible = cv::Mat::zeros(camera.rows, camera.cols, CV_8U);
  gt.grain = cv::Mat(camera.rows, camera.cols, CV_32S, cv::Scalar(-1));
#pragma omp parallel for schedule(dynamic, 4)
  for (int r = 0; r < camera.rows; ++r)
    for (int c = 0; c < camera.cols; ++c) {
      const double a = camera.a0 + c / camera.px_per_m, b = camera.b0 - r / camera.px_per_m;
      Eigen::Vector3d hit = Eigen::Vector3d::Zero();
      const int g = ref_scene.cast(a, b, hit);
      gt.grain.at<int>(r, c) = g;
      if (g < 0) continue;
      const Particle& p0 = reference.particles[static_cast<std::size_t>(g)];
      const auto it = cur_index.find(p0.id);
      if (it == cur_index.end()) continue;
      const Particle& p1 = current.particles[static_cast<std::size_t>(it->second)];
      const Eigen::Vector3d body = body_to_lab(p0).transpose() * (hit - p0.position);
      const Eigen::Vector3d moved =
          p1.position + body_to_lab(p1) * (body * (p1.radius / p0.radius));
      const Eigen::Vector2d q = camera.to_pixel(moved);
      gt.u.at<double>(r, c) = q.x() - c;
      gt.v.at<double>(r, c) = q.y() - r;
      Eigen::Vector3d hit1 = Eigen::Vector3d::Zero();
      const int g1 = cur_scene.cast(moved.dot(camera.right), moved.dot(camera.up), hit1);
      gt.visible.at<std::uint8_t>(r, c) =
          (g1 == it->second && (hit1 - moved).norm() < 1e-6 * p1.radius + 1e-12) ? 1 : 0;
    }
  return gt;
}

}  // namespace gs::dic
