// granoscope.rev and granoscope.shearzone: the maps of `granoscope analyze rev` and `analyze
// shearzone`, through the same library calls (analysis/rev_map.hpp), same numbers.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "common.hpp"
#include "rev_map.hpp"

namespace py = pybind11;
namespace ga = gs::analysis;

namespace gs::py_bind {
namespace {

// The grid as `analyze rev` writes it in /grid (dims nx, ny, nz: field[c] with c = i + nx (j +
// ny k), so field.reshape(dims[::-1]) indexes [k, j, i]).
py::dict grid_dict(const ga::RevGrid& g) {
  py::dict d;
  d["dims"] = array1(std::vector<std::int64_t>{g.n[0], g.n[1], g.n[2]});
  d["axes"] = Eigen::Matrix3d(g.axes);
  d["origin"] = Eigen::Vector3d(g.origin);
  d["first_centre_local"] = Eigen::Vector3d(g.lo + 0.5 * g.size);
  d["step"] = g.step;
  d["dim"] = g.dim;
  d["slab"] = g.slab;
  return d;
}

ga::GridSpec grid_spec(std::optional<double> cell, std::optional<double> cell_d50,
                       std::optional<double> step, std::optional<double> step_d50) {
  ga::GridSpec g;
  g.cell = cell;
  g.cell_d50 = cell_d50;
  g.step = step;
  g.step_d50 = step_d50;
  return g;
}

}  // namespace

void bind_maps(py::module_& m) {
  m.def(
      "rev",
      [](const Frame& f, std::optional<Frame> to, const std::string& method,
         std::optional<double> cell, std::optional<double> cell_d50, std::optional<double> step,
         std::optional<double> step_d50, std::optional<double> width,
         std::optional<double> width_d50, double particle_density, OptVec profile,
         int profile_points, bool slab, OptVec slab_origin, OptVec slab_normal, OptVec slab_axis,
         std::optional<double> slab_thickness, std::optional<double> slab_d50, OptVec region,
         std::optional<double> d50) {
        ga::RevMapSpec spec;
        spec.method = method;
        spec.grid = grid_spec(cell, cell_d50, step, step_d50);
        spec.width = width;
        spec.width_d50 = width_d50;
        spec.particle_density = particle_density;
        spec.selection = selection_spec(slab, slab_origin, slab_normal, slab_axis, slab_thickness,
                                        slab_d50, region);
        const double d = frame_d50(f, d50);
        ga::RevMap r;
        std::vector<VtkArray> prof;
        {
          py::gil_scoped_release unlocked;
          r = ga::rev_map(kFrame, f, to ? &*to : nullptr, d, spec);
          if (profile) prof = ga::rev_profile(kFrame, r, *profile, profile_points);
        }
        py::dict cells = table(ga::rev_cell_table(r));
        py::dict out;
        out["method"] = r.method;
        out["mode"] = r.mode();
        out["d50"] = r.d50;
        out["cell"] = r.cell;
        out["step"] = r.step;
        out["width"] = r.width;
        out["slab_thickness"] = r.slab_thickness;
        out["particle_contacts"] = r.particle_contacts;
        out["wall_contacts"] = r.wall_contacts;
        out["seconds"] = r.seconds;
        out["grid"] = grid_dict(r.grid);
        out["cells"] = cells;
        if (profile) out["profile"] = table(prof);
        return out;
      },
      py::arg("frame"), py::kw_only(), py::arg("to") = py::none(), py::arg("method") = "box",
      py::arg("cell") = py::none(), py::arg("cell_d50") = py::none(), py::arg("step") = py::none(),
      py::arg("step_d50") = py::none(), py::arg("width") = py::none(),
      py::arg("width_d50") = py::none(), py::arg("particle_density") = 2650.0,
      py::arg("profile") = py::none(), py::arg("profile_points") = 0, py::arg("slab") = false,
      py::arg("slab_origin") = py::none(), py::arg("slab_normal") = py::none(),
      py::arg("slab_axis") = py::none(), py::arg("slab_thickness") = py::none(),
      py::arg("slab_d50") = py::none(), py::arg("region") = py::none(), py::arg("d50") = py::none(),
      "REV map as `granoscope analyze rev`: method 'box' (REV cells L = cell, default 5 d50, "
      "every step, default 1 d50; seed 000 §3) or 'gaussian' (coarse-graining, kernel width); "
      "3D or in a slab. Returns grid (dims nx, ny, nz; a field reshaped to dims[::-1] indexes "
      "[k, j, i]), cells (centre, local in m; void_ratio, solid_fraction, solid_volume m^3, "
      "particles, coordination, rotation rad, displacement m (with `to`), stress Pa (n, 3, 3), "
      "p, q Pa, eta, phi_mob_deg, b, lode_deg; gaussian: density kg/m^3, velocity m/s, "
      "stress_contact, stress_kinetic) and, with profile = [x0, y0, z0, x1, y1, z1], the fields "
      "interpolated along that line.");

  m.def(
      "shearzone",
      [](const Frame& f, std::optional<Frame> to, const std::string& field,
         std::optional<double> cell, std::optional<double> cell_d50, std::optional<double> step,
         std::optional<double> step_d50, OptVec slab_origin, OptVec slab_normal, OptVec slab_axis,
         std::optional<double> slab_thickness, std::optional<double> slab_d50,
         std::optional<double> d50) {
        ga::ShearZoneSpec spec;
        spec.field = field;
        spec.grid = grid_spec(cell, cell_d50, step, step_d50);
        spec.selection = selection_spec(false, slab_origin, slab_normal, slab_axis, slab_thickness,
                                        slab_d50, std::nullopt);
        const double d = frame_d50(f, d50);
        ga::ShearZoneMap s;
        {
          py::gil_scoped_release unlocked;
          s = ga::shear_zone_map(kFrame, f, to ? &*to : nullptr, d, spec);
        }
        const ga::ShearZone& z = s.zone;
        py::dict out;
        out["field"] = field;
        out["d50"] = s.d50;
        out["cell"] = s.cell;
        out["step"] = s.step;
        out["angle_deg"] = z.angle_deg;
        out["inclination_deg"] = z.inclination_deg;
        out["thickness_m"] = z.thickness;
        out["thickness_d50"] = z.thickness / s.d50;
        out["lower_m"] = z.lower_d;
        out["upper_m"] = z.upper_d;
        out["peak_value"] = z.peak_value;
        out["by_rows"] = z.by_rows;
        out["grid"] = grid_dict(s.grid);
        py::dict map;
        map["value"] = array2(s.map.value, static_cast<std::size_t>(s.map.nu));
        map["u0"] = s.map.u0;
        map["v0"] = s.map.v0;
        map["step"] = s.map.step;
        out["map"] = map;
        py::dict ridge;
        ridge["points"] = rows2(z.ridge);
        ridge["inlier"] = array1(z.inlier);
        out["ridge"] = ridge;
        py::dict line;
        line["point"] = Eigen::Vector2d(z.point);
        line["direction"] = Eigen::Vector2d(z.direction);
        out["line"] = line;
        py::dict profile;
        profile["distance"] = array1(z.profile_d);
        profile["value"] = array1(z.profile_value);
        out["profile"] = profile;
        return out;
      },
      py::arg("frame"), py::kw_only(), py::arg("to") = py::none(), py::arg("field") = "rotation",
      py::arg("cell") = py::none(), py::arg("cell_d50") = py::none(), py::arg("step") = py::none(),
      py::arg("step_d50") = py::none(), py::arg("slab_origin") = py::none(),
      py::arg("slab_normal") = py::none(), py::arg("slab_axis") = py::none(),
      py::arg("slab_thickness") = py::none(), py::arg("slab_d50") = py::none(),
      py::arg("d50") = py::none(),
      "Shear band as `granoscope analyze shearzone`: on a REV map (a slab of a 3D frame, default "
      "the front view) of |rotation| about the map normal (field 'rotation') or of the shear "
      "strain of the displacement to `to` ('shear'): inclination_deg to the horizontal, "
      "thickness_m (inflection points of the profile across the band), the map (rows v, "
      "columns u; u0, v0, step in m), ridge points and the fitted line.");
}

}  // namespace gs::py_bind
