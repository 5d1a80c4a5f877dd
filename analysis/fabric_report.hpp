// `analyze fabric` as one call (the CLI and the Python package both make it): the contact
// fabric (seed 003 eq 18-21) of the particle-particle contacts in a selection and the clump
// orientation fabric (seed 003 §4.3) of the bodies in it.
#pragma once

#include <Eigen/Core>
#include <string>

#include "fabric.hpp"
#include "selection.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

struct FabricReport {
  Fabric contacts;
  OrientationFabric orientation;
  Eigen::Matrix3d view_axes = Eigen::Matrix3d::Identity();  // rows e1, e2, n of the 2D view
};

/// Contacts whose point lies in `sel`, among the particles whose centre does; clump bodies by
/// centre of mass when the frame has them, else the members one by one. Throws InputError
/// naming `file` when the selection holds no particle or no contact.
FabricReport fabric_report(const std::string& file, const Frame& f, const Selection& sel);

}  // namespace gs::analysis
