// Seed 003's tangential polyhedron and its walls under an imposed F (see
// tangential_polyhedron.hpp).
#include "tangential_polyhedron.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "simulation.hpp"

namespace gs::solver {
namespace {

Eigen::Vector3d unit(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

}  // namespace

PolygonMeasure polygon_measure(const std::vector<Eigen::Vector3d>& p) {
  PolygonMeasure m;
  if (p.size() < 3) return m;
  // Fan from the first vertex: area vector Σ (a × b) / 2, centre Σ area_k centroid_k / area.
  Eigen::Vector3d area_vector = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
  for (std::size_t k = 1; k + 1 < p.size(); ++k) {
    const Eigen::Vector3d a = 0.5 * (p[k] - p[0]).cross(p[k + 1] - p[0]);
    area_vector += a;
    moment += a.norm() * (p[0] + p[k] + p[k + 1]) / 3.0;  // (convex polygons: all fans agree)
  }
  m.area = area_vector.norm();
  if (m.area > 0.0) {
    m.normal = area_vector / m.area;
    double fan = 0.0;
    for (std::size_t k = 1; k + 1 < p.size(); ++k)
      fan += 0.5 * (p[k] - p[0]).cross(p[k + 1] - p[0]).norm();
    m.centre = moment / fan;
  }
  return m;
}

double polyhedron_volume(const std::vector<Eigen::Vector3d>& v,
                         const std::vector<std::vector<int>>& faces) {
  double vol = 0.0;  // (1/3) Σ (x_c · n) A over the faces, with the origin as the apex
  for (const auto& f : faces) {
    std::vector<Eigen::Vector3d> p;
    for (const int k : f) p.push_back(v[static_cast<std::size_t>(k)]);
    const PolygonMeasure m = polygon_measure(p);
    vol += m.centre.dot(m.normal) * m.area / 3.0;
  }
  return vol;
}

TangentialPolyhedron tangential_polyhedron(int n, double R) {
  if (n < 4 || n % 2 != 0)
    throw std::invalid_argument("the polyhedron needs an even n >= 4 (" + std::to_string(n) + ")");
  if (!(R > 0.0) || !std::isfinite(R))
    throw std::invalid_argument("the polyhedron needs a radius R > 0 (" + std::to_string(R) + ")");
  TangentialPolyhedron P;
  P.n = n;
  P.R = R;
  const double w = std::numbers::pi / n;  // ϖ = 180°/n
  const double cw = std::cos(w);
  // Layer i: the vertical polygons' vertices at polar angle (2i - 1) ϖ, distance R / cos ϖ from
  // the centre (App. 3 (b)); they are the mid-edge points of the layer's horizontal n-gon, whose
  // vertices sit at azimuths (2j - 1) ϖ, a factor 1 / cos ϖ further out (App. 3 (c)-(d)).
  for (int i = 1; i <= n / 2; ++i) {
    const double a = (2 * i - 1) * w;
    const double z = R * std::cos(a) / cw, r = R * std::sin(a) / (cw * cw);
    for (int j = 1; j <= n; ++j) {
      const double phi = (2 * j - 1) * w;
      P.vertices.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
  }
  const auto id = [n](int i, int j) { return (i - 1) * n + (j - 1); };  // (1-based i, j)
  // Side wall (i - 1) n + j: layers i and i + 1, columns j - 1 (n when j = 1) and j; tangent at
  // (R, 2 i ϖ, 2 (j - 1) ϖ).
  for (int i = 1; i <= n / 2 - 1; ++i)
    for (int j = 1; j <= n; ++j) {
      const int jm = j == 1 ? n : j - 1;
      P.faces.push_back({id(i + 1, jm), id(i + 1, j), id(i, j), id(i, jm)});
      P.normals.push_back(unit(2 * i * w, 2 * (j - 1) * w));
    }
  std::vector<int> top, bottom;
  for (int j = 1; j <= n; ++j) top.push_back(id(1, j));
  for (int j = n; j >= 1; --j) bottom.push_back(id(n / 2, j));
  P.faces.push_back(top);
  P.normals.emplace_back(0.0, 0.0, 1.0);
  P.faces.push_back(bottom);
  P.normals.emplace_back(0.0, 0.0, -1.0);
  for (std::size_t f = 0; f < P.faces.size(); ++f) {
    // Counter-clockwise seen from outside: reverse a face whose polygon normal points inward.
    std::vector<Eigen::Vector3d> p;
    for (const int k : P.faces[f]) p.push_back(P.vertices[static_cast<std::size_t>(k)]);
    if (polygon_measure(p).normal.dot(P.normals[f]) < 0.0)
      P.faces[f] = std::vector<int>(P.faces[f].rbegin(), P.faces[f].rend());
    P.tangent.push_back(R * P.normals[f]);
  }
  for (const auto& f : P.faces) {  // the reference measures of Eq 4, from the oriented polygons
    std::vector<Eigen::Vector3d> p;
    for (const int k : f) p.push_back(P.vertices[static_cast<std::size_t>(k)]);
    const PolygonMeasure m = polygon_measure(p);
    P.face_normal.push_back(m.normal);
    P.area.push_back(m.area);
  }
  P.volume = polyhedron_volume(P.vertices, P.faces);
  return P;
}

Eigen::Matrix3d deformation_gradient_from_faces(const TangentialPolyhedron& ref,
                                                const std::vector<Eigen::Vector3d>& current) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (std::size_t f = 0; f < ref.faces.size(); ++f) {
    std::vector<Eigen::Vector3d> p;
    for (const int k : ref.faces[f]) p.push_back(current[static_cast<std::size_t>(k)]);
    // Eq 4 with N the inward normal: -x^c N^T ΔS = x^c n_out^T ΔS (reference n_out, ΔS, V).
    sum += polygon_measure(p).centre * ref.face_normal[f].transpose() * ref.area[f];
  }
  return sum / ref.volume;
}

std::vector<Eigen::Vector3d> vertices_from_planes(const TangentialPolyhedron& ref,
                                                  const std::vector<Eigen::Vector3d>& point,
                                                  const std::vector<Eigen::Vector3d>& normal) {
  std::vector<Eigen::Matrix3d> A(ref.vertices.size(), Eigen::Matrix3d::Zero());
  std::vector<Eigen::Vector3d> b(ref.vertices.size(), Eigen::Vector3d::Zero());
  for (std::size_t f = 0; f < ref.faces.size(); ++f) {
    const Eigen::Vector3d nf = normal[f].normalized();
    for (const int k : ref.faces[f]) {
      A[static_cast<std::size_t>(k)] += nf * nf.transpose();
      b[static_cast<std::size_t>(k)] += nf * nf.dot(point[f]);
    }
  }
  std::vector<Eigen::Vector3d> out;
  for (std::size_t k = 0; k < A.size(); ++k) out.push_back(A[k].ldlt().solve(b[k]));
  return out;
}

std::vector<WallPlane> wall_planes(const TangentialPolyhedron& ref, const Eigen::Matrix3d& F) {
  std::vector<WallPlane> out;
  for (std::size_t f = 0; f < ref.faces.size(); ++f) {
    const Eigen::Vector3d N = ref.normals[f];
    // Two in-plane vectors of the reference wall (Eq 6 maps them; Eq 7 gives the normal).
    const Eigen::Vector3d T1 =
        (std::abs(N.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX())
            .cross(N)
            .normalized();
    const Eigen::Vector3d T2 = N.cross(T1);
    out.push_back({F * ref.tangent[f], (F * T1).cross(F * T2).normalized()});
  }
  return out;
}

std::vector<WallMotion> wall_motions(const TangentialPolyhedron& ref, const Eigen::Matrix3d& F,
                                     const Eigen::Matrix3d& F_target, double dt) {
  if (!(dt > 0.0)) throw std::invalid_argument("wall_motions needs dt > 0");
  const auto now = wall_planes(ref, F), next = wall_planes(ref, F_target);
  std::vector<WallMotion> out;
  for (std::size_t f = 0; f < ref.faces.size(); ++f) {
    WallMotion m;
    m.centre = now[f].centre;                                  // Eq 5
    m.normal = now[f].normal;                                  // Eq 7
    m.velocity = (F_target - F) * ref.tangent[f] / dt;         // Eq 8
    m.angular_velocity = m.normal.cross(next[f].normal) / dt;  // Eq 9
    out.push_back(m);
  }
  return out;
}

std::vector<WallSpec> polyhedron_walls(const TangentialPolyhedron& P, double friction_deg) {
  std::vector<WallSpec> out;
  for (std::size_t f = 0; f < P.faces.size(); ++f) {
    WallSpec w;
    w.name = "poly" + std::to_string(f + 1);
    w.shape = WallShape::Plane;
    w.center = P.tangent[f];
    w.normal = -P.normals[f];
    w.friction_deg = friction_deg;
    out.push_back(w);
  }
  return out;
}

void drive_polyhedron(Simulation& sim, std::size_t first, const TangentialPolyhedron& P,
                      const Eigen::Matrix3d& F_target, double dt) {
  const auto target = wall_planes(P, F_target);
  auto& walls = sim.mutable_walls();
  for (std::size_t f = 0; f < P.faces.size(); ++f) {
    WallState& w = walls[first + f];
    const Eigen::Vector3d n_now = -w.normal, n_next = target[f].normal;  // outward
    w.vel = (target[f].centre - w.pos) / dt;
    // Eq 9 turns n by asin|n x n_t| (the engine turns by |ω| dt): the angle itself, so that one
    // step lands on n_t to round-off.
    const Eigen::Vector3d axis = n_now.cross(n_next);
    const double s = axis.norm();
    w.spec.angular_velocity =
        s > 0.0 ? Eigen::Vector3d(axis / s * std::atan2(s, n_now.dot(n_next)) / dt)
                : Eigen::Vector3d::Zero();
  }
}

namespace {

// The polyhedron's current vertices: the intersections of the engine walls' planes.
std::vector<Eigen::Vector3d> current_vertices(const Simulation& sim, std::size_t first,
                                              const TangentialPolyhedron& P) {
  std::vector<Eigen::Vector3d> point, normal;
  for (std::size_t f = 0; f < P.faces.size(); ++f) {
    point.push_back(sim.walls()[first + f].pos);
    normal.push_back(-sim.walls()[first + f].normal);
  }
  return vertices_from_planes(P, point, normal);
}

// Eq 14 over the volume of the `current` vertices.
Eigen::Matrix3d stress_within(const Simulation& sim, std::size_t first,
                              const TangentialPolyhedron& P,
                              const std::vector<Eigen::Vector3d>& current) {
  const double v = polyhedron_volume(current, P.faces);
  Eigen::Matrix3d m = sim.wall_contact_moment(first, P.faces.size());
  const auto& p = sim.particles();
  const Eigen::Vector3d g = sim.config().gravity;
  if (g.squaredNorm() > 0.0) {
    const std::vector<Eigen::Vector3d> x = sim.present_positions();  // (under a domain: shared)
    for (std::size_t k = 0; k < x.size(); ++k)
      if (!p.removed[k]) m += x[k] * (p.mass[k] * g).transpose();
  }
  return -m / v;
}

}  // namespace

Eigen::Matrix3d polyhedron_deformation_gradient(const Simulation& sim, std::size_t first,
                                                const TangentialPolyhedron& P) {
  return deformation_gradient_from_faces(P, current_vertices(sim, first, P));
}

double polyhedron_current_volume(const Simulation& sim, std::size_t first,
                                 const TangentialPolyhedron& P) {
  return polyhedron_volume(current_vertices(sim, first, P), P.faces);
}

Eigen::Matrix3d polyhedron_stress(const Simulation& sim, std::size_t first,
                                  const TangentialPolyhedron& P) {
  return stress_within(sim, first, P, current_vertices(sim, first, P));
}

double servo_modulus(double kn, double mean_radius, double circumradius, double relaxation) {
  if (!(kn > 0.0) || !(mean_radius > 0.0) || !(circumradius > 0.0) || !(relaxation > 0.0))
    throw std::invalid_argument("servo_modulus needs kn, radii and relaxation > 0");
  const double A = 4.0 * mean_radius * mean_radius, L = 2.0 * circumradius;
  return kn * L / (relaxation * A);
}

Eigen::Matrix3d servo_step(Simulation& sim, std::size_t first, const TangentialPolyhedron& P,
                           const Eigen::Matrix3d& sigma_target, const PolyhedronServo& servo,
                           double dt, Eigen::Matrix3d* sigma_now, Eigen::Matrix3d* F_now) {
  if (!(servo.E > 0.0)) throw std::invalid_argument("servo needs E > 0");
  const auto current = current_vertices(sim, first, P);  // (once: F and the volume)
  const Eigen::Matrix3d F = deformation_gradient_from_faces(P, current);
  const Eigen::Matrix3d sigma = stress_within(sim, first, P, current);
  if (sigma_now) *sigma_now = sigma;
  if (F_now) *F_now = F;
  Eigen::Matrix3d ds = sigma_target - sigma;
  ds = 0.5 * (ds + ds.transpose()).eval();
  const double tr = ds.trace();
  Eigen::Matrix3d de =
      (1.0 + servo.nu) / servo.E * ds - servo.nu / servo.E * tr * Eigen::Matrix3d::Identity();
  const double dv = de.trace() / 3.0;  // its volumetric part, scaled by the gain
  de += (servo.volumetric_gain - 1.0) * dv * Eigen::Matrix3d::Identity();
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(de, Eigen::EigenvaluesOnly)
                             .eigenvalues()
                             .cwiseAbs()
                             .maxCoeff();
  if (servo.max_strain_step > 0.0 && largest > servo.max_strain_step)
    de *= servo.max_strain_step / largest;
  const Eigen::Matrix3d target = F - de;
  drive_polyhedron(sim, first, P, target, dt);
  return target;
}

Eigen::Matrix3d principal_stress_state(double p, double eta, double b, double alpha) {
  const double th = std::atan2(std::sqrt(3.0) * b, 2.0 - b);
  const double k = 2.0 / 3.0 * eta, third = 2.0 * std::numbers::pi / 3.0;
  const double s1 = p * (1 + k * std::cos(th)), s2 = p * (1 + k * std::cos(third - th)),
               s3 = p * (1 + k * std::cos(third + th));
  const Eigen::Vector3d n1(std::cos(alpha), 0, std::sin(alpha)), n2(0, 1, 0),
      n3(-std::sin(alpha), 0, std::cos(alpha));
  return s1 * n1 * n1.transpose() + s2 * n2 * n2.transpose() + s3 * n3 * n3.transpose();
}

bool inside_polyhedron(const TangentialPolyhedron& P, const Eigen::Vector3d& x, double margin) {
  for (const auto& n : P.normals)
    if (!(x.dot(n) <= P.R - margin)) return false;
  return true;
}

std::vector<std::size_t> carve_polyhedron(const TangentialPolyhedron& P,
                                          const std::vector<Eigen::Vector3d>& centre,
                                          const std::vector<double>& radius,
                                          const std::vector<std::int64_t>& clump) {
  std::vector<std::uint8_t> keep(centre.size());
  for (std::size_t k = 0; k < centre.size(); ++k)
    keep[k] = inside_polyhedron(P, centre[k], radius[k]) ? 1 : 0;
  if (!clump.empty()) {  // a clump goes as a whole
    std::unordered_map<std::int64_t, std::uint8_t> whole;
    for (std::size_t k = 0; k < centre.size(); ++k)
      if (clump[k] >= 0) {
        auto [it, fresh] = whole.emplace(clump[k], keep[k]);
        if (!fresh) it->second &= keep[k];
      }
    for (std::size_t k = 0; k < centre.size(); ++k)
      if (clump[k] >= 0) keep[k] = whole[clump[k]];
  }
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < centre.size(); ++k)
    if (keep[k]) out.push_back(k);
  return out;
}

}  // namespace gs::solver
