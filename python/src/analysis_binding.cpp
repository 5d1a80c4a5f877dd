// Analyses of frames, as the `analyze` subcommands compute them (same library calls, same
// numbers). Results are dicts of numpy arrays and scalars with the CLI's HDF5 names.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "bindings.hpp"
#include "common.hpp"
#include "errors.hpp"
#include "fabric.hpp"
#include "fabric_report.hpp"
#include "force_chains.hpp"
#include "grain_size.hpp"
#include "love_weber_stress.hpp"
#include "rose_report.hpp"
#include "selection.hpp"
#include "snapshot.hpp"
#include "specimen_stress.hpp"
#include "tensor_invariants.hpp"
#include "wall_stress.hpp"

namespace py = pybind11;
namespace ga = gs::analysis;

namespace gs::py_bind {
namespace {

// The selection the CLI's --slab* / --region / --d50 options would make on this frame.
ga::Selection selection_of(const Frame& f, bool slab, const OptVec& slab_origin,
                           const OptVec& slab_normal, const OptVec& slab_axis,
                           std::optional<double> slab_thickness, std::optional<double> slab_d50,
                           const OptVec& region, std::optional<double> d50) {
  return ga::make_selection(
      kFrame, f, frame_d50(f, d50),
      selection_spec(slab, slab_origin, slab_normal, slab_axis, slab_thickness, slab_d50, region));
}

// The invariants of a stress tensor under their C++ names (`invariants`' "stress" dict and
// `stress_invariants`).
void put_stress_invariants(py::dict& d, const ga::StressInvariants& s) {
  d["p"] = s.p;
  d["q"] = s.q;
  d["eta"] = s.eta;
  d["b"] = s.b;
  d["lode_deg"] = s.lode_deg;
  d["phi_mob_deg"] = s.phi_mob_deg;
  d["j2d"] = s.j2d;
  d["j3d"] = s.j3d;
  d["asymmetry"] = s.asymmetry;
  d["principal"] = s.principal;
  d["directions"] = s.directions;
}

}  // namespace

void bind_analysis(py::module_& m) {
  m.def(
      "d50", [](const Frame& f) { return ga::d50(f); }, py::arg("frame"),
      "Median diameter (m): by volume in 3D, by area in 2D.");

  m.def(
      "fabric",
      [](const Frame& f, bool slab, OptVec slab_origin, OptVec slab_normal, OptVec slab_axis,
         std::optional<double> slab_thickness, std::optional<double> slab_d50, OptVec region,
         std::optional<double> d50) {
        const ga::Selection sel = selection_of(f, slab, slab_origin, slab_normal, slab_axis,
                                               slab_thickness, slab_d50, region, d50);
        const ga::FabricReport r = ga::fabric_report(kFrame, f, sel);
        const ga::Fabric& fab = r.contacts;
        const ga::OrientationFabric& o = r.orientation;
        py::dict orientation;
        orientation["source"] = ga::orientation_source_name(o.source);
        orientation["bodies"] = o.bodies;
        orientation["Phi"] = o.Phi;
        orientation["D"] = o.D;
        orientation["D_norm"] = o.D_norm;
        orientation["clump"] = o.clump;
        orientation["axis"] = o.axis;
        orientation["centroid"] = o.centroid;
        py::dict out;
        out["dim"] = fab.dim;
        out["particles"] = fab.particles;
        out["contacts"] = fab.contacts;
        out["omega"] = fab.omega;
        out["M"] = fab.M;
        out["D"] = fab.D;
        out["D_norm"] = fab.D_norm;
        out["D_principal"] = fab.D_principal;
        out["D_directions"] = fab.D_directions;
        out["view_axes"] = r.view_axes;
        out["orientation"] = orientation;
        return out;
      },
      py::arg("frame"), py::kw_only(), py::arg("slab") = false, py::arg("slab_origin") = py::none(),
      py::arg("slab_normal") = py::none(), py::arg("slab_axis") = py::none(),
      py::arg("slab_thickness") = py::none(), py::arg("slab_d50") = py::none(),
      py::arg("region") = py::none(), py::arg("d50") = py::none(),
      "Contact-normal fabric M_ij, coordination omega, Kanatani anisotropy D_ij (seed 003 eq "
      "18-21) and the clump orientation fabric, as `granoscope analyze fabric` (the selection "
      "keywords are its --slab* and --region options; lengths in m, slab_d50 in d50).");

  m.def(
      "rose",
      [](const Frame& f, double bin_deg, OptVec plane_normal, OptVec plane_axis, bool three_d,
         std::vector<int> bins3d, bool walls, bool slab, OptVec slab_origin, OptVec slab_normal,
         OptVec slab_axis, std::optional<double> slab_thickness, std::optional<double> slab_d50,
         OptVec region, std::optional<double> d50) {
        ga::RoseSpec spec;
        spec.bin_deg = bin_deg;
        spec.plane_normal = plane_normal.value_or(std::vector<double>{});
        spec.plane_axis = plane_axis.value_or(std::vector<double>{});
        spec.three_d = three_d;
        spec.bins3d = bins3d;
        spec.walls = walls;
        ga::check_rose_spec(kFrame, spec);
        const ga::Selection sel = selection_of(f, slab, slab_origin, slab_normal, slab_axis,
                                               slab_thickness, slab_d50, region, d50);
        const ga::RoseReport r = ga::rose_report(kFrame, f, sel, spec);
        const auto rose = [](const ga::Rose& x) {
          py::dict d;
          d["count"] = x.count;
          d["density"] = x.density;
          d["mean_fn"] = x.mean_fn;
          d["mean_fs"] = x.mean_fs;
          d["contacts"] = x.contacts;
          d["skipped"] = x.skipped;
          if (x.dim == 2) {
            d["angle_deg"] = x.angle_deg;
            d["bin_rad"] = x.bin_size;
          } else {
            d["direction"] = x.direction;
            d["solid_angle"] = x.bin_size;
            d["n_theta"] = x.n_theta;
            d["n_phi"] = x.n_phi;
          }
          return d;
        };
        py::dict out;
        out["axes"] = r.axes;
        out["rose2d"] = rose(r.rose2d);
        if (r.rose3d) out["rose3d"] = rose(*r.rose3d);
        return out;
      },
      py::arg("frame"), py::kw_only(), py::arg("bin_deg") = 10.0,
      py::arg("plane_normal") = py::none(), py::arg("plane_axis") = py::none(),
      py::arg("three_d") = false, py::arg("bins3d") = std::vector<int>{18, 36},
      py::arg("walls") = false, py::arg("slab") = false, py::arg("slab_origin") = py::none(),
      py::arg("slab_normal") = py::none(), py::arg("slab_axis") = py::none(),
      py::arg("slab_thickness") = py::none(), py::arg("slab_d50") = py::none(),
      py::arg("region") = py::none(), py::arg("d50") = py::none(),
      "Polar histograms of contact normals with the mean |Fn| and |Fs| per bin, as `granoscope "
      "analyze rose` (its /rose2d and /rose3d datasets; axes = rows e1, e2, n of the plane).");

  m.def(
      "chains",
      [](const Frame& f, std::optional<double> threshold, double mean_factor, bool walls, bool slab,
         OptVec slab_origin, OptVec slab_normal, OptVec slab_axis,
         std::optional<double> slab_thickness, std::optional<double> slab_d50, OptVec region,
         std::optional<double> d50) {
        ga::ChainOptions o;
        o.threshold_n = threshold.value_or(-1.0);
        o.mean_factor = mean_factor;
        o.walls = walls;
        ga::check_chain_options(kFrame, o);
        const ga::Selection sel = selection_of(f, slab, slab_origin, slab_normal, slab_axis,
                                               slab_thickness, slab_d50, region, d50);
        const ga::ForceChains c = ga::force_chains_in(kFrame, f, sel, o);
        py::dict out;
        out["a"] = c.a;
        out["b"] = c.b;
        out["fn"] = c.fn;
        out["fs"] = c.fs;
        out["strong"] = std::vector<bool>(c.strong.begin(), c.strong.end());
        out["chain"] = c.chain;
        out["mean_fn"] = c.mean_fn;
        out["max_fn"] = c.max_fn;
        out["threshold"] = c.threshold;
        out["strong_count"] = c.strong_count;
        out["chains"] = c.chains;
        out["largest_chain"] = c.largest_chain;
        out["view_axes"] = ga::view_axes(f, sel.slab);
        return out;
      },
      py::arg("frame"), py::kw_only(), py::arg("threshold") = py::none(),
      py::arg("mean_factor") = 1.0, py::arg("walls") = false, py::arg("slab") = false,
      py::arg("slab_origin") = py::none(), py::arg("slab_normal") = py::none(),
      py::arg("slab_axis") = py::none(), py::arg("slab_thickness") = py::none(),
      py::arg("slab_d50") = py::none(), py::arg("region") = py::none(), py::arg("d50") = py::none(),
      "Strong-force network as `granoscope analyze chains`: per contact segment its ends a, b "
      "(m), |Fn|, |Fs| (N), strong flag and chain id (-1: not a strong particle contact); the "
      "threshold (N; default mean |Fn| x mean_factor), counts of strong contacts and chains.");

  m.def(
      "walls",
      [](const Frame& f, std::vector<double> up, std::optional<double> bin,
         std::optional<double> bin_d50, std::optional<double> width, double gravity,
         double particle_density, std::optional<double> d50) {
        if (up.size() != 3) throw InputError(kFrame, "--up needs 3 numbers");
        ga::WallSpec spec;
        spec.up = Eigen::Vector3d(up[0], up[1], up[2]);
        spec.bin = bin;
        spec.bin_d50 = bin_d50;
        spec.width = width;
        spec.gravity = gravity;
        spec.particle_density = particle_density;
        const ga::WallReport r = ga::wall_report(kFrame, f, frame_d50(f, d50), spec);
        const ga::WallLoads& w = r.loads;
        py::list walls;
        for (const auto& l : w.walls) {
          py::dict d;
          d["id"] = l.id;
          d["role"] = l.role;
          d["inferred"] = l.inferred;
          d["contacts"] = l.contacts;
          d["N"] = l.N;
          d["T"] = l.T;
          d["phi_w_deg"] = l.phi_deg;
          d["width"] = l.width;
          d["force"] = l.force;
          d["recorded_force"] = l.recorded;
          d["normal"] = l.normal;
          d["axis"] = l.axis;
          d["position"] = l.position;
          d["sigma_n"] = l.sigma_n;
          d["tau"] = l.tau;
          d["count"] = l.count;
          walls.append(d);
        }
        py::dict out;
        out["P"] = w.P;
        out["T"] = w.T;
        out["N"] = w.N;
        out["G"] = w.G;
        out["phi_w_deg"] = w.phi_deg;
        out["bin"] = r.options.bin;
        out["up"] = Eigen::Vector3d(r.options.up.normalized());
        out["walls"] = walls;
        return out;
      },
      py::arg("frame"), py::kw_only(), py::arg("up") = std::vector<double>{0.0, 0.0, 1.0},
      py::arg("bin") = py::none(), py::arg("bin_d50") = py::none(), py::arg("width") = py::none(),
      py::arg("gravity") = 9.81, py::arg("particle_density") = 2650.0, py::arg("d50") = py::none(),
      "Wall stresses as `granoscope analyze walls` (seed 004 §5.3.1): per wall its role, N, T "
      "(N), phi_w, and the profiles sigma_n, tau (Pa) at bin centres `position` (m along "
      "`axis`); resultants P, T, N, G (N) and phi_w.");

  m.def(
      "invariants",
      [](std::optional<Frame> frame, std::optional<Frame> to, OptVec region,
         std::optional<Eigen::Matrix3d> stress, std::optional<Eigen::Matrix3d> gradient) {
        // `granoscope analyze invariants`: a given stress / gradient wins over the frame's.
        int dim = frame && frame->two_d ? 2 : 3;
        py::dict out;
        std::optional<Eigen::Matrix3d> sigma = stress, F = gradient;
        if (sigma && !sigma->allFinite())
          throw InputError(kFrame, "--stress must be 9 finite numbers");
        if (F && !F->allFinite()) throw InputError(kFrame, "--gradient must be 9 finite numbers");
        py::dict sd;
        if (frame && !sigma) {
          ga::SelectionSpec spec;
          spec.region = region.value_or(std::vector<double>{});
          const ga::SpecimenStress st =
              ga::specimen_stress(kFrame, *frame, spec.make_region(kFrame));
          sigma = st.sigma;
          sd["volume"] = st.volume;
          if (st.boundary_eq14) sd["boundary_eq14"] = *st.boundary_eq14;
        }
        if (frame && to && !F) F = ga::fit_deformation_gradient(kFrame, *frame, *to);
        if (!sigma && !F) throw InputError(kFrame, "nothing to evaluate");
        if (sigma) {
          const ga::StressInvariants s = ga::stress_invariants(*sigma, dim);
          sd["tensor"] = *sigma;
          put_stress_invariants(sd, s);
          out["stress"] = sd;
        }
        if (F) {
          ga::StrainInvariants e;
          try {
            e = ga::strain_invariants(*F);
          } catch (const std::invalid_argument& x) {
            throw InputError(kFrame, x.what());
          }
          py::dict ed;
          ed["F"] = *F;
          ed["U"] = e.U;
          ed["R"] = e.R;
          ed["biot"] = e.biot;
          ed["Fv"] = e.Fv;
          ed["Fd"] = e.Fd;
          ed["directions"] = e.directions;
          ed["principal"] = e.principal;
          ed["J"] = e.J;
          ed["eps_v"] = e.eps_v;
          ed["eps_q"] = e.eps_q;
          ed["b_eps"] = e.b_eps;
          ed["b_stretch"] = e.b_stretch;
          ed["lode_deg"] = e.lode_deg;
          out["strain"] = ed;
        }
        return out;
      },
      py::arg("frame") = py::none(), py::kw_only(), py::arg("to") = py::none(),
      py::arg("region") = py::none(), py::arg("stress") = py::none(),
      py::arg("gradient") = py::none(),
      "As `granoscope analyze invariants`: the specimen stress of `frame` (Love-Weber over "
      "`region`, the periodic cell or the particles' box; with wall contacts also seed 003 eq "
      "14) or a given `stress`, and its invariants; the deformation gradient fitted from "
      "`frame` to `to` (or a given `gradient`) and its invariants (seed 003 eqs 2, 11, 12).");

  m.def(
      "stress_invariants",
      [](const Eigen::Matrix3d& sigma, int dim) {
        if (dim != 2 && dim != 3) throw InputError("dim", "must be 2 or 3", std::to_string(dim));
        const ga::StressInvariants s = ga::stress_invariants(sigma, dim);
        py::dict out;
        put_stress_invariants(out, s);
        return out;
      },
      py::arg("sigma"), py::arg("dim") = 3,
      "Invariants of the symmetric part of a stress tensor (Pa; compression positive): p, q, "
      "eta = q/p, b, Lode angle, mobilised friction angle, principal values and directions.");
}

}  // namespace gs::py_bind
