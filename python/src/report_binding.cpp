// granoscope.rotation, .silo, .interface and .materials: the scene reports of `granoscope analyze
// rotation | silo | interface | materials` (seed 003 §3-4, seed 004 §5.3 and §4.3-4.4, the DEM8
// drum's mixing monitor), through the same library calls (analysis/rotation_report.hpp,
// silo_series.hpp, interface_zone.hpp, material_zones.hpp).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "common.hpp"
#include "errors.hpp"
#include "grain_size.hpp"
#include "interface_zone.hpp"
#include "material_zones.hpp"
#include "rotation_report.hpp"
#include "silo_series.hpp"

namespace py = pybind11;
namespace ga = gs::analysis;

namespace gs::py_bind {
namespace {

constexpr const char* kRun = "<trajectory>";
using Parameters = std::vector<std::pair<std::string, std::string>>;

// A run's recorded parameters: a Trajectory's metadata; a list of frames has none.
Parameters parameters_of(const py::object& run) {
  if (py::hasattr(run, "parameters")) return run.attr("parameters").cast<Parameters>();
  return {};
}

// Frame i of a Trajectory or a list of Frames (negative: from the end).
Frame frame_of(const py::object& run, long i, long n, const char* what) {
  if (i < 0) i += n;
  if (i < 0 || i >= n)
    throw InputError(kRun, std::string(what) + " out of range 0.." + std::to_string(n - 1),
                     std::to_string(i));
  return run[py::int_(i)].cast<Frame>();
}

Eigen::Vector3d vec3(const std::vector<double>& v, const char* name) {
  if (v.size() != 3) throw InputError(kRun, std::string(name) + " needs 3 numbers");
  return {v[0], v[1], v[2]};
}

}  // namespace

void bind_reports(py::module_& m) {
  m.def(
      "rotation",
      [](py::object run, const std::filesystem::path& curve, double window_deg) {
        if (!(window_deg > 0))
          throw InputError(kRun, "window_deg must be positive", std::to_string(window_deg));
        std::vector<Frame> frames;
        const auto n = static_cast<long>(py::len(run));
        for (long i = 0; i < n; ++i) frames.push_back(run[py::int_(i)].cast<Frame>());
        ga::RotationReport r;
        {
          py::gil_scoped_release unlocked;
          r = ga::rotation_report(ga::read_rotation_curve(curve), frames, window_deg,
                                  curve.string(), kRun);
        }
        const auto table = [](const ga::RotationColumns& c) {
          py::dict d;
          for (const auto& [name, v] : c) d[py::str(name)] = array1(v);
          return d;
        };
        py::dict out;
        out["strain"] = table(ga::rotation_strain_table(r));
        out["increments"] = table(ga::rotation_increments_table(r));
        out["fabric"] = table(ga::rotation_fabric_table(r));
        out["cycles"] = table(ga::rotation_cycles_table(r));
        return out;
      },
      py::arg("run"), py::arg("curve"), py::arg("window_deg") = 3.0,
      "Principal stress rotation report as `granoscope analyze rotation` (seed 003 §3-4) of a "
      "stress_rotation run (a Trajectory or list of Frames) and its curve.csv: dicts 'strain', "
      "'increments', 'fabric' and 'cycles' of numpy columns, named as the CSV files' columns "
      "(docs/rotation.md).");

  m.def(
      "silo",
      [](py::object run, std::vector<double> up, std::vector<double> across, long from_frame,
         std::optional<double> from_time, std::optional<double> bin, std::optional<double> bin_d50,
         std::optional<double> depth, std::optional<double> d50, double gravity,
         std::optional<double> zone_height, double zone_band_d50, double zone_bin_d50,
         double zone_window_d50, double zone_extent_factor, std::vector<double> layers,
         double layer_bin_d50, double layer_band_d50, int rose_bins, double rev_width_d50,
         int flow_bands, double flow_wall_d50, double flow_threshold, double phi_i, double en_k) {
        ga::SiloSpec spec;
        spec.up = vec3(up, "--up");
        spec.across = vec3(across, "--across");
        spec.from = from_frame;
        spec.from_time = from_time;
        spec.bin = bin;
        spec.bin_d50 = bin_d50;
        spec.depth = depth;
        spec.d50 = d50;
        spec.scene_d50 = ga::recorded_d50(parameters_of(run));  // as the CLI
        spec.gravity = gravity;
        spec.zone_height = zone_height;
        spec.zone_band_d50 = zone_band_d50;
        spec.zone_bin_d50 = zone_bin_d50;
        spec.zone_window_d50 = zone_window_d50;
        spec.zone_extent_factor = zone_extent_factor;
        spec.layers = layers;
        spec.layer_bin_d50 = layer_bin_d50;
        spec.layer_band_d50 = layer_band_d50;
        spec.rose_bins = rose_bins;
        spec.rev_width_d50 = rev_width_d50;
        spec.flow_bands = flow_bands;
        spec.flow_wall_d50 = flow_wall_d50;
        spec.flow_threshold = flow_threshold;
        spec.phi_i = phi_i;
        spec.en_k = en_k;
        std::vector<Frame> frames;
        const auto n = static_cast<long>(py::len(run));
        for (long i = 0; i < n; ++i) frames.push_back(run[py::int_(i)].cast<Frame>());
        ga::SiloSeries s;
        {
          py::gil_scoped_release unlocked;
          s = ga::silo_series(kRun, frames, spec);
        }
        py::dict series;
        for (const auto& [name, v] : s.series) series[py::str(name)] = array1(v);
        py::list states;
        for (const auto& st : s.states) {
          const auto& r = s.reports[st.index];
          py::dict d;
          d["name"] = st.name;
          d["frame"] = s.from + static_cast<long>(st.index);
          d["time_s"] = r.time;
          d["P_G"] = r.P / r.G;
          d["phi_w_mean_deg"] = st.phi_w_mean_deg;
          d["K_drescher"] = st.K_drescher;
          d["P_G_drescher"] = st.P_G_drescher;
          d["P_G_en1991"] = st.P_G_en1991;
          d["width_m"] = r.width;
          d["fill_height_m"] = r.fill_height;
          py::dict prof;
          prof["height_m"] = array1(r.profile.height);
          prof["sigma11_left_Pa"] = array1(r.profile.sigma11_left);
          prof["sigma21_left_Pa"] = array1(r.profile.sigma21_left);
          prof["sigma11_right_Pa"] = array1(r.profile.sigma11_right);
          prof["sigma21_right_Pa"] = array1(r.profile.sigma21_right);
          prof["lw_sigma11_left_Pa"] = array1(r.profile.lw_sigma11_left);
          prof["lw_sigma21_left_Pa"] = array1(r.profile.lw_sigma21_left);
          prof["lw_sigma11_right_Pa"] = array1(r.profile.lw_sigma11_right);
          prof["lw_sigma21_right_Pa"] = array1(r.profile.lw_sigma21_right);
          d["profile"] = prof;
          py::dict zone;
          zone["height_m"] = r.zone_height;
          zone["left_m"] = r.zone_left;
          zone["right_m"] = r.zone_right;
          zone["core_rad"] = r.zone_core;
          zone["extent_left_m"] = r.zone_extent_left;
          zone["extent_right_m"] = r.zone_extent_right;
          zone["across_m"] = array1(r.zone_across);
          zone["rotation_rad"] = array1(r.zone_rotation);
          d["zone"] = zone;
          py::list layers_out;
          for (const auto& L : r.layers) {
            py::dict l;
            l["height_m"] = L.height;
            l["across_m"] = array1(L.across);
            l["void_ratio"] = array1(L.void_ratio);
            l["displacement_down_m"] = array1(L.displacement_down);
            l["rotation_rad"] = array1(L.rotation);
            layers_out.append(l);
          }
          d["layers"] = layers_out;
          d["rose_left_angle_deg"] = array1(r.rose_angle_deg);
          d["rose_left_density"] = array1(r.rose_density);
          d["fabric_left_angle_deg"] = r.fabric_angle_deg;
          d["fabric_left_anisotropy"] = r.fabric_anisotropy;
          d["fabric_left_contacts"] = r.fabric_contacts;
          d["flow_pattern"] = ga::flow_pattern_name(r.flow);
          states.append(d);
        }
        py::dict out;
        out["d50"] = s.d50;
        out["bin"] = s.options.bin;
        out["from_frame"] = s.from;
        out["series"] = series;
        out["states"] = states;
        return out;
      },
      py::arg("run"), py::kw_only(), py::arg("up") = std::vector<double>{0, 0, 1},
      py::arg("across") = std::vector<double>{1, 0, 0}, py::arg("from_frame") = 0,
      py::arg("from_time") = py::none(), py::arg("bin") = py::none(),
      py::arg("bin_d50") = py::none(), py::arg("depth") = py::none(), py::arg("d50") = py::none(),
      py::arg("gravity") = 9.81, py::arg("zone_height") = py::none(),
      py::arg("zone_band_d50") = 5.0, py::arg("zone_bin_d50") = 1.0,
      py::arg("zone_window_d50") = 0.0, py::arg("zone_extent_factor") = 2.0,
      py::arg("layers") = std::vector<double>{0.2, 0.5, 0.8}, py::arg("layer_bin_d50") = 2.0,
      py::arg("layer_band_d50") = 5.0, py::arg("rose_bins") = 36, py::arg("rev_width_d50") = 2.0,
      py::arg("flow_bands") = 10, py::arg("flow_wall_d50") = 3.0, py::arg("flow_threshold") = 0.1,
      py::arg("phi_i") = 35.0, py::arg("en_k") = 0.63,
      "Silo report as `granoscope analyze silo` (seed 004 §5.3) of a silo run (a Trajectory or "
      "a list of Frames): series per frame (frame, time_s, G_N, P_N, T_left_N, ..., P_G, "
      "T_left_G, ..., balance_G, phi_w_left_deg, discharged_kg, flow_pattern, ...) and the "
      "initial, maximum and residual states with their wall stress profiles (Pa), shear zones, "
      "void-ratio layers, left-half rose, and the slice method beside ours (P_G_drescher, "
      "P_G_en1991).");

  m.def(
      "interface",
      [](py::object run, long frame, long from_frame, std::optional<double> surface_z,
         std::optional<double> bin, std::optional<double> bin_d50, double inset_d50,
         std::optional<double> d50) {
        const auto n = static_cast<long>(py::len(run));
        const Frame f = frame_of(run, frame, n, "frame");
        const long k = frame < 0 ? frame + n : frame;
        const long r = from_frame < 0 ? from_frame + n : from_frame;
        std::optional<Frame> reference;
        if (r != k) reference = frame_of(run, r, n, "--from");
        ga::InterfaceSpec spec;
        spec.surface_z = surface_z;
        spec.bin = bin;
        spec.bin_d50 = bin_d50;
        spec.inset_d50 = inset_d50;
        const double d = frame_d50(f, d50 ? d50 : ga::recorded_d50(parameters_of(run)));
        ga::InterfaceZoneOptions o =
            ga::interface_zone_options(kRun, d, spec, ga::recorded_surface(parameters_of(run)));
        if (reference) o.reference = &*reference;
        ga::InterfaceZone z;
        try {
          py::gil_scoped_release unlocked;
          z = ga::interface_zone(f, o);
        } catch (const std::invalid_argument& e) {
          throw InputError(kRun, "frame " + std::to_string(k) + ": " + e.what());
        }
        py::dict out;
        out["frame"] = k;
        out["reference_frame"] = r;
        out["time_s"] = f.time;
        out["d50"] = d;
        out["bin"] = o.bin;
        out["surface_z_m"] = o.surface_z;
        out["x_lo_m"] = z.x_lo;
        out["x_hi_m"] = z.x_hi;
        out["peak_height_m"] = z.peak_height;
        out["zone_lower_m"] = z.lower;
        out["zone_upper_m"] = z.upper;
        out["zone_thickness_m"] = z.thickness;
        out["u_top_m"] = z.u_top;
        out["u_surface_m"] = z.u_surface;
        out["slip_ratio"] = z.slip_ratio;
        out["height_m"] = array1(z.height);
        out["rotation_rad"] = array1(z.rotation);
        out["displacement_x_m"] = array1(z.displacement);
        out["count"] = array1(z.count);
        return out;
      },
      py::arg("run"), py::kw_only(), py::arg("frame") = -1, py::arg("from_frame") = 0,
      py::arg("surface_z") = py::none(), py::arg("bin") = py::none(),
      py::arg("bin_d50") = py::none(), py::arg("inset_d50") = 2.0, py::arg("d50") = py::none(),
      "Interface shear zone as `granoscope analyze interface` (seed 004 §4.3-4.4) of frame "
      "`frame` of `run` (a Trajectory or a list of Frames; displacements since `from_frame`): "
      "profiles of rotation (rad), x displacement (m) and count against the height above the "
      "surface (m), the zone's boundaries and thickness (m), the slip ratio. surface_z: the "
      "surface's mean level (default: what an interface shear run recorded).");

  m.def(
      "materials",
      [](py::object run, std::vector<std::string> zones, bool drum, long every) {
        const std::vector<ga::Zone> z = ga::material_zones(kRun, drum, zones);
        const auto n = static_cast<long>(py::len(run));
        const auto cols = ga::material_table(
            kRun, n, [&run](long i) { return run[py::int_(i)].cast<Frame>(); }, every, z,
            ga::recorded_material_names(parameters_of(run)));
        return table(cols);
      },
      py::arg("run"), py::kw_only(), py::arg("zones") = std::vector<std::string>{},
      py::arg("drum") = false, py::arg("every") = 1,
      "Per frame, each material's count, centre of mass (m) and counts in zones, as `granoscope "
      "analyze materials` (the DEM8 drum's mixing monitor): {column: array} with the CSV's "
      "columns. zones: 'NAME:xlo,ylo,zlo,xhi,yhi,zhi'; drum: the quadrants x+z- and x-z+.");
}

}  // namespace gs::py_bind
