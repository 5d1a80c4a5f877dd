#include "layered_filling.hpp"

#include <tuple>

#include <algorithm>
#include <cmath>
#include <random>
#include <unordered_map>

#include "contact_geometry.hpp"

namespace gs::solver {

FillParticles fill_particles(const FillSpec& spec, std::int64_t first_id) {
  if (spec.layers < 1) throw std::invalid_argument("fill needs at least one layer");
  if (spec.count < spec.layers) throw std::invalid_argument("fill needs a particle per layer");
  std::mt19937_64 rng(spec.seed);
  const Eigen::Vector3d mid = 0.5 * (spec.region_lo_m + spec.region_hi_m);
  FillParticles out;
  const std::int64_t per = spec.count / spec.layers, extra = spec.count % spec.layers;
  std::uint32_t next = 0;
  for (int l = 0; l < spec.layers; ++l) {
    const std::int64_t n = per + (l < extra ? 1 : 0);
    std::vector<double> d(static_cast<std::size_t>(n));
    for (auto& x : d) x = draw_diameter(spec.sizes, rng);
    std::sort(d.begin(), d.end(), std::greater<>());
    auto& layer = out.layers.emplace_back();
    for (const double di : d) {
      Particle p;
      p.id = first_id + next;
      p.radius = 0.5 * di;
      p.position = mid;
      out.particles.push_back(p);
      layer.push_back(next++);
    }
  }
  return out;
}

std::vector<Eigen::Vector3d> place_in_region(const Simulation& sim,
                                             const std::vector<double>& radii,
                                             const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                             std::uint64_t seed, int max_attempts, bool lattice) {
  std::vector<Eigen::Vector3d> out;
  if (radii.empty()) return out;
  const ParticleState& p = sim.particles();
  double rmax = *std::max_element(radii.begin(), radii.end());
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.removed[i] == 0) rmax = std::max(rmax, p.radius[i]);
  // Hash grid (cell 2·rmax) of the spheres that may reach into the region, then of those placed.
  const double cell = 2 * rmax;
  auto key = [&](const Eigen::Vector3d& x, int dx, int dy, int dz) {
    const auto c = [&](int k, int d) {
      return static_cast<std::int64_t>(std::floor((x[k] - lo[k]) / cell)) + d;
    };
    return (c(2, dz) * 1000003 + c(1, dy)) * 1000003 + c(0, dx);
  };
  std::vector<Eigen::Vector3d> centre;
  std::vector<double> radius;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> grid;
  auto add = [&](const Eigen::Vector3d& x, double r) {
    grid[key(x, 0, 0, 0)].push_back(static_cast<std::uint32_t>(centre.size()));
    centre.push_back(x);
    radius.push_back(r);
  };
  const Eigen::Vector3d reach = Eigen::Vector3d::Constant(2 * rmax);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.removed[i] == 0 && (p.pos[i].array() >= (lo - reach).array()).all() &&
        (p.pos[i].array() <= (hi + reach).array()).all())
      add(p.pos[i], p.radius[i]);
  // The facets near the region (the other walls are few: all checked).
  struct Near {
    std::size_t wall, facet;
  };
  std::vector<Near> facets;
  std::vector<std::size_t> others;
  for (std::size_t w = 0; w < sim.walls().size(); ++w) {
    const WallState& ws = sim.walls()[w];
    if (!ws.active) continue;
    if (ws.spec.shape != WallShape::Facets) {
      others.push_back(w);
      continue;
    }
    for (std::size_t f = 0; f < ws.facets.size(); ++f) {
      Eigen::Vector3d a = Eigen::Vector3d::Constant(HUGE_VAL), b = -a;
      for (const auto& v : ws.facets[f].vertex) {
        const Eigen::Vector3d x = ws.pos + (ws.facets[f].offset + v).eigen();
        a = a.cwiseMin(x);
        b = b.cwiseMax(x);
      }
      if ((b.array() >= (lo - reach).array()).all() && (a.array() <= (hi + reach).array()).all())
        facets.push_back({w, f});
    }
  }
  auto clear_of_walls = [&](const Eigen::Vector3d& x, double r) {
    for (const std::size_t w : others) {
      const WallState& ws = sim.walls()[w];
      const double d = ws.spec.shape == WallShape::Box
                           ? box_distance(ws.pos, ws.spec.half_extents, x)
                           : (x - ws.pos).dot(ws.normal);
      if (d < r) return false;
    }
    for (const Near& n : facets) {
      const WallState& ws = sim.walls()[n.wall];
      ContactGeometry g;
      if (facet_sphere_geometry(ws.facets[n.facet], V3(ws.pos), V3(x), r, true, g) < r)
        return false;
    }
    return true;
  };
  std::mt19937_64 rng(seed);
  auto free_of_particles = [&](const Eigen::Vector3d& x, double r) {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = grid.find(key(x, dx, dy, dz));
          if (it == grid.end()) continue;
          for (const auto j : it->second) {
            const double s = r + radius[j];
            if ((centre[j] - x).squaredNorm() < s * s) return false;
          }
        }
    return true;
  };
  // Places a sphere at x if nothing is there (true: placed).
  auto try_place = [&](const Eigen::Vector3d& x, double r) {
    if (!free_of_particles(x, r) || !clear_of_walls(x, r)) return false;
    add(x, r);
    out.push_back(x);
    return true;
  };
  if (lattice) {
    // Sites of a simple cubic lattice, spacing a = 1.05 · 2 r_max, ordered from the bottom up
    // (along gravity; x then y within a level when gravity is along z).
    const double rl = *std::max_element(radii.begin(), radii.end());
    const double a = 1.05 * 2 * rl, jitter = 0.01 * 2 * rl;
    Eigen::Array3d count;  // sites per axis
    for (int k = 0; k < 3; ++k) {
      const double span = hi[k] - lo[k] - 2 * rl;
      if (span < 0) return out;
      count[k] = std::floor(span / a) + 1;
    }
    const Eigen::Vector3d g = sim.config().gravity;
    int up = 2;  // the axis most along gravity is the slowest index, walked against gravity
    for (int k = 0; k < 3; ++k)
      if (std::abs(g[k]) > std::abs(g[up])) up = k;
    const int u = (up + 1) % 3, v = (up + 2) % 3;
    const auto levels = static_cast<std::int64_t>(count[up]),
               nu = static_cast<std::int64_t>(count[u]), nv = static_cast<std::int64_t>(count[v]);
    const std::int64_t sites = levels * nu * nv;
    std::int64_t next = 0;
    for (const double r : radii) {
      bool placed = false;
      while (!placed && next < sites) {
        const std::int64_t s = next++;
        std::int64_t level = s / (nu * nv);
        if (g[up] > 0) level = levels - 1 - level;  // gravity along +axis: fill from the top
        const std::int64_t iv = (s / nu) % nv, iu = s % nu;
        Eigen::Vector3d x;
        x[up] = lo[up] + rl + static_cast<double>(level) * a;
        x[u] = lo[u] + rl + static_cast<double>(iu) * a;
        x[v] = lo[v] + rl + static_cast<double>(iv) * a;
        for (int k = 0; k < 3; ++k)
          x[k] = std::clamp(x[k] + jitter * (2 * uniform01(rng) - 1), lo[k] + r, hi[k] - r);
        placed = try_place(x, r);
      }
      if (!placed) break;
    }
    return out;
  }
  for (const double r : radii) {
    if (((hi - lo).array() < 2 * r).any()) return out;
    bool placed = false;
    for (int attempt = 0; attempt < max_attempts && !placed; ++attempt) {
      Eigen::Vector3d x;
      for (int k = 0; k < 3; ++k) x[k] = lo[k] + r + uniform01(rng) * (hi[k] - lo[k] - 2 * r);
      placed = try_place(x, r);
    }
    if (!placed) break;
  }
  return out;
}

LayeredFilling::LayeredFilling(FillSpec spec, std::uint32_t first_index,
                               std::vector<std::vector<std::uint32_t>> layers,
                               std::int64_t frame_every, std::vector<std::size_t> open_walls)
    : spec_(std::move(spec)),
      first_(first_index),
      layers_(std::move(layers)),
      open_walls_(std::move(open_walls)),
      frame_every_(std::max<std::int64_t>(1, frame_every)) {}

// (The sums in index order over the bodies, each term from its owner under a domain: the same
// bits on any number of processes, so every process inserts the next layer at the same step.)
namespace {
// The settling sums' terms: a free body's translational kinetic energy (in the scene).
double kinetic_term(const ParticleState& p, std::size_t i) {
  return p.removed[i] == 0 && p.clump[i] < 0 ? 0.5 * p.mass[i] * p.vel[i].squaredNorm() : 0.0;
}
double kinetic_term(const ClumpBody& c) {
  return 0.5 * c.mass * c.vel.squaredNorm();
}
}  // namespace

std::pair<double, double> LayeredFilling::energy_and_threshold(const Simulation& sim,
                                                               bool exact) const {
  const ParticleState& p = sim.particles();
  const auto& clumps = sim.clumps();
  const double g = sim.config().gravity.norm();
  const auto s = sim.owned_sums<2>(
      [&](std::size_t i, double* t) {
        t[0] = kinetic_term(p, i);
        t[1] = p.removed[i] == 0 ? p.mass[i] * g * 2 * p.radius[i] : 0.0;
      },
      [&](std::size_t k, double* t) {
        t[0] = kinetic_term(clumps[k]);
        t[1] = 0.0;
      },
      exact);
  return {s[0], spec_.kinetic_ratio * s[1]};
}

double LayeredFilling::settling_energy(const Simulation& sim) {
  const ParticleState& p = sim.particles();
  const auto& clumps = sim.clumps();
  return sim.owned_sums<1>([&](std::size_t i, double* t) { t[0] = kinetic_term(p, i); },
                           [&](std::size_t k, double* t) { t[0] = kinetic_term(clumps[k]); })[0];
}

double LayeredFilling::threshold(const Simulation& sim) const {
  return energy_and_threshold(sim).second;
}

void LayeredFilling::insert_layer(Simulation& sim) {
  sim.share_all_states();  // (under a domain: every process places the layer among them all)
  const auto& layer = layers_[static_cast<std::size_t>(inserted_)];
  std::vector<double> radii;
  for (const auto k : layer) radii.push_back(sim.particles().radius[first_ + k]);
  // One seed per layer: the placement depends only on the state (bit-exact resume).
  const auto x = place_in_region(sim, radii, spec_.region_lo_m, spec_.region_hi_m,
                                 spec_.seed + 0x9e3779b97f4a7c15ull * (inserted_ + 1),
                                 spec_.max_attempts, spec_.lattice);
  if (x.size() < layer.size())
    throw FillError("fill: layer " + std::to_string(inserted_ + 1) + " of " +
                    std::to_string(layers_.size()) + ": the region took " +
                    std::to_string(x.size()) + " of its " + std::to_string(layer.size()) +
                    " particles (enlarge the region, use more layers or fewer particles)");
  for (std::size_t k = 0; k < layer.size(); ++k) sim.insert_particle(first_ + layer[k], x[k]);
  ++inserted_;
  last_insert_step_ = sim.step_count();
  moved_ = false;
  below_ = 0;
}

void LayeredFilling::start(Simulation& sim) {
  std::vector<std::uint32_t> all;
  for (const auto& l : layers_)
    for (const auto k : l) all.push_back(first_ + k);
  sim.set_pending(all);
  inserted_ = 0;
  done_ = false;
  material_friction_deg_ = sim.config().material.friction_deg;
  if (spec_.friction_deg >= 0) sim.set_friction_deg(spec_.friction_deg);
  solver_damping_ = sim.config().damping;
  if (spec_.damping >= 0) sim.set_damping(spec_.damping);
  insert_layer(sim);
}

void LayeredFilling::control(Simulation& sim) {
  if (done_) return;
  const std::int64_t since = sim.step_count() - last_insert_step_;
  if (since < spec_.min_steps) return;
  // Under a domain the sums per process first (a few bytes; within round-off of the exact
  // ones, the same on every process): only a layer near its threshold needs the exact sums,
  // every term shared, for the decision one process makes. (Both are sums of the same positive
  // terms: they differ by less than N·ε relative, far below the margin.)
  auto [ek, threshold_J] = energy_and_threshold(sim, !sim.decomposed());
  if (sim.decomposed() && !(ek > threshold_J * (1 + 1e-6)))
    std::tie(ek, threshold_J) = energy_and_threshold(sim, true);
  // A layer placed at rest has next to no kinetic energy while it starts to fall: it has
  // settled only once it has moved (its energy went above the threshold) or has had the time
  // to fall through the region's height.
  const Eigen::Vector3d g = sim.config().gravity;
  const double fall_height = std::abs((spec_.region_hi_m - spec_.region_lo_m).dot(g.normalized()));
  const bool fallen = moved_ || static_cast<double>(since) * sim.config().dt >=
                                    std::sqrt(2 * fall_height / g.norm());
  if (ek >= threshold_J) moved_ = true;
  if (ek >= threshold_J || !fallen) {
    below_ = 0;
    if (since >= spec_.max_steps)
      throw FillError("fill: layer " + std::to_string(inserted_) + " did not settle within " +
                      std::to_string(spec_.max_steps) + " steps (translational kinetic energy " +
                      std::to_string(ek) + " J, threshold " + std::to_string(threshold_J) + " J)");
    return;
  }
  if (++below_ < spec_.hold_steps) return;  // (held below for hold_steps steps in a row)
  if (inserted_ < static_cast<int>(layers_.size())) {
    insert_layer(sim);
    return;
  }
  for (const std::size_t w : open_walls_) sim.set_wall_active(w, false);
  if (spec_.friction_deg >= 0) sim.set_friction_deg(material_friction_deg_);
  if (spec_.damping >= 0) sim.set_damping(solver_damping_);
  done_ = true;
}

double LayeredFilling::progress(const Simulation&) const {
  return static_cast<double>(inserted_) / static_cast<double>(layers_.size() + 1);
}

std::int64_t LayeredFilling::frame_index(const Simulation& sim) const {
  return sim.step_count() / frame_every_;
}

std::string LayeredFilling::summary(const Simulation& sim) const {
  std::size_t n = 0;
  for (const auto& l : layers_) n += l.size();
  return "filling: " + std::to_string(layers_.size()) + " layers, " + std::to_string(n) +
         " particles, settled at step " + std::to_string(sim.step_count()) +
         " (translational kinetic energy " + std::to_string(settling_energy(sim)) + " J)";
}

std::string LayeredFilling::save_state() const {
  ProgrammeState st;
  st.set("inserted", static_cast<std::int64_t>(inserted_));
  st.set("last_insert_step", last_insert_step_);
  st.set("done", static_cast<std::int64_t>(done_));
  st.set("material_friction_deg", material_friction_deg_);
  st.set("solver_damping", solver_damping_);
  st.set("moved", static_cast<std::int64_t>(moved_));
  st.set("below", below_);
  return st.text();
}

void LayeredFilling::load_state(const std::string& state) {
  const ProgrammeState st(state);
  inserted_ = static_cast<int>(st.integer("inserted"));
  last_insert_step_ = st.integer("last_insert_step");
  done_ = st.integer("done") != 0;
  material_friction_deg_ = st.has("material_friction_deg") ? st.number("material_friction_deg")
                                                           : -1.0;  // (older checkpoints)
  solver_damping_ = st.has("solver_damping") ? st.number("solver_damping") : 0.0;
  moved_ = st.has("moved") ? st.integer("moved") != 0 : true;
  below_ = st.has("below") ? st.integer("below") : 0;  // (older checkpoints: no hold)
}

}  // namespace gs::solver
