// `granoscope analyze fabric | rose | chains | walls`: contact-based analyses of one snapshot
// (Kanatani fabric, polar contact histograms, strong-force network, wall loads). Methods and
// seed equations: docs/analysis.md. Outputs: HDF5 (root attribute format = granoscope-fabric /
// -rose / -chains / -walls, for `granoscope figures`), optionally CSV / VTP.

#include <CLI/CLI.hpp>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "analyze_common.hpp"
#include "commands.hpp"
#include "contact_rose.hpp"
#include "errors.hpp"
#include "fabric.hpp"
#include "fabric_report.hpp"
#include "field_output.hpp"
#include "force_chains.hpp"
#include "frame_series.hpp"
#include "love_weber_stress.hpp"
#include "rose_report.hpp"
#include "wall_stress.hpp"

namespace gs::cli {
namespace {

namespace ga = gs::analysis;

std::vector<double> flat(const Eigen::Matrix3d& m) {
  std::vector<double> v;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) v.push_back(m(i, j));
  return v;
}

std::vector<double> flat(const Eigen::Vector3d& x) {
  return {x.x(), x.y(), x.z()};
}

// ---- fabric --------------------------------------------------------------------------------

struct FabricArgs {
  FrameArgs in;
  FrameSeriesArgs series;
  SelectionArgs sel;
  std::string output, csv;
};

void run_fabric(const FabricArgs& a) {
  const Frame f = a.in.load();
  const double d50 = a.in.d50_of(f);
  const auto sel = a.sel.selection(a.in.input, f, d50);
  const ga::FabricReport rep = ga::fabric_report(a.in.input, f, sel);
  const ga::Fabric& fab = rep.contacts;
  const ga::OrientationFabric& o = rep.orientation;
  H5FieldFile h(a.output, "granoscope-fabric");
  h.attr("source", a.in.input);
  h.attr("frame", static_cast<long long>(a.in.frame_index()));
  h.attr("dim", static_cast<long long>(fab.dim));
  h.attr("particles", static_cast<long long>(fab.particles));
  h.attr("contacts", static_cast<long long>(fab.contacts));
  h.attr("omega", fab.omega);
  h.attr("D_norm", fab.D_norm);
  h.write("/M", flat(fab.M), {3, 3});
  h.write("/D", flat(fab.D), {3, 3});
  h.write("/D_principal", flat(fab.D_principal));
  h.write("/D_directions", flat(fab.D_directions), {3, 3});
  h.write("/view_axes", flat(rep.view_axes), {3, 3});
  h.group("/orientation");
  h.attr("bodies", static_cast<long long>(o.bodies), "/orientation");
  h.attr("D_norm", o.D_norm, "/orientation");
  h.attr("source", ga::orientation_source_name(o.source), "/orientation");
  h.write("/orientation/Phi", flat(o.Phi), {3, 3});
  h.write("/orientation/D", flat(o.D), {3, 3});
  h.write("/orientation/axis", o.axis);
  h.write("/orientation/centroid", o.centroid);
  h.commit();
  if (!a.csv.empty()) {
    write_csv_table(a.csv, {{"particles", 1, {static_cast<double>(fab.particles)}},
                            {"contacts", 1, {static_cast<double>(fab.contacts)}},
                            {"omega", 1, {fab.omega}},
                            {"D_norm", 1, {fab.D_norm}},
                            {"M", 9, flat(fab.M)},
                            {"D", 9, flat(fab.D)},
                            {"orientation_bodies", 1, {static_cast<double>(o.bodies)}},
                            {"orientation_D_norm", 1, {o.D_norm}}});
  }
  std::cout << std::setprecision(4) << "fabric: " << fab.particles << " particles, " << fab.contacts
            << " contacts, coordination omega = " << fab.omega << ", |D| = " << fab.D_norm
            << ", D principal " << fab.D_principal.transpose();
  if (o.source != ga::OrientationSource::None)
    std::cout << "; " << o.bodies << " clumps (orientation from the "
              << ga::orientation_source_name(o.source) << "), orientation |D| = " << o.D_norm;
  std::cout << "\n";
}

// ---- rose ----------------------------------------------------------------------------------

struct RoseArgs {
  FrameArgs in;
  FrameSeriesArgs series;
  SelectionArgs sel;
  std::string output, csv;
  ga::RoseSpec spec;
};

void run_rose(const RoseArgs& a) {
  ga::check_rose_spec(a.in.input, a.spec);  // before reading the frame
  const Frame f = a.in.load();
  const double d50 = a.in.d50_of(f);
  const auto sel = a.sel.selection(a.in.input, f, d50);
  const ga::RoseReport rep = ga::rose_report(a.in.input, f, sel, a.spec);
  const ga::Rose& r2 = rep.rose2d;
  const Eigen::Matrix3d& axes = rep.axes;
  H5FieldFile h(a.output, "granoscope-rose");
  h.attr("source", a.in.input);
  h.attr("frame", static_cast<long long>(a.in.frame_index()));
  h.attr("walls", static_cast<long long>(a.spec.walls ? 1 : 0));
  h.group("/rose2d");
  h.attr("bin_deg", a.spec.bin_deg, "/rose2d");
  h.attr("contacts", static_cast<long long>(r2.contacts), "/rose2d");
  h.attr("skipped", static_cast<long long>(r2.skipped), "/rose2d");
  h.write("/rose2d/axes", flat(axes), {3, 3});
  h.write("/rose2d/angle_deg", r2.angle_deg);
  h.write("/rose2d/count", r2.count);
  h.write("/rose2d/density", r2.density);
  h.write("/rose2d/mean_fn", r2.mean_fn);
  h.write("/rose2d/mean_fs", r2.mean_fs);
  if (rep.rose3d) {
    const ga::Rose& r3 = *rep.rose3d;
    h.group("/rose3d");
    h.attr("n_theta", static_cast<long long>(r3.n_theta), "/rose3d");
    h.attr("n_phi", static_cast<long long>(r3.n_phi), "/rose3d");
    h.attr("solid_angle", r3.bin_size, "/rose3d");
    h.write("/rose3d/direction", r3.direction);
    h.write("/rose3d/count", r3.count);
    h.write("/rose3d/density", r3.density);
    h.write("/rose3d/mean_fn", r3.mean_fn);
    h.write("/rose3d/mean_fs", r3.mean_fs);
  }
  h.commit();
  if (!a.csv.empty()) {
    write_csv_table(a.csv, {{"angle_deg", 1, r2.angle_deg},
                            {"count", 1, r2.count},
                            {"density", 1, r2.density},
                            {"mean_fn", 1, r2.mean_fn},
                            {"mean_fs", 1, r2.mean_fs}});
  }
  std::cout << "rose: " << r2.contacts << " contacts in " << r2.count.size() << " bins of "
            << a.spec.bin_deg << " deg (" << r2.skipped << " normal to the plane skipped)"
            << (a.spec.three_d ? ", 3D equal-area histogram" : "") << "\n";
}

// ---- chains --------------------------------------------------------------------------------

struct ChainArgs {
  FrameArgs in;
  FrameSeriesArgs series;
  SelectionArgs sel;
  std::string output, vtp;
  double threshold = -1.0, mean_factor = 1.0;
  bool walls = false;
};

void run_chains(const ChainArgs& a) {
  ga::ChainOptions o;
  o.threshold_n = a.threshold;
  o.mean_factor = a.mean_factor;
  o.walls = a.walls;
  ga::check_chain_options(a.in.input, o);  // before reading the frame
  const Frame f = a.in.load();
  const double d50 = a.in.d50_of(f);
  const auto sel = a.sel.selection(a.in.input, f, d50);
  const auto fc = ga::force_chains_in(a.in.input, f, sel, o);
  H5FieldFile h(a.output, "granoscope-chains");
  h.attr("source", a.in.input);
  h.attr("frame", static_cast<long long>(a.in.frame_index()));
  h.attr("mean_fn", fc.mean_fn);
  h.attr("max_fn", fc.max_fn);
  h.attr("threshold", fc.threshold);
  h.attr("strong", static_cast<long long>(fc.strong_count));
  h.attr("chains", static_cast<long long>(fc.chains));
  h.attr("largest_chain", static_cast<long long>(fc.largest_chain));
  h.attr("d50", d50);
  h.write("/view_axes", flat(view_axes(f, sel.slab)), {3, 3});
  h.group("/segments");
  h.write("/segments/a", fc.a);
  h.write("/segments/b", fc.b);
  h.write("/segments/fn", fc.fn);
  h.write("/segments/fs", fc.fs);
  h.write("/segments/strong", fc.strong);
  h.write("/segments/chain", fc.chain);
  h.commit();
  if (!a.vtp.empty()) {  // the strong network, widths in proportion to |Fn|
    std::vector<Eigen::Vector3d> pts;
    std::vector<std::vector<std::int64_t>> lines;
    std::vector<double> fn, fs, width, chain;
    for (std::size_t s = 0; s < fc.fn.size(); ++s) {
      if (!fc.strong[s]) continue;
      lines.push_back(
          {static_cast<std::int64_t>(pts.size()), static_cast<std::int64_t>(pts.size() + 1)});
      pts.push_back(fc.a[s]);
      pts.push_back(fc.b[s]);
      fn.push_back(fc.fn[s]);
      fs.push_back(fc.fs[s]);
      width.push_back(fc.max_fn > 0 ? fc.fn[s] / fc.max_fn : 0.0);
      chain.push_back(fc.chain[s]);
    }
    write_vtp_polylines(a.vtp, pts, lines, {},
                        {{"normal_force", 1, fn},
                         {"shear_force", 1, fs},
                         {"width", 1, width},
                         {"chain", 1, chain}});
  }
  std::cout << std::setprecision(4) << "chains: " << fc.fn.size() << " contacts, mean |Fn| "
            << fc.mean_fn << " N, threshold " << fc.threshold << " N, " << fc.strong_count
            << " strong in " << fc.chains << " chains (largest " << fc.largest_chain
            << " particles)\n";
}

// ---- walls ---------------------------------------------------------------------------------

struct WallArgs {
  FrameArgs in;
  FrameSeriesArgs series;
  std::string output, csv;
  std::vector<double> up{0.0, 0.0, 1.0};
  std::optional<double> bin, bin_d50, width;
  double gravity = 9.81, particle_density = 2650.0;
};

void run_walls(const WallArgs& a) {
  const Frame f = a.in.load();
  const double d50 = a.in.d50_of(f);
  ga::WallSpec spec;
  spec.up = Eigen::Vector3d(a.up[0], a.up[1], a.up[2]);
  spec.bin = a.bin;
  spec.bin_d50 = a.bin_d50;
  spec.width = a.width;
  spec.gravity = a.gravity;
  spec.particle_density = a.particle_density;
  const ga::WallReport rep = ga::wall_report(a.in.input, f, d50, spec);
  const ga::WallOptions& o = rep.options;
  const ga::WallLoads& w = rep.loads;
  H5FieldFile h(a.output, "granoscope-walls");
  h.attr("source", a.in.input);
  h.attr("frame", static_cast<long long>(a.in.frame_index()));
  h.attr("d50", d50);
  h.attr("bin", o.bin);
  for (const auto& [n, v] :
       std::vector<std::pair<const char*, double>>{{"P", w.P},
                                                   {"T", w.T},
                                                   {"N", w.N},
                                                   {"G", w.G},
                                                   {"phi_w_deg", w.phi_deg},
                                                   {"P_over_G", w.P / w.G},
                                                   {"T_over_G", w.T / w.G},
                                                   {"N_over_G", w.N / w.G},
                                                   {"balance", (w.T + w.P) / w.G}})
    h.attr(n, v);
  h.write("/up", flat(o.up.normalized()));
  std::vector<double> cid, cpos, csn, ctau, ccount;
  h.group("/walls");
  std::cout << std::setprecision(5);
  for (std::size_t k = 0; k < w.walls.size(); ++k) {
    const auto& l = w.walls[k];
    const std::string g = "/walls/" + std::to_string(k);
    h.group(g);
    h.attr("id", static_cast<long long>(l.id), g);
    h.attr("role", l.role, g);
    h.attr("inferred", static_cast<long long>(l.inferred ? 1 : 0), g);
    h.attr("contacts", static_cast<long long>(l.contacts), g);
    h.attr("N", l.N, g);
    h.attr("T", l.T, g);
    h.attr("phi_w_deg", l.phi_deg, g);
    h.attr("width", l.width, g);
    h.write(g + "/force", flat(l.force));
    h.write(g + "/recorded_force", flat(l.recorded));
    h.write(g + "/normal", flat(l.normal));
    h.write(g + "/axis", flat(l.axis));
    h.write(g + "/position", l.position);
    h.write(g + "/sigma_n", l.sigma_n);
    h.write(g + "/tau", l.tau);
    h.write(g + "/count", l.count);
    for (std::size_t b = 0; b < l.position.size(); ++b) {
      cid.push_back(static_cast<double>(l.id));
      cpos.push_back(l.position[b]);
      csn.push_back(l.sigma_n[b]);
      ctau.push_back(l.tau[b]);
      ccount.push_back(l.count[b]);
    }
    std::cout << "wall " << l.id << " (" << l.role << (l.inferred ? ", inferred" : "")
              << "): " << l.contacts << " contacts, force " << l.force.transpose() << " N, N "
              << l.N << " N, T " << l.T << " N, phi_w " << l.phi_deg << " deg\n";
  }
  h.commit();
  if (!a.csv.empty()) {
    write_csv_table(a.csv, {{"wall_id", 1, cid},
                            {"position", 1, cpos},
                            {"sigma_n", 1, csn},
                            {"tau", 1, ctau},
                            {"contacts", 1, ccount}});
  }
  std::cout << "walls: G " << w.G << " N, P/G " << w.P / w.G << ", T/G " << w.T / w.G << ", N/G "
            << w.N / w.G << ", phi_w " << w.phi_deg << " deg, (T + P)/G " << (w.T + w.P) / w.G
            << "\n";
}

}  // namespace

void register_analyze_contacts(CLI::App& app) {
  auto& analyze = analyze_command(app);
  {
    auto a = std::make_shared<FabricArgs>();
    auto* s = analyze.add_subcommand(
        "fabric",
        "Contact-normal fabric M_ij, coordination omega, Kanatani anisotropy D_ij (seed 003 "
        "eq 18-21); clump orientation fabric when clumps are present");
    a->in.add_to(*s, false);
    a->sel.add_to(*s);
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-fabric)")->required();
    s->add_option("--csv", a->csv, "also write one CSV row");
    add_frame_series(*s, a, "fabric", &run_fabric);
  }
  {
    auto a = std::make_shared<RoseArgs>();
    auto* s = analyze.add_subcommand(
        "rose",
        "Polar histograms of contact normals and mean normal / tangential force per direction "
        "(2D in a plane, 3D on equal-area bins)");
    a->in.add_to(*s, false);
    a->sel.add_to(*s);
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-rose)")->required();
    s->add_option("--bin-deg", a->spec.bin_deg, "2D bin size in deg (default 10)");
    s->add_option("--plane-normal", a->spec.plane_normal,
                  "plane of the 2D rose: normal x y z (default: the front view x-z, or the slab)")
        ->expected(3);
    s->add_option("--plane-axis", a->spec.plane_axis, "direction of angle 0 in the plane")
        ->expected(3);
    s->add_flag("--3d", a->spec.three_d, "also the 3D histogram on equal-area bins");
    s->add_option("--bins3d", a->spec.bins3d, "3D bins: bands in cos(theta) and longitudes (18 36)")
        ->expected(2);
    s->add_flag("--walls", a->spec.walls, "include particle-wall contacts");
    s->add_option("--csv", a->csv, "also write the 2D rose as CSV");
    add_frame_series(*s, a, "rose", &run_rose);
  }
  {
    auto a = std::make_shared<ChainArgs>();
    auto* s = analyze.add_subcommand(
        "chains",
        "Strong-force network: contacts with |Fn| above the mean (or a threshold), chains of "
        "connected strong contacts; VTP for ParaView");
    a->in.add_to(*s, false);
    a->sel.add_to(*s);
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-chains)")->required();
    s->add_option("--threshold", a->threshold, "strong above this |Fn| in N");
    s->add_option("--mean-factor", a->mean_factor, "strong above factor x mean |Fn| (default 1)");
    s->add_flag("--walls", a->walls, "include particle-wall contacts");
    s->add_option("--vtp", a->vtp, "also write the strong network as VTP polylines");
    add_frame_series(*s, a, "chains", &run_chains);
  }
  {
    auto a = std::make_shared<WallArgs>();
    auto* s = analyze.add_subcommand(
        "walls",
        "Wall stresses along each wall (sigma_n, tau) and resultants P, T, N, G, phi_w = "
        "atan(T/N) (seed 004 §5.3.1) from particle-wall contacts");
    a->in.add_to(*s, false);
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-walls)")->required();
    s->add_option("--up", a->up, "vertical direction x y z (default 0 0 1)")->expected(3);
    s->add_option("--bin", a->bin, "bin along the wall in m");
    s->add_option("--bin-d50", a->bin_d50, "bin along the wall in d50 (default 5)");
    s->add_option("--width", a->width,
                  "wall width across the bins in m (default: extent of the particles)");
    s->add_option("--gravity", a->gravity, "m/s^2 for the weight G (default 9.81)");
    s->add_option("--particle-density", a->particle_density,
                  "kg/m^3 for particles of unknown mass (default 2650)");
    s->add_option("--csv", a->csv, "also write the distributions as CSV");
    add_frame_series(*s, a, "walls", &run_walls);
  }
}

}  // namespace gs::cli
