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
    const double a = std::sqrt(a2);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(a * dt, p.angvel[i] / a));
    p.ori[i] = q * p.ori[i];
  }
  p.ori[i].normalize();
  p.rot[i] += p.angvel[i] * dt;
  return dissipated;
}

}  // namespace gs::solver
