// Scenes from Python (granoscope.Scene, python/granoscope/simulation.py): load a scene file with
// values set over it, and run it through the CLI's own run (solver/scenes/scene_run.hpp) with a
// progress callback that can stop it; Ctrl-C stops it too, after a checkpoint to resume from.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "common.hpp"
#include "scene_file.hpp"
#include "scene_run.hpp"

namespace py = pybind11;

namespace gs::py_bind {
namespace {

using Overrides = std::vector<std::pair<std::string, std::string>>;

std::string scene_toml(const solver::Scene& s) {
  for (const auto& [k, v] : s.parameters)
    if (k == "scene.toml") return v;
  return {};
}

}  // namespace

void bind_simulation(py::module_& m) {
  m.def(
      "_scene_info",
      [](const std::filesystem::path& path, const Overrides& overrides, int sweep_point) {
        solver::Scene s;
        {
          py::gil_scoped_release unlocked;
          s = solver::load_scene(path, sweep_point, overrides);
        }
        py::dict d;
        d["name"] = s.name;
        d["test"] = s.test;
        d["particles"] = s.particles.size();
        d["clumps"] = s.clumps.size();
        d["walls"] = s.walls.size();
        d["dt"] = s.config.dt;
        d["dt_pwave"] = s.dt_pwave;
        d["steps"] = s.steps;
        d["threads"] = s.config.threads;
        d["toml"] = scene_toml(s);
        d["values"] = solver::scene_values(scene_toml(s));
        if (s.sweep) {
          d["sweep_key"] = s.sweep->key;
          d["sweep_values"] = s.sweep->values;
        }
        return d;
      },
      py::arg("path"), py::arg("overrides"), py::arg("sweep_point"));

  m.def(
      "_run_scene",
      [](const std::filesystem::path& path, const Overrides& overrides, int sweep_point,
         const std::filesystem::path& out, std::optional<std::int64_t> steps, int threads,
         bool resume, py::object progress, std::int64_t every, py::object log) {
        solver::RunOptions o;
        o.out = out;
        o.steps = steps;
        o.threads = threads;
        o.resume = resume;
        o.progress_every = every;
        o.provenance = "granoscope.Scene(" + path.string() + ").run";
        if (!log.is_none()) {
          o.print = o.warn = [&log](const std::string& line) {
            py::gil_scoped_acquire locked;
            log(line);
          };
        }
        // Every report: a pending Ctrl-C (KeyboardInterrupt) stops the run after a checkpoint;
        // the callback's False stops it quietly; its exception stops it and is raised.
        o.progress = [&progress](const solver::RunProgress& p) {
          raise_pending_signal();
          py::gil_scoped_acquire locked;
          if (progress.is_none()) return true;
          py::dict d;
          d["phase"] = p.phase;
          d["phase_index"] = p.phase_index;
          d["phases"] = p.phases;
          d["step"] = p.step;
          d["time_s"] = p.time_s;
          d["phase_fraction"] = p.phase_fraction;
          d["fraction"] = p.fraction;
          d["steps_per_s"] = p.steps_per_s;
          d["eta_s"] = p.eta_s;
          d["phase_start"] = p.phase_start;
          const py::object r = progress(d);
          return r.is_none() || r.cast<bool>();
        };
        solver::RunOutcome r;
        {
          py::gil_scoped_release unlocked;
          const solver::Scene scene = solver::load_scene(path, sweep_point, overrides);
          r = solver::run_scene(scene, o);
        }
        py::dict d;
        d["out"] = r.out;
        d["trajectory"] = r.trajectory;
        d["history"] = r.history;
        d["curve"] = r.curve.empty() ? py::object(py::none()) : py::cast(r.curve);
        d["ended"] = r.ended;
        d["stopped"] = r.stopped;
        d["was_complete"] = r.was_complete;
        d["step"] = r.step;
        d["steps_run"] = r.steps_run;
        d["particles"] = r.particles;
        d["seconds"] = r.seconds;
        py::dict results;
        for (const auto& [k, v] : r.results) results[py::str(k)] = v;
        d["results"] = results;
        return d;
      },
      py::arg("path"), py::arg("overrides"), py::arg("sweep_point"), py::arg("out"),
      py::arg("steps"), py::arg("threads"), py::arg("resume"), py::arg("progress"),
      py::arg("every"), py::arg("log"));
}

}  // namespace gs::py_bind
