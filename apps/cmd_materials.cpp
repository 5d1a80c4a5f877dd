// `granoscope analyze materials RUN.h5`: per frame, each material's particle count, centre of
// mass and counts in the zones asked for (analysis/material_zones.hpp): the mixing and
// segregation monitor of the DEM8 benchmark's rotating drum (docs/dem8.md, Case 2), as a CSV
// table with one row per frame.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "frame_motion.hpp"
#include "hdf5_trajectory.hpp"
#include "material_zones.hpp"

namespace gs::cli {
namespace {

namespace ga = gs::analysis;

struct MaterialsArgs {
  std::string input, output;
  std::vector<std::string> zones;
  bool drum = false;
  long every = 1;
};

/// The material names a granoscope run recorded (metadata "material_names", comma-separated).
std::vector<std::string> recorded_names(const std::string& file) {
  std::vector<std::string> names;
  if (!is_hdf5_file(file)) return names;
  const TrajectoryReader reader(file);
  for (const auto& [key, v] : reader.metadata().parameters)
    if (key == "material_names") {
      std::stringstream in(v);
      std::string name;
      while (std::getline(in, name, ',')) names.push_back(name);
    }
  return names;
}

void run_materials(const MaterialsArgs& a) {
  const std::string& file = a.input;
  if (a.every < 1) throw InputError(file, "--every: must be at least 1", std::to_string(a.every));
  std::vector<ga::Zone> zones;
  if (a.drum) {
    const double inf = HUGE_VAL;
    zones.push_back({"x+z-", {0, -inf, -inf}, {inf, inf, 0}});
    zones.push_back({"x-z+", {-inf, -inf, 0}, {0, inf, inf}});
  }
  for (const auto& spec : a.zones) {
    try {
      zones.push_back(ga::parse_zone(spec));
    } catch (const std::invalid_argument& e) {
      throw InputError(file, std::string("--zone: ") + e.what(), spec);
    }
  }
  std::set<std::string> seen;
  for (const auto& z : zones)
    if (!seen.insert(z.name).second) throw InputError(file, "--zone: name used twice", z.name);
  const std::size_t frames = frame_count(file);
  std::vector<double> step, time;
  std::vector<std::vector<ga::MaterialStats>> rows;
  std::set<std::int32_t> materials;
  for (std::size_t i = 0; i < frames; i += static_cast<std::size_t>(a.every)) {
    const Frame f = read_frame(file, static_cast<long>(i));
    rows.push_back(ga::material_zone_stats(f.particles, zones));
    for (const auto& s : rows.back()) materials.insert(s.material);
    step.push_back(static_cast<double>(f.step));
    time.push_back(f.time);
  }
  const auto names = recorded_names(file);
  auto name_of = [&](std::int32_t m) {
    return m >= 0 && static_cast<std::size_t>(m) < names.size() ? names[static_cast<std::size_t>(m)]
                                                                : "material" + std::to_string(m);
  };
  std::vector<VtkArray> cols = {{"step", 1, step}, {"time_s", 1, time}};
  for (const std::int32_t m : materials) {
    const std::string n = name_of(m);
    std::vector<double> count, x, y, z;
    std::vector<std::vector<double>> in(zones.size());
    for (const auto& r : rows) {
      const ga::MaterialStats* s = nullptr;
      for (const auto& q : r)
        if (q.material == m) s = &q;
      const double nan = std::nan("");
      count.push_back(s ? static_cast<double>(s->count) : 0.0);
      x.push_back(s ? s->centre_m.x() : nan);
      y.push_back(s ? s->centre_m.y() : nan);
      z.push_back(s ? s->centre_m.z() : nan);
      for (std::size_t k = 0; k < zones.size(); ++k)
        in[k].push_back(s ? static_cast<double>(s->in_zone[k]) : 0.0);
    }
    cols.push_back({n + "_count", 1, count});
    cols.push_back({n + "_com_x_m", 1, x});
    cols.push_back({n + "_com_y_m", 1, y});
    cols.push_back({n + "_com_z_m", 1, z});
    for (std::size_t k = 0; k < zones.size(); ++k)
      cols.push_back({zones[k].name + "_" + n + "_count", 1, in[k]});
  }
  write_csv_table(a.output, cols);
  std::printf("materials: %zu frames of %s, %zu materials, %zu zones -> %s\n", rows.size(),
              file.c_str(), materials.size(), zones.size(), a.output.c_str());
}

}  // namespace

void register_analyze_materials(CLI::App& app) {
  auto& analyze = analyze_command(app);
  auto a = std::make_shared<MaterialsArgs>();
  auto* s = analyze.add_subcommand(
      "materials",
      "Per frame, each material's particle count, centre of mass and counts in zones (the DEM8 "
      "drum's mixing monitor, docs/dem8.md): a CSV row per frame");
  s->add_option("input", a->input, "trajectory or snapshot file")->required();
  s->add_option("-o,--output", a->output, "output CSV")->required();
  s->add_option("--zone", a->zones,
                "NAME:xlo,ylo,zlo,xhi,yhi,zhi, an open box (bounds may be inf, -inf); repeatable");
  s->add_flag("--drum", a->drum,
              "the DEM8 drum's zones: x+z- (x > 0, z < 0) and x-z+ (x < 0, z > 0)");
  s->add_option("--every", a->every, "every K-th frame (default 1)");
  s->callback([a] { run_materials(*a); });
}

}  // namespace gs::cli
