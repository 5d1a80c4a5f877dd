#include "newton_integrator.hpp"

#include <cmath>

namespace gs::solver {

IntegrationSums integrate_particles(ParticleState& p, std::size_t begin, std::size_t end,
                                    const Eigen::Vector3d& gravity, double damping, double dt) {
  IntegrationSums sums;
  const V3 g(gravity);
  for (std::size_t i = begin; i < end; ++i) {
    V3 vel(p.vel[i]);
    if (!p.fixed[i]) {
      const double m = p.mass[i];
      const V3 force(p.force[i]), torque(p.torque[i]), angvel(p.angvel[i]);
      sums.gravity_power += m * dot(g, vel);
      sums.external_power += dot(V3(p.external_force[i]), vel);
      if (damping != 0) {
        sums.damping += dot(abs(vel), abs(force + m * g)) * damping * dt +
                        dot(abs(angvel), abs(torque)) * damping * dt;
      }
      V3 lin = force / m + g;
      cundall_damp(damping, dt, vel, lin);
      vel += dt * lin;
      vel.store(p.vel[i]);
      if (!p.rot_blocked[i]) {
        V3 ang = torque / p.inertia[i];
        cundall_damp(damping, dt, angvel, ang);
        (angvel + dt * ang).store(p.angvel[i]);
      }
    }
    const V3 pos = V3(p.pos[i]) + vel * dt;
    pos.store(p.pos[i]);
    // (checked on the values in registers: reading back what was just stored in three parts
    // stalls the load)
    sums.finite = sums.finite && std::isfinite(squared_norm(pos)) &&
                  std::isfinite(squared_norm(vel));
  }
  for (std::size_t i = begin; i < end; ++i) {
    const V3 angvel(p.angvel[i]);
    const double a2 = squared_norm(angvel);
    if (a2 != 0) {
      // Rotation by angle |ω|·dt about ω (YADE's leapfrogSphericalRotate). For the small
      // angles of a DEM step, sin and cos of the half angle h come from their Taylor series,
      // exact to double precision below h = 1e-3 rad, with no square root, division or sincos
      // (the divider is this loop's bottleneck).
      const double h2 = 0.25 * dt * dt * a2;
      double s_over_a, c;
      if (h2 < 1e-6) {
        s_over_a = 0.5 * dt * (1 - h2 * (1.0 / 6) * (1 - h2 * (1.0 / 20)));
        c = 1 - h2 * 0.5 * (1 - h2 * (1.0 / 12));
      } else {
        const double a = std::sqrt(a2), h = 0.5 * a * dt;
        s_over_a = std::sin(h) / a;
        c = std::cos(h);
      }
      const V3 v = angvel * s_over_a;
      const Eigen::Quaterniond q(c, v.x, v.y, v.z);
      p.ori[i] = q * p.ori[i];
    }
    // Renormalised: one Newton step for 1/|q| when |q|² is within 1e-8 of 1 (error below
    // 1e-16), the exact square root otherwise.
    const double q2 = p.ori[i].squaredNorm();
    if (std::abs(q2 - 1) < 1e-8)
      p.ori[i].coeffs() *= 1.5 - 0.5 * q2;
    else if (q2 > 0)
      p.ori[i].coeffs() *= 1 / std::sqrt(q2);
    add_to(p.rot[i], angvel * dt);
  }
  return sums;
}

}  // namespace gs::solver
