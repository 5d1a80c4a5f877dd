#include "selection.hpp"

#include <cmath>
#include <stdexcept>

#include "errors.hpp"
#include "grain_size.hpp"

namespace gs::analysis {

void require_positive(const std::string& file, const char* name, double v) {
  if (!(v > 0.0) || !std::isfinite(v))
    throw InputError(file, std::string(name) + " must be a finite number > 0", value_str(v));
}

double length_option(const std::string& file, const char* name, const std::optional<double>& m,
                     const std::optional<double>& k, double fallback_d50, double d50) {
  if (m) {
    require_positive(file, name, *m);
    return *m;
  }
  if (k) {
    require_positive(file, (std::string(name) + "-d50").c_str(), *k);
    return *k * d50;
  }
  return fallback_d50 * d50;
}

bool SelectionSpec::slab_requested() const {
  return slab || !slab_origin.empty() || !slab_normal.empty() || !slab_axis.empty() ||
         slab_thickness || slab_d50;
}

namespace {

Eigen::Vector3d vec(const std::string& file, const char* name, const std::vector<double>& v) {
  if (v.size() != 3) throw InputError(file, std::string(name) + " needs 3 numbers");
  const Eigen::Vector3d x(v[0], v[1], v[2]);
  if (!x.allFinite()) throw InputError(file, std::string(name) + " must be finite numbers");
  return x;
}

}  // namespace

std::optional<Slab> SelectionSpec::make_slab(const std::string& file, const Frame& f,
                                             double d50) const {
  if (!slab_requested()) return std::nullopt;
  if (f.two_d) throw InputError(file, "a slab needs a 3D frame (two_d is set)");
  Slab s;
  const auto [lo, hi] = particle_bounds(f);
  s.origin = !slab_origin.empty() ? vec(file, "--slab-origin", slab_origin) : 0.5 * (lo + hi);
  s.normal =
      !slab_normal.empty() ? vec(file, "--slab-normal", slab_normal) : Eigen::Vector3d(0, -1, 0);
  s.axis1 = !slab_axis.empty() ? vec(file, "--slab-axis", slab_axis) : Eigen::Vector3d::UnitX();
  s.thickness = length_option(file, "--slab-thickness", slab_thickness, slab_d50, 5.0, d50);
  try {
    (void)slab_axes(s);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
  return s;
}

std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> SelectionSpec::make_region(
    const std::string& file) const {
  if (region.empty()) return std::nullopt;
  if (region.size() != 6) throw InputError(file, "--region needs 6 numbers x0 y0 z0 x1 y1 z1");
  const Eigen::Vector3d lo(region[0], region[1], region[2]), hi(region[3], region[4], region[5]);
  if (!lo.allFinite() || !hi.allFinite() || !(lo.array() < hi.array()).all()) {
    throw InputError(file, "--region needs finite x0 y0 z0 x1 y1 z1 with x0 < x1, y0 < y1, z0 < z1",
                     value_str(lo.transpose()) + " " + value_str(hi.transpose()));
  }
  return std::make_pair(lo, hi);
}

Selection make_selection(const std::string& file, const Frame& f, double d50,
                         const SelectionSpec& spec) {
  Selection s;
  s.slab = spec.make_slab(file, f, d50);
  if (s.slab) s.axes = slab_axes(*s.slab);
  s.box = spec.make_region(file);
  return s;
}

bool Selection::contains(const Eigen::Vector3d& x) const {
  if (slab && std::abs(axes.row(2).dot(x - slab->origin)) > 0.5 * slab->thickness) return false;
  return !box ||
         ((x.array() >= box->first.array()).all() && (x.array() <= box->second.array()).all());
}

Eigen::Matrix3d view_axes(const Frame& f, const std::optional<Slab>& slab) {
  if (slab) return slab_axes(*slab);
  Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
  if (f.two_d) return a;
  a.row(0) = Eigen::Vector3d::UnitX();
  a.row(1) = Eigen::Vector3d::UnitZ();
  a.row(2) = -Eigen::Vector3d::UnitY();
  return a;
}

ContactBranches selected_branches(const Frame& f, const ContactBranches& all, const Selection& sel,
                                  bool walls) {
  ContactBranches out;
  for (const auto& b : all.branches) {
    if (b.p2 < 0 && !walls) continue;
    if (!sel.contains(f.contacts[static_cast<std::size_t>(b.contact)].point)) continue;
    out.branches.push_back(b);
    (b.p2 < 0 ? out.wall_contacts : out.particle_contacts) += 1;
  }
  return out;
}

Slab ProjectionSlabSpec::make(const Frame& frame) const {
  Slab s;
  if (origin.size() == 3) s.origin = Eigen::Vector3d(origin.data());
  if (normal.size() == 3) s.normal = Eigen::Vector3d(normal.data());
  if (axis.size() == 3) s.axis1 = Eigen::Vector3d(axis.data());
  s.thickness = thickness;
  if (d50_multiple > 0.0) s.thickness = d50_multiple * d50(frame);
  return s;
}

}  // namespace gs::analysis
