// `granoscope simulate SCENE.toml`: runs a DEM scene, writing an HDF5 trajectory (frames with
// contacts and walls), a monitor history (CSV) and checkpoints it can resume from bit-for-bit.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "scene_file.hpp"
#include "text_parse.hpp"

namespace gs::cli {

namespace {

namespace fs = std::filesystem;

struct Args {
  std::string scene;
  std::string out;
  std::int64_t steps = -1;
  int threads = 0;
  bool resume = false;
  bool quiet = false;
};

struct CheckpointInfo {
  std::int64_t step = 0;
  std::size_t frames = 0, history_rows = 0;
  std::string state_file;
};

void write_checkpoint_info(const fs::path& path, const CheckpointInfo& c) {
  AtomicOutput out(path);
  {
    std::ofstream o(out.temp_path());
    o << "step " << c.step << "\nframes " << c.frames << "\nhistory_rows " << c.history_rows
      << "\nstate " << c.state_file << "\n";
    if (!o.flush()) throw InputError(path.string(), "cannot write checkpoint index");
  }
  out.commit();
}

CheckpointInfo read_checkpoint_info(const fs::path& path) {
  const std::string text = text::read_text_file(path, 1 << 16);
  CheckpointInfo c;
  std::istringstream in(text);
  std::string key;
  bool got[4] = {};
  while (in >> key) {
    if (key == "step")
      got[0] = static_cast<bool>(in >> c.step);
    else if (key == "frames")
      got[1] = static_cast<bool>(in >> c.frames);
    else if (key == "history_rows")
      got[2] = static_cast<bool>(in >> c.history_rows);
    else if (key == "state")
      got[3] = static_cast<bool>(in >> c.state_file);
    else
      throw InputError(path.string(), "unknown key in checkpoint index", key);
  }
  for (bool g : got)
    if (!g) throw InputError(path.string(), "incomplete checkpoint index");
  return c;
}

std::string history_header(const solver::Simulation& sim) {
  std::string h =
      "step,time_s,contacts,kinetic_J,unbalanced_force,elastic_J,friction_dissipation_J,"
      "rolling_dissipation_J,damping_dissipation_J,gravity_work_J,wall_work_J,energy_residual_J";
  for (const auto& w : sim.walls()) {
    const std::string n = w.spec.name.empty() ? "wall" : w.spec.name;
    for (const char* c : {"_fx_N", "_fy_N", "_fz_N", "_x_m", "_y_m", "_z_m"}) h += "," + n + c;
  }
  return h + "\n";
}

std::string history_row(solver::Simulation& sim) {
  const auto& e = sim.energy();
  char buf[512];
  std::snprintf(
      buf, sizeof buf, "%lld,%.17g,%zu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
      static_cast<long long>(sim.step_count()), sim.time(), sim.contact_count(), e.kinetic,
      sim.unbalanced_force(), sim.inertial_number(),
      e.elastic_normal + e.elastic_shear + e.elastic_rolling, e.friction_dissipation,
      e.rolling_dissipation, e.damping_dissipation, e.gravity_work, e.wall_work, e.residual());
  std::string row = buf;
  for (const auto& w : sim.walls()) {
    std::snprintf(buf, sizeof buf, ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", w.force.x(), w.force.y(),
                  w.force.z(), w.pos.x(), w.pos.y(), w.pos.z());
    row += buf;
  }
  return row + "\n";
}

Frame output_frame(const solver::Simulation& sim, bool contacts) {
  Frame f = sim.frame();
  if (!contacts) f.contacts.clear();
  return f;
}

void run(const Args& a) {
  solver::Scene scene = solver::load_scene(a.scene);
  if (a.steps >= 0) scene.steps = a.steps;
  if (a.threads > 0) scene.config.threads = a.threads;
  const fs::path out = a.out.empty() ? fs::path("out") / scene.name : fs::path(a.out);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw InputError(out.string(), "cannot create output directory", ec.message());
  const fs::path traj = out / scene.output.trajectory;
  const fs::path history = out / scene.output.history;
  const fs::path history_partial = fs::path(history.string() + ".partial");
  const fs::path ckpt_index = out / "checkpoint.txt";
  const bool tty = isatty(STDERR_FILENO) && !a.quiet;

  if (scene.config.dt > scene.dt_pwave)
    std::cerr << "warning: " << a.scene << ": dt " << scene.config.dt
              << " s exceeds the P-wave time step " << scene.dt_pwave
              << " s (YADE's PWaveTimeStep); the run may be unstable\n";

  solver::Simulation sim(scene.config, scene.particles, scene.walls);
  RunMetadata meta;
  meta.provenance = "granoscope simulate " + a.scene;
  meta.parameters = scene.parameters;
  meta.parameters.emplace_back("solver.dt_s", value_str(scene.config.dt));
  meta.parameters.emplace_back("solver.dt_pwave_s", value_str(scene.dt_pwave));

  std::optional<TrajectoryWriter> writer;
  CheckpointInfo ck;
  std::size_t history_rows = 0;
  std::ofstream hist;
  if (a.resume) {
    if (!fs::exists(ckpt_index))
      throw InputError(ckpt_index.string(), "no checkpoint to resume from");
    ck = read_checkpoint_info(ckpt_index);
    sim.load_checkpoint(out / ck.state_file);
    if (sim.step_count() != ck.step)
      throw InputError((out / ck.state_file).string(), "checkpoint step differs from its index",
                       std::to_string(sim.step_count()));
    writer.emplace(TrajectoryWriter::resume(traj, ck.frames, {.discard_unfinished = false}));
    // Keep the header and the rows up to the checkpoint.
    const std::string old = text::read_text_file(history_partial);
    const auto lines = text::split_lines(old);
    if (lines.size() < ck.history_rows + 1)
      throw InputError(history_partial.string(), "history shorter than its checkpoint",
                       std::to_string(lines.size()));
    std::string kept;
    for (std::size_t i = 0; i <= ck.history_rows; ++i) kept += std::string(lines[i]) + "\n";
    std::ofstream(history_partial, std::ios::trunc) << kept;
    history_rows = ck.history_rows;
    hist.open(history_partial, std::ios::app);
    std::cerr << "resuming " << scene.name << " from step " << ck.step << "\n";
  } else {
    writer.emplace(traj, meta, TrajectoryWriter::Options{.discard_unfinished = false});
    hist.open(history_partial, std::ios::trunc);
    hist << history_header(sim) << history_row(sim);
    history_rows = 1;
    writer->append(output_frame(sim, scene.output.contacts));
    ck.step = 0;
    ck.frames = writer->frames_written();
    ck.history_rows = history_rows;
    ck.state_file = "checkpoint-0.bin";
    hist.flush();
    sim.save_checkpoint(out / ck.state_file);
    write_checkpoint_info(ckpt_index, ck);
  }
  if (!hist) throw InputError(history_partial.string(), "cannot write history");

  const auto t0 = std::chrono::steady_clock::now();
  auto last_print = t0;
  const std::int64_t first = sim.step_count();
  try {
    while (sim.step_count() < scene.steps) {
      sim.step();
      const std::int64_t s = sim.step_count();
      const bool last = s == scene.steps;
      if (s % scene.output.history_every == 0 || last) {
        sim.check_energy();
        hist << history_row(sim);
        ++history_rows;
      }
      if (s % scene.output.every == 0 || last)
        writer->append(output_frame(sim, scene.output.contacts));
      if (s % scene.output.checkpoint_every == 0 && !last) {
        hist.flush();
        CheckpointInfo next{s, writer->frames_written(), history_rows,
                            "checkpoint-" + std::to_string(s) + ".bin"};
        sim.save_checkpoint(out / next.state_file);
        write_checkpoint_info(ckpt_index, next);
        fs::remove(out / ck.state_file, ec);
        ck = next;
      }
      if (tty) {
        const auto now = std::chrono::steady_clock::now();
        if (now - last_print > std::chrono::milliseconds(500) || last) {
          const double el = std::chrono::duration<double>(now - t0).count();
          const double rate = static_cast<double>(s - first) / std::max(el, 1e-9);
          std::fprintf(stderr, "\rstep %lld/%lld (%.1f%%)  %.3g steps/s  ETA %.0f s   ",
                       static_cast<long long>(s), static_cast<long long>(scene.steps),
                       100.0 * static_cast<double>(s) / static_cast<double>(scene.steps), rate,
                       static_cast<double>(scene.steps - s) / std::max(rate, 1e-9));
          last_print = now;
        }
      }
    }
  } catch (const solver::BlowUp& e) {
    hist.flush();
    throw InputError(a.scene, std::string("blow-up: ") + e.what() +
                                  "; last good checkpoint at step " + std::to_string(ck.step) +
                                  " in " + (out / ck.state_file).string());
  }
  if (tty) std::fprintf(stderr, "\n");
  hist.close();
  writer->finish();
  fs::rename(history_partial, history, ec);
  if (ec) throw InputError(history.string(), "cannot rename output into place", ec.message());
  fs::remove(out / ck.state_file, ec);
  fs::remove(ckpt_index, ec);
  const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double ps =
      static_cast<double>(sim.step_count() - first) * static_cast<double>(sim.particles().size());
  const auto& e = sim.energy();
  std::printf("%s: %lld steps of %zu particles in %.2f s (%.3g particle-steps/s, %d thread(s))\n",
              scene.name.c_str(), static_cast<long long>(sim.step_count() - first),
              sim.particles().size(), el, ps / std::max(el, 1e-9), scene.config.threads);
  std::printf(
      "final: %zu contacts, unbalanced force %.3g, kinetic energy %.3g J, energy residual %.3g J "
      "(%.2g of the energy turnover)\n",
      sim.contact_count(), sim.unbalanced_force(), e.kinetic, e.residual(),
      std::abs(e.residual()) / std::max(1e-300, e.stored() + e.dissipated()));
  std::printf("wrote %s, %s\n", traj.string().c_str(), history.string().c_str());
}

}  // namespace

void register_simulate(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Run a DEM scene (TOML, docs/scenes.md)");
  auto a = std::make_shared<Args>();
  cmd->add_option("SCENE", a->scene, "scene file (.toml)")->required();
  cmd->add_option("-o,--out", a->out, "output directory (default out/<scene name>)");
  cmd->add_option("--steps", a->steps, "override the number of steps")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--threads", a->threads, "override the thread count")->check(CLI::PositiveNumber);
  cmd->add_flag("--resume", a->resume, "continue from the last checkpoint in the output directory");
  cmd->add_flag("-q,--quiet", a->quiet, "no progress line");
  cmd->callback([a] { run(*a); });
}

}  // namespace gs::cli
