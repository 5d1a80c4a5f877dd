#include "rotation_report.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "errors.hpp"
#include "text_parse.hpp"

namespace gs::analysis {

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

// The angle (degrees, from z, folded into (−90, 90]) of the major principal direction of the x-z
// part of a symmetric tensor: tan 2θ = 2 T_xz / (T_zz − T_xx).
double xz_major_from_z_deg(double xx, double zz, double xz) {
  return fold_axis_deg(0.5 * std::atan2(2.0 * xz, zz - xx) * kDeg);
}

}  // namespace

double fold_axis_deg(double a) {
  double r = std::remainder(a, 180.0);  // [−90, 90]
  if (r <= -90.0) r += 180.0;
  return r;
}

std::vector<RotationState> read_rotation_curve(const std::filesystem::path& path) {
  const std::string file = path.string();
  const std::string body = text::read_text_file(path);
  const auto lines = text::split_lines(body);
  if (lines.empty()) throw InputError(file, "empty curve");
  const auto header = text::split_csv(lines[0]);
  const std::vector<std::string_view> names = {
      "step",   "stage",  "alpha_deg", "p_Pa",   "q_Pa",   "b",      "alpha_sigma_deg",
      "sxx_Pa", "syy_Pa", "szz_Pa",    "sxy_Pa", "sxz_Pa", "syz_Pa", "exx",
      "eyy",    "ezz",    "exy",       "exz",    "eyz",    "eps_v",  "void_ratio"};
  const auto idx = text::column_indices(header, names);
  for (std::size_t k = 0; k < names.size(); ++k)
    if (idx[k] >= header.size())
      throw InputError(file, "not the curve of a stress_rotation run: missing column",
                       std::string(names[k]));
  std::vector<RotationState> out;
  for (std::size_t ln = 1; ln < lines.size(); ++ln) {
    if (text::trim(lines[ln]).empty()) continue;
    const auto tok = text::split_csv(lines[ln]);
    if (tok.size() < header.size())
      throw InputError(file, "line " + std::to_string(ln + 1) + ": too few columns");
    double v[21];
    for (std::size_t k = 0; k < names.size(); ++k)
      v[k] = text::to_double(tok[idx[k]], file, ln + 1, std::string(names[k]));
    RotationState s;
    s.step = static_cast<std::int64_t>(v[0]);
    s.stage = static_cast<int>(v[1]);
    s.alpha_deg = v[2];
    s.p = v[3];
    s.q = v[4];
    s.b = v[5];
    s.alpha_sigma_deg = v[6];
    s.sigma << v[7], v[10], v[11], v[10], v[8], v[12], v[11], v[12], v[9];
    s.eps << v[13], v[16], v[17], v[16], v[14], v[18], v[17], v[18], v[15];
    s.eps_v = v[19];
    s.void_ratio = v[20];
    for (const double x : {s.alpha_deg, s.p, s.q, s.eps_v})
      if (!std::isfinite(x))
        throw InputError(file, "line " + std::to_string(ln + 1) + ": a value is not finite");
    out.push_back(s);
  }
  return out;
}

std::vector<RotationState> rotation_rows(const std::vector<RotationState>& curve,
                                         const std::string& source) {
  std::vector<RotationState> rows;
  for (const auto& s : curve)
    if (s.stage >= 4) rows.push_back(s);
  if (rows.size() < 2)
    throw InputError(source, "the run has no rotation stage (stage 4) in its curve");
  const Eigen::Matrix3d e0 = rows.front().eps;
  const double v0 = rows.front().eps_v;
  for (auto& s : rows) {
    s.eps -= e0;
    s.eps_v -= v0;
  }
  return rows;
}

std::vector<StrainIncrement> strain_increments(const std::vector<RotationState>& rows,
                                               double window_deg) {
  if (!(window_deg > 0)) throw std::invalid_argument("strain increments: window must be positive");
  std::vector<StrainIncrement> out;
  std::size_t a = 0;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    const double span = rows[k].alpha_deg - rows[a].alpha_deg;
    if (span + 1e-9 < window_deg) continue;
    // Normalised by Δα in radians (§3.2: Δε^R = lim Δε/Δα).
    const Eigen::Matrix3d d = (rows[k].eps - rows[a].eps) / (span / kDeg);
    StrainIncrement s;
    s.alpha_deg = 0.5 * (rows[k].alpha_deg + rows[a].alpha_deg);
    s.cycle = s.alpha_deg / 180.0;
    s.d_eps_v_R = d(0, 0) + d(2, 2);
    s.d_eps_q_R = std::sqrt(0.25 * std::pow(d(0, 0) - d(2, 2), 2) + d(0, 2) * d(0, 2));
    s.d_eps_yy_R = d(1, 1);
    s.alpha_d_eps_deg = xz_major_from_z_deg(d(0, 0), d(2, 2), d(0, 2));
    s.non_coaxiality_deg = fold_axis_deg(s.alpha_d_eps_deg - s.alpha_deg);
    out.push_back(s);
    a = k;
  }
  return out;
}

FabricState rotation_fabric(const Frame& frame, double alpha_deg, const std::string& source) {
  // The bodies: each clump once, each free sphere once; a contact counts when its two
  // particles belong to different bodies (walls and members' own pairs left out).
  std::unordered_map<std::int64_t, std::int64_t> body;  // particle id -> body id
  std::unordered_set<std::int64_t> bodies;
  for (const auto& p : frame.particles) {
    const std::int64_t b = p.clump_id >= 0 ? p.clump_id : -1 - p.id;
    body.emplace(p.id, b);
    bodies.insert(b);
  }
  std::vector<Eigen::Vector3d> normals;
  for (const auto& c : frame.contacts) {
    const auto a = body.find(c.id1), b = body.find(c.id2);
    if (a == body.end() || b == body.end() || a->second == b->second) continue;
    normals.push_back(c.normal);
  }
  if (normals.empty())
    throw InputError(source, "frame at step " + std::to_string(frame.step) +
                                 " has no contacts between bodies (a frame without contacts?)");
  FabricState f;
  f.step = frame.step;
  f.alpha_deg = alpha_deg;
  f.contacts = contact_fabric(normals, bodies.size(), 3);
  f.alpha_F_deg = xz_major_from_z_deg(f.contacts.D(0, 0), f.contacts.D(2, 2), f.contacts.D(0, 2));
  f.alpha_minus_F_deg = fold_axis_deg(alpha_deg - f.alpha_F_deg);
  f.bodies = orientation_fabric(frame);
  return f;
}

std::vector<CycleSummary> cycle_summaries(const std::vector<RotationState>& rows,
                                          const std::vector<StrainIncrement>& increments,
                                          const std::vector<FabricState>& fabric) {
  std::vector<CycleSummary> out;
  if (rows.empty()) return out;
  const int cycles = static_cast<int>(std::floor(rows.back().alpha_deg / 180.0 + 1e-9));
  for (int c = 1; c <= cycles; ++c) {
    CycleSummary s;
    s.cycle = c;
    const double lo = 180.0 * (c - 1), hi = 180.0 * c;
    // The first row at the cycle's end (the increment there applied; its last state).
    for (const auto& r : rows)
      if (r.alpha_deg <= hi + 1e-9) {
        s.eps_v = r.eps_v;
        s.eps_yy = r.eps(1, 1);
      }
    double sum = 0;
    std::size_t n = 0;
    for (const auto& i : increments)
      if (i.alpha_deg > lo && i.alpha_deg <= hi) {
        sum += i.non_coaxiality_deg;
        ++n;
      }
    s.non_coaxiality_deg = n ? sum / static_cast<double>(n) : NAN;
    std::vector<Eigen::Vector2d> loop;
    for (const auto& f : fabric)
      if (f.alpha_deg >= lo - 1e-9 && f.alpha_deg < hi - 1e-9)
        loop.emplace_back(0.5 * (f.contacts.D(0, 0) - f.contacts.D(2, 2)), f.contacts.D(0, 2));
    s.frames = loop.size();
    if (!loop.empty()) {
      for (const auto& x : loop) s.fabric_centre += x;
      s.fabric_centre /= static_cast<double>(loop.size());
      for (const auto& x : loop) s.fabric_radius += (x - s.fabric_centre).norm();
      s.fabric_radius /= static_cast<double>(loop.size());
    }
    out.push_back(s);
  }
  return out;
}

RotationReport rotation_report(const std::vector<RotationState>& curve,
                               const std::vector<Frame>& frames, double window_deg,
                               const std::string& curve_source, const std::string& run_source) {
  RotationReport r;
  r.rows = rotation_rows(curve, curve_source);
  r.increments = strain_increments(r.rows, window_deg);
  // The frames after the curve's last row before the rotation: the one written when the
  // rotation began comes before its first row.
  std::int64_t before = -1;
  for (const auto& row : curve)
    if (row.stage < 4) before = row.step;
  const std::int64_t first = r.rows.front().step;
  for (const auto& f : frames) {
    if (f.step <= before) continue;
    // The path's α of the frame: that of the curve row nearest in step (rows come every
    // curve_every steps: to within the increments made between two rows).
    double alpha = 0;
    std::int64_t best = -1;
    for (const auto& row : curve) {
      const std::int64_t d = row.step > f.step ? row.step - f.step : f.step - row.step;
      if (best < 0 || d <= best) {
        best = d;
        alpha = row.alpha_deg;
      }
    }
    r.fabric.push_back(rotation_fabric(f, alpha, run_source));
  }
  if (r.fabric.empty())
    throw InputError(run_source,
                     "no frame of the rotation stage (from step " + std::to_string(first) + ")");
  r.cycles = cycle_summaries(r.rows, r.increments, r.fabric);
  return r;
}

RotationColumns rotation_strain_table(const RotationReport& r) {
  RotationColumns c = {{"alpha_deg", {}},
                       {"cycle", {}},
                       {"exx", {}},
                       {"eyy", {}},
                       {"ezz", {}},
                       {"exy", {}},
                       {"exz", {}},
                       {"eyz", {}},
                       {"eps_v", {}},
                       {"p_Pa", {}},
                       {"eta", {}},
                       {"b", {}},
                       {"alpha_sigma_deg", {}},
                       {"void_ratio", {}}};
  for (const auto& s : r.rows) {
    const double v[] = {s.alpha_deg,
                        s.alpha_deg / 180.0,
                        s.eps(0, 0),
                        s.eps(1, 1),
                        s.eps(2, 2),
                        s.eps(0, 1),
                        s.eps(0, 2),
                        s.eps(1, 2),
                        s.eps_v,
                        s.p,
                        s.p > 0 ? s.q / s.p : 0.0,
                        s.b,
                        s.alpha_sigma_deg,
                        s.void_ratio};
    for (std::size_t k = 0; k < c.size(); ++k) c[k].second.push_back(v[k]);
  }
  return c;
}

RotationColumns rotation_increments_table(const RotationReport& r) {
  RotationColumns c = {{"alpha_deg", {}},         {"cycle", {}},      {"d_eps_v_R", {}},
                       {"d_eps_q_R", {}},         {"d_eps_yy_R", {}}, {"alpha_d_eps_deg", {}},
                       {"non_coaxiality_deg", {}}};
  for (const auto& s : r.increments) {
    const double v[] = {s.alpha_deg,  s.cycle,           s.d_eps_v_R,         s.d_eps_q_R,
                        s.d_eps_yy_R, s.alpha_d_eps_deg, s.non_coaxiality_deg};
    for (std::size_t k = 0; k < c.size(); ++k) c[k].second.push_back(v[k]);
  }
  return c;
}

RotationColumns rotation_fabric_table(const RotationReport& r) {
  RotationColumns c = {{"step", {}},   {"alpha_deg", {}},   {"omega", {}},
                       {"Dxx", {}},    {"Dyy", {}},         {"Dzz", {}},
                       {"Dxy", {}},    {"Dxz", {}},         {"Dyz", {}},
                       {"D_norm", {}}, {"alpha_F_deg", {}}, {"alpha_minus_F_deg", {}},
                       {"Dp_xx", {}},  {"Dp_yy", {}},       {"Dp_zz", {}},
                       {"Dp_xz", {}},  {"Dp_norm", {}}};
  for (const auto& f : r.fabric) {
    const Eigen::Matrix3d& D = f.contacts.D;
    const Eigen::Matrix3d& P = f.bodies.D;
    const double v[] = {static_cast<double>(f.step),
                        f.alpha_deg,
                        f.contacts.omega,
                        D(0, 0),
                        D(1, 1),
                        D(2, 2),
                        D(0, 1),
                        D(0, 2),
                        D(1, 2),
                        f.contacts.D_norm,
                        f.alpha_F_deg,
                        f.alpha_minus_F_deg,
                        P(0, 0),
                        P(1, 1),
                        P(2, 2),
                        P(0, 2),
                        f.bodies.D_norm};
    for (std::size_t k = 0; k < c.size(); ++k) c[k].second.push_back(v[k]);
  }
  return c;
}

RotationColumns rotation_cycles_table(const RotationReport& r) {
  RotationColumns c = {{"cycle", {}},
                       {"eps_v", {}},
                       {"eps_yy", {}},
                       {"non_coaxiality_deg", {}},
                       {"fabric_loop_radius", {}},
                       {"fabric_loop_centre_x", {}},
                       {"fabric_loop_centre_xz", {}}};
  for (const auto& s : r.cycles) {
    const double v[] = {static_cast<double>(s.cycle), s.eps_v,         s.eps_yy,
                        s.non_coaxiality_deg,         s.fabric_radius, s.fabric_centre.x(),
                        s.fabric_centre.y()};
    for (std::size_t k = 0; k < c.size(); ++k) c[k].second.push_back(v[k]);
  }
  return c;
}

}  // namespace gs::analysis
