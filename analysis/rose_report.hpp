// `analyze rose` as one call (the CLI and the Python package both make it): polar histograms
// of the contact normals in a selection, with the mean normal and tangential force per bin, in
// a plane (2D) and optionally on equal-area bins of the sphere (3D).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "contact_rose.hpp"
#include "selection.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

struct RoseSpec {
  double bin_deg = 10.0;                         // 2D bin, must divide 360 into >= 2 bins
  std::vector<double> plane_normal, plane_axis;  // 3 values each when given (3D frames)
  bool three_d = false;                          // also the 3D histogram
  std::vector<int> bins3d{18, 36};               // bands in cos(theta), longitudes
  bool walls = false;                            // include particle-wall contacts
};

/// Throws InputError naming `file` and the option (--bin-deg, --bins3d) when `spec` is invalid.
void check_rose_spec(const std::string& file, const RoseSpec& spec);

struct RoseReport {
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // rows e1, e2, n of the rose's plane
  Rose rose2d;
  std::optional<Rose> rose3d;
};

/// The plane: --plane-normal / --plane-axis when given, else the view of the selection (slab
/// axes, front view, or x-y for 2D frames). Throws InputError naming `file`: bad spec or
/// plane, no contact in the selection, --3d on a 2D frame.
RoseReport rose_report(const std::string& file, const Frame& f, const Selection& sel,
                       const RoseSpec& spec);

}  // namespace gs::analysis
