// Builds a scene's specimen, walls and loading programmes (scene_file.hpp: scene_programmes).
#include <algorithm>
#include <cmath>
#include <random>

#include "cuboid_walls.hpp"
#include "errors.hpp"
#include "scene_file.hpp"

namespace gs::solver {

double FixedSteps::progress(const Simulation& sim) const {
  const auto span = std::max<std::int64_t>(1, relative_ ? steps_ : steps_ - first_);
  return std::clamp(static_cast<double>(sim.step_count() - first_) / static_cast<double>(span), 0.0,
                    1.0);
}

std::string FixedSteps::save_state() const {
  ProgrammeState st;
  st.set("first", first_);
  return st.text();
}

void FixedSteps::load_state(const std::string& state) {
  first_ = ProgrammeState(state).integer("first");
}

namespace {

double max_diameter(const std::vector<Particle>& p) {
  double d = 0;
  for (const auto& q : p) d = std::max(d, 2 * q.radius);
  return d;
}

/// Seeded specimen in the box [0, cloud]: the number of spheres is set by the target box and
/// void ratio, the cloud is the loose box they are placed in.
/// `reach`: the spheres are placed as if `reach` times larger (then given their own size back),
/// so that the clumps replacing them, which reach that far from their centres, do not overlap.
std::vector<Particle> generate(const Scene& s, const Eigen::Vector3d& cloud,
                               const Eigen::Vector3d& lo = Eigen::Vector3d::Zero(),
                               double reach = 1.0) {
  const SpecimenSpec& sp = *s.specimen;
  std::mt19937_64 rng(sp.seed);
  const double solid = sp.size_m.prod() / (1 + sp.void_ratio);
  try {
    auto d = draw_diameters(sp.sizes, solid, rng);
    for (auto& x : d) x *= reach;
    auto ps = random_sequential_packing(d, lo, lo + cloud, rng);
    for (auto& p : ps) p.radius /= reach;
    return ps;
  } catch (const std::invalid_argument& e) {
    throw InputError(s.file.string(), std::string("[specimen]: ") + e.what());
  }
}

/// How far the clump that replaces a sphere reaches from its centre, in the sphere's radii (1
/// without [clumps] replace): the clump of a sphere's volume reaches further than the sphere, so
/// the spheres are placed as if that much larger (their cloud as much larger), and the clumps
/// start apart. (Without it a cloud at solid fraction 0.3 of the four-sphere clumps starts with
/// members of neighbouring clumps overlapping by more than a radius.)
double clump_reach(const Scene& s) {
  if (!s.clump_replace) return 1.0;
  const auto& shape = s.clump_replace->shape;
  const MassProperties m = clump_mass_properties(shape, 1.0, ClumpMassModel::Union);
  double enclosing = 0;
  for (const auto& c : shape)
    enclosing = std::max(enclosing, (c.offset - m.centroid).norm() + c.radius);
  return std::max(1.0, std::cbrt(4.0 / 3.0 * M_PI / m.volume) * enclosing);
}

/// Union volume over the members' summed volume of the scene's clumps (1 without clumps): what
/// a void ratio counts of a member sphere (the members of a clump overlap).
double clump_solid_factor(const Scene& s) {
  if (!s.clump_replace || s.clumps.empty()) return 1.0;
  const ClumpShape shape = clump_shape(s.clump_replace->shape);
  double sum = 0;
  for (const auto& m : s.clump_replace->shape) sum += 4.0 / 3.0 * M_PI * std::pow(m.radius, 3);
  return shape.volume / sum;
}

}  // namespace

std::vector<std::unique_ptr<LoadingProgramme>> scene_programmes(Scene& s) {
  std::vector<std::unique_ptr<LoadingProgramme>> out;
  if (s.test.empty()) {
    if (s.fill)
      out.push_back(std::make_unique<LayeredFilling>(*s.fill, s.fill_first, s.fill_layers,
                                                     s.output.every, s.open_after_fill));
    out.push_back(std::make_unique<FixedSteps>(s.steps, s.output.every, s.fill.has_value()));
    return out;
  }
  if (s.test == "silo") {
    // Seed 004 §5.2: the silo's walls, the filling in layers, then the flow.
    const FillSpec& f = *s.fill;
    const double d50 = s.silo.d50_m > 0 ? s.silo.d50_m : mass_quantile(f.sizes, 0.5);
    SiloWalls idx;
    try {
      s.walls = silo_walls(s.silo, d50, f.sizes.dmax_m, idx);
      // For `analyze silo` (the run's metadata): the d50 the roughness and the report's lengths
      // are in units of (the seed's is a median by number, not the grading's by volume).
      s.parameters.emplace_back("scene.d50_m", value_str(d50));
      // What falls through the outlet (or, while filling, bounces over a wall) is removed two
      // grains below the side walls' lower end.
      const double big = 10 * (s.silo.width_m + s.silo.height_m + s.silo.depth_m);
      s.outlet = std::make_pair(Eigen::Vector3d(-big, -big, idx.floor_z_m - 2 * f.sizes.dmax_m),
                                Eigen::Vector3d(big, big, big));
      out.push_back(
          std::make_unique<LayeredFilling>(f, s.fill_first, s.fill_layers, s.output.every));
      out.push_back(std::make_unique<SiloFlow>(s.silo, idx));
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file.string(), e.what());
    }
    return out;
  }
  if (s.test == "stress_rotation") {
    // Seed 003 §2.4: the spheres generated in a box of the specimen's footprint whose floor is
    // half the bed's height below the polyhedron's centre (the origin), replaced by clumps; the
    // box's six planes (frictional as the grains, §2.4) and the polyhedron's walls, switched off
    // until the carving. Both follow the friction the test sets.
    const SpecimenSpec& sp = *s.specimen;
    const StressRotationSpec& x = s.stress_rotation;
    const double half_w = 0.5 * std::min(sp.size_m.x(), sp.size_m.y());
    try {
      const TangentialPolyhedron P = tangential_polyhedron(x.sides, x.radius_m);
      double footprint = 0;  // the polyhedron's largest horizontal radius
      for (const auto& v : P.vertices) footprint = std::max(footprint, v.head<2>().norm());
      if (!(half_w > footprint + sp.sizes.dmax_m))
        throw InputError(s.file.string(),
                         "specimen.size_m: the box's footprint does not hold the polyhedron (its "
                         "half-width must exceed " +
                             value_str(footprint + sp.sizes.dmax_m) + " m)",
                         value_str(2 * half_w));
      if (!(0.5 * sp.size_m.z() > x.radius_m + sp.sizes.dmax_m))
        throw InputError(s.file.string(),
                         "specimen.size_m: the bed's height does not cover the polyhedron (its "
                         "half must exceed " +
                             value_str(x.radius_m + sp.sizes.dmax_m) + " m)",
                         value_str(sp.size_m.z()));
      const double reach = clump_reach(s);
      const double cloud_h =
          sp.size_m.z() / (1 + sp.void_ratio) / sp.cloud_solid_fraction * reach * reach * reach;
      const Eigen::Vector3d lo(-0.5 * sp.size_m.x(), -0.5 * sp.size_m.y(), -0.5 * sp.size_m.z());
      s.particles = generate(s, {sp.size_m.x(), sp.size_m.y(), cloud_h}, lo, reach);
      replace_spheres_by_clumps(s);
      s.walls = cuboid_planes(lo, lo + Eigen::Vector3d(sp.size_m.x(), sp.size_m.y(), cloud_h), -1);
      // The walls start outward by the largest member radius (StressRotation: the carving
      // keeps members whose centres are inside), off until the carving.
      double rmax = 0;
      for (const auto& q : s.particles) rmax = std::max(rmax, q.radius);
      auto poly = polyhedron_walls(P);
      for (auto& w : poly) {
        w.center *= 1.0 + rmax / x.radius_m;
        w.active = false;
      }
      s.stress_rotation.box_first = 0;
      s.stress_rotation.poly_first = s.walls.size();
      s.walls.insert(s.walls.end(), poly.begin(), poly.end());
      out.push_back(
          std::make_unique<StressRotation>(s.stress_rotation, s.config.material.friction_deg));
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file.string(), std::string("[stress_rotation]: ") + e.what());
    }
    return out;
  }
  const double test_friction = s.config.material.friction_deg;
  std::optional<SpecimenGauge> gauge;
  std::unique_ptr<LoadingProgramme> test;
  if (s.test == "biaxial_periodic") {
    // Seed 002 §4: disks in a square doubly periodic cell, of the thickness asked for.
    const SpecimenSpec& sp = *s.specimen;
    // The cell's z is not searched periodically: it must be thicker than 2 r_max + skin (the
    // skin's default is half the smallest radius).
    const double skin = s.config.skin > 0 ? s.config.skin : 0.25 * sp.sizes.dmin_m;
    if (!(sp.thickness_m > sp.sizes.dmax_m + skin))
      throw InputError(s.file.string(),
                       "specimen.thickness_m: not thicker than dmax + skin (" +
                           value_str(sp.sizes.dmax_m + skin) + " m)",
                       value_str(sp.thickness_m));
    std::mt19937_64 rng(sp.seed);
    try {
      const auto d = draw_diameter_count(sp.sizes, static_cast<std::size_t>(sp.count), rng);
      double area = 0;
      for (const double x : d) area += 0.25 * M_PI * x * x;
      const double side = std::sqrt(area / sp.cloud_solid_fraction);
      s.particles = random_disk_packing_periodic(d, side, side, 0.5 * sp.thickness_m, rng);
      auto& c = s.cell.emplace();
      c.hsize = Eigen::Vector3d(side, side, sp.thickness_m).asDiagonal();
      c.planar = true;
      c.disks = sp.disks;
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file.string(), std::string("[specimen]: ") + e.what());
    }
    try {
      gauge = cell_gauge(2, s.preparation ? s.preparation->max_cell_rate_1_s : 1.0);
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file.string(), std::string("[preparation]: ") + e.what());
    }
    if (s.biaxial_periodic.d50_m <= 0 && sp.sizes.d50_m > 0)
      s.biaxial_periodic.d50_m = sp.sizes.d50_m;
    try {
      test = std::make_unique<PeriodicBiaxial>(s.biaxial_periodic);
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file.string(), std::string("[biaxial_periodic]: ") + e.what());
    }
  } else if (s.test == "triaxial" || s.test == "plane_strain") {
    Eigen::Vector3d lo, hi;
    if (s.specimen) {
      const double phi = 1 / (1 + s.specimen->void_ratio);
      const double reach = clump_reach(s);
      const double scale = std::cbrt(phi / s.specimen->cloud_solid_fraction) * reach;
      lo.setZero();
      hi = s.specimen->size_m * scale;
      s.particles = generate(s, hi, lo, reach);
      replace_spheres_by_clumps(s);
    } else {
      Frame f;
      f.particles = s.particles;
      std::tie(lo, hi) = particle_bounds(f);
    }
    s.walls = cuboid_planes(lo, hi, s.wall_friction_deg);
    if (s.test == "plane_strain") {
      const auto clamps = membrane_clamps();
      s.walls.insert(s.walls.end(), clamps.begin(), clamps.end());
    }
    gauge = cuboid_gauge();
    s.triaxial.core_inset_m = s.plane_strain.core_inset_m = max_diameter(s.particles);
    // A clump member counts its share of its clump's union volume in every void ratio.
    gauge->clump_solid_factor = s.triaxial.clump_solid_factor = s.plane_strain.clump_solid_factor =
        clump_solid_factor(s);
    if (s.test == "triaxial") {
      test = std::make_unique<TriaxialCompression>(s.triaxial);
    } else {
      test = std::make_unique<PlaneStrainCompression>(s.plane_strain);
    }
  } else if (s.test == "interface_shear") {
    // Seed 004 §4.3–4.4: the specimen's cloud is made above the surface's crests.
    const auto& sp = *s.specimen;
    InterfaceShearGeometry& g = s.interface_geometry;
    InterfaceSurfaceSpec& f = s.interface_surface;
    g.length_m = sp.size_m.x();
    g.width_m = sp.size_m.y();
    g.height_m = sp.size_m.z();
    g.travel_m = s.interface_shear.max_displacement_m;
    const double dmax = sp.sizes.dmax_m;
    if (f.kind == "saw_tooth" && !(f.d50_m > 0)) f.d50_m = mass_quantile(sp.sizes, 0.5);
    g.wall_thickness_m = std::max(2 * dmax, 0.05 * g.length_m);
    InterfaceShearWalls idx;
    try {
      // The surface first: the cloud is placed above its crests, the box around the cloud.
      s.walls = interface_surface_walls(f, g, dmax, idx);
      const double reach = clump_reach(s);
      const double cloud_h =
          g.height_m * (1 / (1 + sp.void_ratio)) / sp.cloud_solid_fraction * reach * reach * reach;
      s.particles =
          generate(s, {g.length_m, g.width_m, cloud_h}, Eigen::Vector3d(0, 0, g.crest_z_m), reach);
      replace_spheres_by_clumps(s);
      g.clump_solid_factor = clump_solid_factor(s);
      g.platen_z_m = g.crest_z_m + cloud_h;
      g.frame_top_m = g.platen_z_m + g.wall_thickness_m;
      append_interface_box_walls(g, dmax, s.walls, idx);
      // Grains pushed off the surface's ends fall away (removed there).
      const double big = 1e3 * (g.length_m + g.height_m + g.travel_m);
      s.outlet = std::make_pair(Eigen::Vector3d(g.surface_x0_m, -big, -big),
                                Eigen::Vector3d(g.surface_x1_m, big, big));
      gauge = interface_shear_gauge(g, idx);
      // For `analyze interface` (the run's metadata): where the surface is.
      s.parameters.emplace_back("interface_shear.surface_mean_z_m", value_str(g.mean_z_m));
      s.parameters.emplace_back("interface_shear.surface_crest_z_m", value_str(g.crest_z_m));
      if (f.kind == "saw_tooth") s.parameters.emplace_back("scene.d50_m", value_str(f.d50_m));
      test = std::make_unique<InterfaceShear>(s.interface_shear, g, idx);
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file.string(), e.what());
    }
  } else {  // direct shear
    ShearBoxGeometry& g = s.shear_box;
    double top;
    if (s.specimen) {
      const auto& sp = *s.specimen;
      g.length_m = sp.size_m.x();
      g.width_m = sp.size_m.y();
      g.height_m = sp.size_m.z();
      const double reach = clump_reach(s);
      top =
          g.height_m * (1 / (1 + sp.void_ratio)) / sp.cloud_solid_fraction * reach * reach * reach;
      s.particles = generate(s, {g.length_m, g.width_m, top}, Eigen::Vector3d::Zero(), reach);
      replace_spheres_by_clumps(s);
    } else {
      Frame f;
      f.particles = s.particles;
      const auto [lo, hi] = particle_bounds(f);
      for (auto& p : s.particles) p.position -= lo;
      g.length_m = hi.x() - lo.x();
      g.width_m = hi.y() - lo.y();
      g.height_m = hi.z() - lo.z();
      top = g.height_m;
    }
    const double dmax = max_diameter(s.particles);
    if (g.gap_m < 0) g.gap_m = dmax;
    g.wall_thickness_m = std::max(2 * dmax, 0.05 * g.length_m);
    g.platen_z_m = top;
    g.frame_top_m = top + g.wall_thickness_m;
    ShearBoxWalls idx;
    try {
      s.walls = shear_box_walls(g, idx);
      gauge = shear_box_gauge(g, idx);
      gauge->clump_solid_factor = s.direct_shear.clump_solid_factor = clump_solid_factor(s);
      test = std::make_unique<DirectShear>(s.direct_shear, g, idx);
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file.string(), std::string("[direct_shear]: ") + e.what());
    }
  }
  const double inset = max_diameter(s.particles);  // the loose layer along a wall
  if (s.preparation) {
    if (s.preparation->core_inset_m < 0) s.preparation->core_inset_m = inset;
    try {
      out.push_back(std::make_unique<SpecimenPreparation>(*s.preparation, *gauge, test_friction));
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file.string(), std::string("[preparation]: ") + e.what());
    }
  }
  out.push_back(std::move(test));
  return out;
}

}  // namespace gs::solver
