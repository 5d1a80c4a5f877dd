// `granoscope surface sawtooth | sinusoid | box -o FILE.stl`: the seeds' wall surfaces
// (solver/boundaries/surface_generators.hpp; seed 004 §4.3-4.4, §5.2 Fig 5.2) as ASCII STL, for
// a scene's [[mesh]] and for ParaView.
#include <array>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "commands.hpp"
#include "errors.hpp"
#include "surface_generators.hpp"
#include "triangle_mesh.hpp"

namespace gs::cli {

namespace {

struct Frame3 {
  std::array<double, 3> origin{0, 0, 0}, along{1, 0, 0}, normal{0, 0, 1};
};

Eigen::Vector3d vec(const std::array<double, 3>& a) {
  return {a[0], a[1], a[2]};
}

void add_frame(CLI::App* c, Frame3& f) {
  c->add_option("--origin", f.origin, "corner u = v = 0 on the base plane, m")->delimiter(',');
  c->add_option("--along", f.along, "e_u: the profile direction (across the ridges)")
      ->delimiter(',');
  c->add_option("--normal", f.normal, "e_n: into the granular material")->delimiter(',');
}

void write(const TriangleMesh& m, const std::string& out, const std::string& what) {
  write_stl_ascii(m, out);
  std::cerr << "wrote " << out << " (" << what << ", " << m.triangles.size() << " triangles)\n";
}

/// The generators' std::invalid_argument as the one-line error naming the output file.
template <class F>
void guarded(const std::string& out, F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    throw InputError(out, e.what());
  }
}

/// A patch generator's subcommand: the options every patch has (L, W, frame, group, output),
/// `extra` adds its own, and the callback writes `make(spec)`.
template <class Spec, class Extra, class Make>
void add_patch(CLI::App* cmd, const char* name, const char* help, const char* what, Extra extra,
               Make make) {
  auto* c = cmd->add_subcommand(name, help);
  auto s = std::make_shared<Spec>();
  auto f = std::make_shared<Frame3>();
  auto out = std::make_shared<std::string>();
  c->add_option("--length", s->length_m, "L along e_u, m")->required();
  c->add_option("--width", s->width_m, "W along the ridges, m")->required();
  extra(c, *s);
  c->add_option("--group", s->group, "STL solid name")->capture_default_str();
  add_frame(c, *f);
  c->add_option("-o,--out", *out, "output .stl")->required();
  c->callback([=] {
    guarded(*out, [&] {
      Spec spec = *s;
      spec.origin = vec(f->origin);
      spec.along = vec(f->along);
      spec.normal = vec(f->normal);
      write(make(spec), *out, what);
    });
  });
}

}  // namespace

void register_surface(CLI::App& app) {
  auto* cmd = app.add_subcommand("surface", "Write a wall surface of the seeds as ASCII STL");
  cmd->require_subcommand(1);
  add_patch<solver::SawToothSpec>(
      cmd, "sawtooth", "Saw-tooth wall (seed 004 §4.3, §5.2 Fig 5.2)", "saw-tooth wall",
      [](CLI::App* c, solver::SawToothSpec& s) {
        c->add_option("--height", s.height_m, "groove height h_g = R_n·d50, m")->required();
        c->add_option("--spacing", s.spacing_m, "groove spacing s_g (tip to tip), m")->required();
        c->add_option("--slope", s.slope_deg, "ramp inclination α_g, degrees")
            ->capture_default_str();
        c->add_option("--back-slope", s.back_slope_deg, "back face inclination, degrees")
            ->capture_default_str();
      },
      [](const solver::SawToothSpec& s) { return solver::saw_tooth_wall(s); });
  add_patch<solver::SinusoidSpec>(
      cmd, "sinusoid", "Sinusoidal corrugation (seed 004 §4.4)", "sinusoidal wall",
      [](CLI::App* c, solver::SinusoidSpec& s) {
        c->add_option("--depth", s.depth_m, "depth d, trough to crest, m")->required();
        c->add_option("--wavelength", s.wavelength_m, "wavelength l, m")->required();
        c->add_option("--segments", s.segments_per_wavelength, "profile segments per wavelength")
            ->capture_default_str();
      },
      [](const solver::SinusoidSpec& s) { return solver::sinusoidal_wall(s); });
  {
    auto* c = cmd->add_subcommand("box", "Closed box of 12 triangles, normals inward");
    auto lo = std::make_shared<std::array<double, 3>>();
    auto hi = std::make_shared<std::array<double, 3>>();
    auto out = std::make_shared<std::string>();
    auto outward = std::make_shared<bool>(false);
    c->add_option("--lo", *lo, "lower corner, m")->delimiter(',')->required();
    c->add_option("--hi", *hi, "upper corner, m")->delimiter(',')->required();
    c->add_flag("--outward", *outward, "normals outward (an obstacle)");
    c->add_option("-o,--out", *out, "output .stl")->required();
    c->callback([=] {
      guarded(*out, [&] {
        write(solver::box_mesh(vec(*lo), vec(*hi),
                               *outward ? solver::BoxFacing::Outward : solver::BoxFacing::Inward),
              *out, "box");
      });
    });
  }
}

}  // namespace gs::cli
