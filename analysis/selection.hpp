// The part of a frame an analysis looks at: a slab (seed 000 §3: a slice 5 d50 thick, default
// the front view x-z through the specimen centre) and/or a box region. What the CLI's --slab*
// and --region options say (apps/analyze_common.hpp) and the Python package's keyword
// arguments of the same names; one implementation for both.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "love_weber_stress.hpp"
#include "slab_projection.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

/// A length given in m (`m`) or in multiples of d50 (`k`): m if given, else k d50, else
/// fallback_d50 d50. Throws InputError (naming `file` and option `name`) for a given value <= 0
/// or not finite.
double length_option(const std::string& file, const char* name, const std::optional<double>& m,
                     const std::optional<double>& k, double fallback_d50, double d50);

/// Rejects a non-finite or non-positive value with one line naming the option.
void require_positive(const std::string& file, const char* name, double v);

/// The selection options, as given (empty / unset = not given).
struct SelectionSpec {
  bool slab = false;                                        // the default front slab
  std::vector<double> slab_origin, slab_normal, slab_axis;  // 3 values each when given
  std::optional<double> slab_thickness, slab_d50;
  std::vector<double> region;  // x0 y0 z0 x1 y1 z1

  bool slab_requested() const;
  /// The slab (default: front view, normal -y, axis x: map x to the right, z up; through the
  /// centre of the particles; 5 d50 thick). Throws InputError on bad geometry.
  std::optional<Slab> make_slab(const std::string& file, const Frame& f, double d50) const;
  /// Region as (lo, hi), validated.
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> make_region(
      const std::string& file) const;
};

/// The slab options of `analyze strain | hhd | vortices`: a slab projected onto its plane (seed
/// 000 §5). Unset: origin 0, normal z, axis x; thickness in m or in d50 of the frame.
struct ProjectionSlabSpec {
  std::vector<double> origin, normal, axis;  // 3 values each when given
  double thickness = 0.0;                    // m
  double d50_multiple = 0.0;                 // thickness in d50 of the frame
  bool any() const { return !normal.empty() || thickness > 0.0 || d50_multiple > 0.0; }
  /// The slab for `frame` (geometry checked where it is used: slab_axes / project_slab).
  Slab make(const Frame& frame) const;
};

/// The slab and region as one predicate on points (all points when neither is given).
struct Selection {
  std::optional<Slab> slab;
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // slab axes
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> box;
  bool active() const { return slab || box; }
  bool contains(const Eigen::Vector3d& x) const;
};

/// The selection `spec` describes for frame `f` (file names the input in messages).
Selection make_selection(const std::string& file, const Frame& f, double d50,
                         const SelectionSpec& spec);

/// Plane axes for 2D views: rows e1, e2, n. 2D frames: x, y; 3D: the slab's axes when given,
/// else the front view (x to the right, z up).
Eigen::Matrix3d view_axes(const Frame& f, const std::optional<Slab>& slab);

/// The contacts (branches) whose contact point lies in the selection; wall contacts only with
/// `walls`. Counts of particle and wall contacts updated.
ContactBranches selected_branches(const Frame& f, const ContactBranches& all, const Selection& sel,
                                  bool walls);

}  // namespace gs::analysis
