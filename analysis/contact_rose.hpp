// Polar histograms ("rose diagrams") of contact normals and of the mean normal and tangential
// contact force per direction (seed 004 Figs 4.11c, 4.19, 4.24, 4.57, 5.27: mean amplitude
// versus orientation, 0–360 deg in the x-y plane of the figure).
//
// A contact has no preferred sense (n and -n are the same contact), so each contact adds 1/2 to
// the bin of n and 1/2 to the bin of -n: the diagram is centrally symmetric and the counts sum to
// the number of contacts. Per bin: count, density (count / (N * bin size): 1/rad in 2D, 1/sr in
// 3D, integrating to 1), mean |Fn| and mean |Fs| of the contacts in it (NaN for an empty bin).
//   2D: angle in a plane (axes e1, e2; normals projected onto it; a normal perpendicular to the
//       plane is skipped), bins of equal angle over 0–360 deg measured from e1 towards e2.
//   3D: equal-area bins on the sphere: n_theta bands of equal height in cos(theta) (theta from
//       e3 = n), each cut into n_phi equal longitudes (Lambert's cylindrical equal-area
//       projection), so every bin has the solid angle 4 pi / (n_theta n_phi).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace gs::analysis {

struct RoseContact {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double fn = 0.0;  // |normal force|, N
  double fs = 0.0;  // |shear force|, N
};

struct Rose {
  int dim = 2;
  std::vector<double> count, density, mean_fn, mean_fs;
  // 2D: bin centres, deg; 3D: bin centres as unit vectors in the lab frame.
  std::vector<double> angle_deg;
  std::vector<Eigen::Vector3d> direction;
  double bin_size = 0.0;  // rad (2D) or sr (3D)
  int n_theta = 0, n_phi = 0;
  std::size_t contacts = 0, skipped = 0;
};

/// 2D rose in the plane of the rows e1, e2 of `axes`, `bins` equal bins over 360 deg.
Rose contact_rose_2d(const std::vector<RoseContact>& contacts, const Eigen::Matrix3d& axes,
                     int bins);

/// 3D rose with axes (rows e1, e2, e3): polar angle from e3, azimuth from e1 towards e2.
Rose contact_rose_3d(const std::vector<RoseContact>& contacts, const Eigen::Matrix3d& axes,
                     int n_theta, int n_phi);

}  // namespace gs::analysis
