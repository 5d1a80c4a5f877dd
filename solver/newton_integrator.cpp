#include "newton_integrator.hpp"

#include <cmath>

namespace gs::solver {

double integrate_particle(ParticleState& p, std::size_t i, const Eigen::Vector3d& gravity,
                          double damping, double dt) {
  double dissipated = 0;
  if (!p.fixed[i]) {
    const double m = p.mass[i];
    if (damping != 0) {
      dissipated = p.vel[i].cwiseAbs().dot((p.force[i] + m * gravity).cwiseAbs()) * damping * dt +
                   p.angvel[i].cwiseAbs().dot(p.torque[i].cwiseAbs()) * damping * dt;
    }
    Eigen::Vector3d lin = p.force[i] / m + gravity;
    cundall_damp(damping, dt, p.vel[i], lin);
    p.vel[i] += dt * lin;
    if (!p.rot_blocked[i]) {
      Eigen::Vector3d ang = p.torque[i] / p.inertia[i];
      cundall_damp(damping, dt, p.angvel[i], ang);
      p.angvel[i] += dt * ang;
    }
  }
  p.pos[i] += p.vel[i] * dt;
  const double a2 = p.angvel[i].squaredNorm();
  if (a2 != 0) {
    // Rotation by angle |ω|·dt about ω (YADE's leapfrogSphericalRotate). For the small angles of
    // a DEM step, sin and cos of the half angle come from their Taylor series, exact to double
    // precision below 1e-3 rad and much cheaper than sincos.
    const double a = std::sqrt(a2);
    const double h = 0.5 * a * dt, h2 = h * h;
    double s_over_a, c;
    if (h < 1e-3) {
      s_over_a = 0.5 * dt * (1 - h2 / 6 * (1 - h2 / 20));
      c = 1 - h2 / 2 * (1 - h2 / 12);
    } else {
      s_over_a = std::sin(h) / a;
      c = std::cos(h);
    }
    const Eigen::Vector3d v = p.angvel[i] * s_over_a;
    const Eigen::Quaterniond q(c, v.x(), v.y(), v.z());
    p.ori[i] = q * p.ori[i];
  }
  p.ori[i].normalize();
  p.rot[i] += p.angvel[i] * dt;
  return dissipated;
}

}  // namespace gs::solver
