// Periodic cell with YADE's Cell semantics (seed 002's doubly periodic assembly; YADE's
// PeriTriaxController and periodic simple shear): the cell matrix H (columns = base vectors), a
// homogeneous velocity gradient L (L_ij = ∂v_i/∂x_j) that deforms it, and the shifts of the
// particle images across its faces. docs/physics.md "Periodic cell" lists the conventions.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>

#include "scalar_vec3.hpp"

namespace gs::solver {

/// Products written out in the order YADE's Eigen evaluates them (a coefficient of a 3×3
/// product is the redux a0 + (a1 + a2); scalar_vec3.hpp), so that the cell rounds as YADE's.
inline V3 mat_vec(const Eigen::Matrix3d& m, const V3& v) {
  return {m(0, 0) * v.x + (m(0, 1) * v.y + m(0, 2) * v.z),
          m(1, 0) * v.x + (m(1, 1) * v.y + m(1, 2) * v.z),
          m(2, 0) * v.x + (m(2, 1) * v.y + m(2, 2) * v.z)};
}
inline Eigen::Matrix3d mat_mat(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r(i, j) = a(i, 0) * b(0, j) + (a(i, 1) * b(1, j) + a(i, 2) * b(2, j));
  return r;
}

struct PeriodicCell {
  Eigen::Matrix3d hsize = Eigen::Matrix3d::Identity();  // m; column j = base vector j
  Eigen::Matrix3d trsf = Eigen::Matrix3d::Identity();   // deformation gradient since the start
  Eigen::Matrix3d vel_grad = Eigen::Matrix3d::Zero();   // 1/s, the gradient in effect
  // A gradient set by the user takes effect in the integration of the next step (YADE's
  // Cell.nextVelGrad: the cell itself then follows one step late).
  Eigen::Matrix3d next_vel_grad = Eigen::Matrix3d::Zero();
  bool vel_grad_changed = false;
  Eigen::Matrix3d prev_vel_grad = Eigen::Matrix3d::Zero();       // NewtonIntegrator's prevVelGrad
  Eigen::Matrix3d prev_hsize = Eigen::Matrix3d::Identity();      // H before this step's update
  Eigen::Matrix3d vgrad_times_prev_h = Eigen::Matrix3d::Zero();  // L·H_prev: image velocities

  /// YADE's Cell::integrateAndUpdate, at the start of every step: H ← H + dt·L·H, the same for
  /// trsf, with the gradient of the previous step's integration.
  void integrate(double dt) {
    const Eigen::Matrix3d inc = dt * vel_grad;
    trsf += mat_mat(inc, trsf);
    prev_hsize = hsize;
    vgrad_times_prev_h = mat_mat(vel_grad, prev_hsize);
    hsize += mat_mat(inc, hsize);
  }
  /// Sets the gradient (takes effect in the next step's integration).
  void set_velocity_gradient(const Eigen::Matrix3d& l) {
    next_vel_grad = l;
    vel_grad_changed = true;
  }
  /// NewtonIntegrator's start: the pending gradient becomes current.
  void apply_pending_gradient() {
    if (vel_grad_changed || next_vel_grad != Eigen::Matrix3d::Zero()) {
      vel_grad = next_vel_grad;
      vel_grad_changed = false;
      next_vel_grad.setZero();
    }
  }
  /// Offset of the image of a body shifted by `cell_dist` periods (H·cellDist).
  V3 shift_pos(const Eigen::Vector3i& cd) const {
    return mat_vec(hsize, V3(cd.x(), cd.y(), cd.z()));
  }
  /// Velocity of that image relative to the body ((L·H_prev)·cellDist, YADE's intrShiftVel).
  V3 shift_vel(const Eigen::Vector3i& cd) const {
    return mat_vec(vgrad_times_prev_h, V3(cd.x(), cd.y(), cd.z()));
  }
  double volume() const { return hsize.determinant(); }
  /// The position wrapped into the cell: H·(s − floor(s)), s = H⁻¹·x (YADE's Cell.wrap).
  Eigen::Vector3d wrap(const Eigen::Vector3d& x) const;
  /// Distance between opposite faces of the cell along each base direction (m).
  Eigen::Vector3d widths() const;
};

}  // namespace gs::solver
