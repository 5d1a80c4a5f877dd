// Analyses of frames, as the `analyze` subcommands compute them (same library calls, same
// numbers). Results are dicts of numpy arrays and scalars with the CLI's HDF5 names.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "errors.hpp"
#include "fabric.hpp"
#include "grain_size.hpp"
#include "love_weber_stress.hpp"
#include "snapshot.hpp"
#include "tensor_invariants.hpp"

namespace py = pybind11;
namespace ga = gs::analysis;

namespace gs::py_bind {

void bind_analysis(py::module_& m) {
  m.def(
      "d50", [](const Frame& f) { return ga::d50(f); }, py::arg("frame"),
      "Median diameter (m): by volume in 3D, by area in 2D.");

  m.def(
      "fabric",
      [](const Frame& f) {
        // `granoscope analyze fabric` over the whole frame (particle-particle contacts).
        const ga::ContactBranches b = ga::contact_branches(f);
        std::vector<Eigen::Vector3d> normals;
        for (const auto& br : b.branches)
          if (br.p2 >= 0)
            normals.push_back(f.contacts[static_cast<std::size_t>(br.contact)].normal);
        ga::Fabric fab;
        try {
          fab = ga::contact_fabric(normals, f.particles.size(), f.two_d ? 2 : 3);
        } catch (const std::invalid_argument& e) {
          throw InputError("<frame>", e.what());
        }
        const auto o = f.clumps.empty() ? ga::member_orientation_fabric(f)
                                        : ga::body_orientation_fabric(f.clumps, fab.dim);
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
        out["orientation"] = orientation;
        return out;
      },
      py::arg("frame"),
      "Contact-normal fabric M_ij, coordination omega, Kanatani anisotropy D_ij (seed 003 eq "
      "18-21) and the clump orientation fabric, as `granoscope analyze fabric` without a "
      "selection.");

  m.def(
      "stress_invariants",
      [](const Eigen::Matrix3d& sigma, int dim) {
        if (dim != 2 && dim != 3) throw InputError("dim", "must be 2 or 3", std::to_string(dim));
        const ga::StressInvariants s = ga::stress_invariants(sigma, dim);
        py::dict out;
        out["p"] = s.p;
        out["q"] = s.q;
        out["eta"] = s.eta;
        out["b"] = s.b;
        out["lode_deg"] = s.lode_deg;
        out["phi_mob_deg"] = s.phi_mob_deg;
        out["j2d"] = s.j2d;
        out["j3d"] = s.j3d;
        out["principal"] = s.principal;
        out["directions"] = s.directions;
        out["asymmetry"] = s.asymmetry;
        return out;
      },
      py::arg("sigma"), py::arg("dim") = 3,
      "Invariants of the symmetric part of a stress tensor (Pa; compression positive): p, q, "
      "eta = q/p, b, Lode angle, mobilised friction angle, principal values and directions.");
}

}  // namespace gs::py_bind
