// Scene files (TOML, schema in docs/scenes.md): packing, material, walls, solver settings and
// output cadence of one `granoscope simulate` run.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "simulation.hpp"
#include "snapshot.hpp"

namespace gs::solver {

struct OutputSpec {
  std::string trajectory = "trajectory.h5";
  std::int64_t every = 1000;            // steps between trajectory frames
  bool contacts = true;                 // store contacts in frames
  std::string history = "history.csv";  // monitors
  std::int64_t history_every = 100;
  std::int64_t checkpoint_every = 10000;
};

struct Scene {
  std::string name;
  std::filesystem::path file;
  SimulationConfig config;
  std::vector<Particle> particles;
  std::vector<WallSpec> walls;
  std::int64_t steps = 0;
  OutputSpec output;
  std::vector<std::pair<std::string, std::string>> parameters;  // flattened, for run metadata
  double dt_pwave = 0;  // YADE's PWaveTimeStep of the packing (s)
};

/// Reads and checks a scene file. Throws InputError "FILE: key: what (value)".
Scene load_scene(const std::filesystem::path& path);

}  // namespace gs::solver
