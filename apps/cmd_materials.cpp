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

void run_materials(const MaterialsArgs& a) {
  const std::string& file = a.input;
  if (a.every < 1) throw InputError(file, "--every: must be at least 1", std::to_string(a.every));
  const std::vector<ga::Zone> zones = ga::material_zones(file, a.drum, a.zones);
  const long frames = static_cast<long>(frame_count(file));
  std::vector<std::string> names;
  if (is_hdf5_file(file))
    names = ga::recorded_material_names(TrajectoryReader(file).metadata().parameters);
  std::size_t materials = 0;
  const std::vector<VtkArray> cols = ga::material_table(
      file, frames, [&](long i) { return read_frame(file, i); }, a.every, zones, names, &materials);
  write_csv_table(a.output, cols);
  std::printf("materials: %zu frames of %s, %zu materials, %zu zones -> %s\n",
              cols.front().values.size(), file.c_str(), materials, zones.size(), a.output.c_str());
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
