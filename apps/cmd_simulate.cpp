// `granoscope simulate SCENE.toml`: runs a DEM scene — a plain run of N steps, or a laboratory
// test (specimen preparation, then triaxial / plane-strain compression or direct shear) —
// writing an HDF5 trajectory (frames with contacts and walls), a monitor history, the test's
// macroscopic curve (CSV), the prepared specimen, and checkpoints it resumes from bit-for-bit.
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "mesh_walls.hpp"
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

/// A CSV written as `<path>.partial` row by row and renamed at the end; on resume it is cut back
/// to the rows a checkpoint recorded.
class CsvOutput {
 public:
  explicit CsvOutput(fs::path path)
      : path_(std::move(path)), partial_(path_.string() + ".partial") {}
  bool open() const { return out_.is_open(); }
  std::size_t rows() const { return rows_; }
  void create(const std::string& header) {
    out_.open(partial_, std::ios::trunc);
    out_ << header << "\n";
    rows_ = 0;
    check();
  }
  void resume(std::size_t rows) {
    // Killed between the final renames: this output was renamed already, the run not finished.
    std::error_code ec;
    if (!fs::exists(partial_) && fs::exists(path_)) fs::rename(path_, partial_, ec);
    if (!fs::exists(partial_)) throw InputError(partial_.string(), "missing output to resume");
    const std::string old = text::read_text_file(partial_);
    forget_input(partial_);
    const auto lines = text::split_lines(old);
    if (lines.size() < rows + 1)
      throw InputError(partial_.string(), "output shorter than its checkpoint",
                       std::to_string(lines.size()));
    std::string kept;
    for (std::size_t i = 0; i <= rows; ++i) kept += std::string(lines[i]) + "\n";
    std::ofstream(partial_, std::ios::trunc) << kept;
    out_.open(partial_, std::ios::app);
    rows_ = rows;
    check();
  }
  void append(const std::string& row) {
    out_ << row << "\n";
    ++rows_;
  }
  void flush() {
    out_.flush();
    check();
  }
  /// flush() and fsync: the rows a checkpoint counts are on disk before its index is.
  void sync() {
    flush();
    sync_to_disk(partial_);
  }
  void finish() {
    if (!out_.is_open()) return;
    out_.close();
    if (out_.fail()) throw InputError(partial_.string(), "cannot write output");
    rename_durably(partial_, path_);
  }
  const fs::path& path() const { return path_; }

 private:
  void check() {
    if (!out_) throw InputError(partial_.string(), "cannot write output");
  }
  fs::path path_, partial_;
  std::ofstream out_;
  std::size_t rows_ = 0;
};

/// An exclusive lock on the output directory for the whole run (a second `simulate` into the same
/// directory mixed its trajectory and history with the first's). Released when the process ends.
class DirectoryLock {
 public:
  explicit DirectoryLock(const fs::path& dir) : path_(dir / ".simulate.lock") {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw InputError(path_.string(), "cannot create lock file", std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      char buf[32] = {};
      const auto n = ::pread(fd_, buf, sizeof buf - 1, 0);
      ::close(fd_);
      fd_ = -1;
      throw InputError(dir.string(), "output directory is in use by another simulate run",
                       n > 0 ? "pid " + std::string(buf, static_cast<std::size_t>(n)) : "");
    }
    const std::string pid = std::to_string(::getpid());
    if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
    }
  }
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;
  ~DirectoryLock() {
    if (fd_ < 0) return;
    std::error_code ec;
    fs::remove(path_, ec);  // (while still held)
    ::close(fd_);
  }

 private:
  fs::path path_;
  int fd_ = -1;
};

/// Temporaries of a killed run (`*.tmp-PID-N` of atomic writes, `.staging-*` directories): with
/// the directory locked, nothing else is writing them.
void remove_stale_temporaries(const fs::path& dir) {
  std::error_code ec;
  std::vector<fs::path> stale;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (n.find(".tmp-") != std::string::npos || n.rfind(".staging-", 0) == 0)
      stale.push_back(e.path());
  }
  for (const auto& p : stale) fs::remove_all(p, ec);
}

/// The scene a run was started with, kept beside its checkpoints.
const char* kSceneCopy = "checkpoint-scene.toml";

std::string flat_scene(const solver::Scene& scene) {
  for (const auto& [k, v] : scene.parameters)
    if (k == "scene.toml") return v;
  return {};
}

using Index = std::map<std::string, std::string>;

void write_index(const fs::path& path, const Index& index) {
  AtomicOutput out(path);
  {
    std::ofstream o(out.temp_path());
    for (const auto& [k, v] : index) o << k << " " << v << "\n";
    if (!o.flush()) throw InputError(path.string(), "cannot write checkpoint index");
  }
  out.commit();
}

Index read_index(const fs::path& path) {
  std::istringstream in(text::read_text_file(path, 1 << 16));
  forget_input(path);  // our own state, replaced at the next checkpoint
  Index index;
  std::string k, v;
  while (in >> k >> v) index[k] = v;
  for (const char* key : {"step", "programme", "frames", "last_frame", "last_frame_step",
                          "last_curve_step", "history_rows", "curve_rows", "prep_rows", "state"})
    if (!index.count(key)) throw InputError(path.string(), "incomplete checkpoint index", key);
  return index;
}

std::int64_t as_int(const Index& index, const std::string& key, const fs::path& path) {
  try {
    return std::stoll(index.at(key));
  } catch (const std::exception&) {
    throw InputError(path.string(), "bad checkpoint index value", key);
  }
}

std::string history_header(const solver::Simulation& sim,
                           const std::vector<std::int64_t>& track_ids) {
  std::string h =
      "step,time_s,contacts,kinetic_J,unbalanced_force,inertial_number,elastic_J,"
      "friction_dissipation_J,rolling_dissipation_J,damping_dissipation_J,gravity_work_J,"
      "wall_work_J,external_work_J,energy_residual_J";
  if (sim.config().law == solver::ContactLaw::HertzMindlin) h += ",viscous_dissipation_J";
  for (std::size_t k = 0; k < sim.walls().size(); ++k) {
    const auto& w = sim.walls()[k];
    if (w.spec.shape == solver::WallShape::Facets) continue;  // (per mesh group, below)
    // An unnamed wall is named by its index, so that no two columns share a name.
    const std::string n = w.spec.name.empty() ? "wall" + std::to_string(k) : w.spec.name;
    for (const char* c : {"_fx_N", "_fy_N", "_fz_N", "_x_m", "_y_m", "_z_m"}) h += "," + n + c;
  }
  auto groups = solver::group_forces(sim);
  for (const auto& g : solver::mesh_forces(sim)) groups.push_back(g);
  for (const auto& g : groups)
    for (const char* c : {"_fx_N", "_fy_N", "_fz_N", "_tx_Nm", "_ty_Nm", "_tz_Nm"})
      h += "," + g.group + c;
  if (sim.facet_forces())
    for (const auto& w : sim.walls())
      for (std::size_t f = 0; f < w.facets.size(); ++f)
        for (const char* c : {"_fx_N", "_fy_N", "_fz_N"})
          h += "," + w.spec.name + "." + std::to_string(f) + c;
  h += ",removed,removed_mass_kg";
  if (sim.periodic()) {  // the cell's stress (Pa, compression negative) and its matrix (m)
    static const char* ij[] = {"xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"};
    for (const char* c : ij) h += std::string(",cell_stress_") + c + "_Pa";
    for (const char* c : ij) h += std::string(",cell_h") + c + "_m";
  }
  for (const auto id : track_ids)  // [output] track_ids: those particles' state
    for (const char* c : {"_x_m", "_y_m", "_z_m", "_vx_m_s", "_vy_m_s", "_vz_m_s"})
      h += ",p" + std::to_string(id) + c;
  return h;
}

std::string history_row(solver::Simulation& sim, const std::vector<std::int64_t>& track_ids) {
  const auto& e = sim.energy();
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "%lld,%.17g,%zu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
                static_cast<long long>(sim.step_count()), sim.time(), sim.contact_count(),
                e.kinetic, sim.unbalanced_force(), sim.inertial_number(),
                e.elastic_normal + e.elastic_shear + e.elastic_rolling, e.friction_dissipation,
                e.rolling_dissipation, e.damping_dissipation, e.gravity_work, e.wall_work,
                e.external_work, e.residual());
  std::string row = buf;
  if (sim.config().law == solver::ContactLaw::HertzMindlin) {
    std::snprintf(buf, sizeof buf, ",%.17g", e.viscous_dissipation);
    row += buf;
  }
  for (const auto& w : sim.walls()) {
    if (w.spec.shape == solver::WallShape::Facets) continue;
    std::snprintf(buf, sizeof buf, ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", w.force.x(), w.force.y(),
                  w.force.z(), w.pos.x(), w.pos.y(), w.pos.z());
    row += buf;
  }
  auto groups = solver::group_forces(sim);
  for (const auto& g : solver::mesh_forces(sim)) groups.push_back(g);
  for (const auto& g : groups) {
    std::snprintf(buf, sizeof buf, ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", g.force.x(), g.force.y(),
                  g.force.z(), g.torque.x(), g.torque.y(), g.torque.z());
    row += buf;
  }
  if (sim.facet_forces())
    for (const auto& w : sim.walls())
      for (std::size_t f = 0; f < w.facets.size(); ++f) {
        const Eigen::Vector3d F =
            f < w.facet_force.size() ? w.facet_force[f] : Eigen::Vector3d::Zero();
        std::snprintf(buf, sizeof buf, ",%.17g,%.17g,%.17g", F.x(), F.y(), F.z());
        row += buf;
      }
  std::snprintf(buf, sizeof buf, ",%zu,%.17g", sim.removed_count(), sim.removed_mass());
  row += buf;
  if (sim.periodic())
    for (const Eigen::Matrix3d& m : {sim.cell_stress(), sim.cell().hsize})
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          std::snprintf(buf, sizeof buf, ",%.17g", m(i, j));
          row += buf;
        }
  const auto& p = sim.particles();
  for (const auto id : track_ids) {
    const auto it = std::find(p.id.begin(), p.id.end(), id);
    const auto i = static_cast<std::size_t>(it - p.id.begin());
    const bool here = it != p.id.end() && !p.removed[i];  // (gone through an outlet: nan)
    const Eigen::Vector3d x = here ? p.pos[i] : Eigen::Vector3d::Constant(NAN);
    const Eigen::Vector3d v = here ? p.vel[i] : Eigen::Vector3d::Constant(NAN);
    std::snprintf(buf, sizeof buf, ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", x.x(), x.y(), x.z(),
                  v.x(), v.y(), v.z());
    row += buf;
  }
  return row;
}

using Results = std::vector<std::pair<std::string, double>>;

/// `results.csv` of a run: name,value rows.
void write_results(const fs::path& path, const Results& r) {
  AtomicOutput out(path);
  {
    std::ofstream o(out.temp_path());
    o << "name,value\n";
    char buf[64];
    for (const auto& [k, v] : r) {
      std::snprintf(buf, sizeof buf, "%.9g", v);
      o << k << "," << buf << "\n";
    }
    if (!o.flush()) throw InputError(path.string(), "cannot write output");
  }
  out.commit();
}

Results read_results(const fs::path& path) {
  Results r;
  const std::string text = text::read_text_file(path, 1 << 20);
  const auto lines = text::split_lines(text);  // (views into `text`)
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::string line(lines[i]);
    const auto comma = line.find(',');
    if (comma == std::string::npos) continue;
    r.emplace_back(line.substr(0, comma), std::strtod(line.c_str() + comma + 1, nullptr));
  }
  return r;
}

/// One run; its results when its last programme ended (not when --steps stopped it first).
Results run(const Args& a, int sweep_point = -1) {
  solver::Scene scene = solver::load_scene(a.scene, sweep_point);
  auto programmes = solver::scene_programmes(scene);
  if (a.threads > 0) scene.config.threads = a.threads;
  // Where the run stops at the latest: --steps, or a plain scene's own number of steps.
  std::optional<std::int64_t> stop_at;
  if (a.steps >= 0) stop_at = a.steps;
  if (scene.test.empty() && !scene.fill) {
    if (!stop_at) stop_at = scene.steps;
    programmes.clear();
    programmes.push_back(std::make_unique<solver::FixedSteps>(*stop_at, scene.output.every));
  }  // (with a [fill]: the filling, then `steps` more; --steps stops at that step)
  const fs::path out = a.out.empty() ? fs::path("out") / scene.name : fs::path(a.out);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw InputError(out.string(), "cannot create output directory", ec.message());
  const DirectoryLock lock(out);
  remove_stale_temporaries(out);
  const fs::path traj = out / scene.output.trajectory;
  const fs::path ckpt_index = out / "checkpoint.txt";
  const fs::path scene_copy = out / kSceneCopy;
  const bool tty = isatty(STDERR_FILENO) && !a.quiet;

  if (scene.config.dt > scene.dt_pwave)
    std::cerr << "warning: " << a.scene << ": dt " << scene.config.dt
              << " s exceeds the P-wave time step " << scene.dt_pwave
              << " s (YADE's PWaveTimeStep); the run may be unstable\n";

  solver::Simulation sim(scene.config, scene.particles, scene.walls);
  if (!scene.clumps.empty()) sim.set_clumps(scene.clumps);
  if (scene.outlet) sim.set_outlet(scene.outlet->first, scene.outlet->second);
  if (scene.cell) {
    try {
      sim.set_periodic(scene.cell->hsize, scene.cell->planar);
      if (scene.cell->disks) sim.set_disks(scene.cell->hsize(2, 2));
      sim.set_velocity_gradient(scene.cell->vel_grad);
      if (scene.cell->servo) sim.set_cell_servo(*scene.cell->servo);
    } catch (const std::invalid_argument& e) {
      throw InputError(a.scene, "[cell]", e.what());
    }
  }
  if (scene.output.facet_forces) sim.set_facet_forces(true);
  RunMetadata meta;
  meta.provenance = "granoscope simulate " + a.scene;
  meta.parameters = scene.parameters;
  meta.parameters.emplace_back("solver.dt_s", value_str(scene.config.dt));
  meta.parameters.emplace_back("solver.dt_pwave_s", value_str(scene.dt_pwave));
  if (!scene.test.empty()) meta.parameters.emplace_back("output.curve", scene.output.curve);

  CsvOutput history(out / scene.output.history);
  CsvOutput curve(out / scene.output.curve);
  CsvOutput prep_curve(out / scene.output.preparation);
  std::optional<TrajectoryWriter> writer;
  std::size_t k = 0;             // current programme
  std::int64_t last_frame = -1;  // frame index of the last frame written
  std::int64_t last_frame_step = -1;
  Index ck;

  std::int64_t last_curve_step = -1;
  auto curve_for = [&](std::size_t i) -> CsvOutput& {
    return programmes[i]->name() == "preparation" ? prep_curve : curve;
  };
  auto open_curve = [&](std::size_t i) {
    const std::string h = programmes[i]->curve_header();
    if (!h.empty()) curve_for(i).create(h);
    last_curve_step = -1;
  };
  auto curve_row = [&] {
    CsvOutput& c = curve_for(k);
    if (c.open() && last_curve_step != sim.step_count()) {
      c.append(programmes[k]->curve_row(sim));
      c.flush();  // a few rows per thousand steps: keep them readable while the run goes on
      last_curve_step = sim.step_count();
    }
  };
  auto write_frame = [&] {
    if (!writer) writer.emplace(traj, meta, TrajectoryWriter::Options{.discard_unfinished = false});
    Frame f = sim.frame();
    if (!scene.output.contacts) f.contacts.clear();
    writer->append(f);
    last_frame_step = sim.step_count();
  };
  auto checkpoint = [&](std::int64_t s) {
    // Everything the index counts reaches the disk before the index does (power loss).
    history.sync();
    if (curve.open()) curve.sync();
    if (prep_curve.open()) prep_curve.sync();
    if (writer) sync_to_disk(partial_path(traj));
    Index next{{"step", std::to_string(s)},
               {"programme", std::to_string(k)},
               {"frames", std::to_string(writer ? writer->frames_written() : 0)},
               {"last_frame", std::to_string(last_frame)},
               {"last_frame_step", std::to_string(last_frame_step)},
               {"last_curve_step", std::to_string(last_curve_step)},
               {"history_rows", std::to_string(history.rows())},
               {"curve_rows", std::to_string(curve.open() ? curve.rows() : 0)},
               {"prep_rows", std::to_string(prep_curve.open() ? prep_curve.rows() : 0)},
               {"state", "checkpoint-" + std::to_string(s) + ".bin"}};
    sim.save_checkpoint(out / next["state"], programmes[k]->save_state());
    write_index(ckpt_index, next);
    if (ck.count("state") && ck["state"] != next["state"]) fs::remove(out / ck["state"], ec);
    ck = next;
  };

  if (a.resume) {
    if (!fs::exists(ckpt_index)) {
      // Killed during the final cleanup (the index goes first): the run is complete.
      if (fs::exists(traj) && !fs::exists(partial_path(traj))) {
        for (const auto& e : fs::directory_iterator(out, ec)) {
          const std::string n = e.path().filename().string();
          if (n.rfind("checkpoint-", 0) == 0) fs::remove(e.path(), ec);
        }
        std::printf("%s: the run is complete (%s); nothing to resume\n", scene.name.c_str(),
                    traj.string().c_str());
        return fs::exists(out / "results.csv") ? read_results(out / "results.csv") : Results{};
      }
      throw InputError(ckpt_index.string(), "no checkpoint to resume from");
    }
    if (fs::exists(scene_copy)) {
      std::vector<std::string> changed;
      for (const auto& key :
           solver::scene_differences(text::read_text_file(scene_copy, 1 << 26), flat_scene(scene)))
        if (key != "solver.steps") changed.push_back(key);  // more (or fewer) steps: safe
      if (!changed.empty()) {
        std::string keys;
        for (const auto& k : changed) keys += (keys.empty() ? "" : ", ") + k;
        throw InputError(a.scene,
                         "scene differs from the run being resumed (rerun without --resume)", keys);
      }
    }
    ck = read_index(ckpt_index);
    const fs::path state = out / ck["state"];
    const std::string extra = sim.load_checkpoint(state);
    forget_input(state);
    if (sim.step_count() != as_int(ck, "step", ckpt_index))
      throw InputError(state.string(), "checkpoint step differs from its index",
                       std::to_string(sim.step_count()));
    k = static_cast<std::size_t>(as_int(ck, "programme", ckpt_index));
    if (k >= programmes.size())
      throw InputError(ckpt_index.string(), "checkpoint programme not in the scene",
                       ck["programme"]);
    programmes[k]->load_state(extra);
    last_frame = as_int(ck, "last_frame", ckpt_index);
    last_frame_step = as_int(ck, "last_frame_step", ckpt_index);
    last_curve_step = as_int(ck, "last_curve_step", ckpt_index);
    const auto frames = static_cast<std::size_t>(as_int(ck, "frames", ckpt_index));
    // Killed between the final renames: the trajectory was renamed, the run not finished.
    if (frames > 0 && !fs::exists(partial_path(traj)) && fs::exists(traj))
      fs::rename(traj, partial_path(traj), ec);
    if (frames > 0)
      writer.emplace(TrajectoryWriter::resume(traj, frames, {.discard_unfinished = false}));
    history.resume(static_cast<std::size_t>(as_int(ck, "history_rows", ckpt_index)));
    // Curves of the phases that have begun.
    for (std::size_t i = 0; i <= k; ++i) {
      if (programmes[i]->curve_header().empty()) continue;
      CsvOutput& c = curve_for(i);
      if (i < k && &c == &prep_curve) continue;  // finished: already renamed
      c.resume(static_cast<std::size_t>(
          as_int(ck, &c == &prep_curve ? "prep_rows" : "curve_rows", ckpt_index)));
    }
    std::cerr << "resuming " << scene.name << " from step " << sim.step_count() << " ("
              << programmes[k]->name() << ")\n";
  } else {
    {
      AtomicOutput copy(scene_copy);
      {
        std::ofstream o(copy.temp_path());
        o << flat_scene(scene);
        if (!o.flush()) throw InputError(scene_copy.string(), "cannot write output");
      }
      copy.commit();
    }
    history.create(history_header(sim, scene.output.track_ids));
    programmes[0]->start(sim);
    open_curve(0);
    history.append(history_row(sim, scene.output.track_ids));
    curve_row();
    if (programmes[0]->name() != "preparation") {
      last_frame = programmes[0]->frame_index(sim);
      write_frame();
    }
    checkpoint(sim.step_count());
  }

  const auto t0 = std::chrono::steady_clock::now();
  auto last_print = t0;
  const std::int64_t first = sim.step_count();
  // stderr not a terminal (a log, CI): one line when a phase starts and at each 10 % of it.
  const bool log_progress = !tty && !a.quiet;
  std::size_t logged_phase = programmes.size();
  int logged_tenth = -1;
  auto log_line = [&](bool phase_start) {
    const double prog = std::clamp(programmes[k]->progress(sim), 0.0, 1.0);
    const int tenth = static_cast<int>(prog * 10.0 + 1e-9);
    if (logged_phase == k && !phase_start && tenth <= logged_tenth) return;
    if (logged_phase == k && phase_start) return;
    logged_phase = k;
    logged_tenth = tenth;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double rate = static_cast<double>(sim.step_count() - first) / std::max(el, 1e-9);
    const double done_frac = (static_cast<double>(k) + prog) / programmes.size();
    const double eta = done_frac > 0 ? el * (1 - done_frac) / done_frac : 0;
    std::fprintf(stderr, "%s %zu/%zu: step %lld  %.0f%%  %.3g steps/s  ETA %.0f s\n",
                 programmes[k]->name().c_str(), k + 1, programmes.size(),
                 static_cast<long long>(sim.step_count()), 100.0 * prog, rate, eta);
    std::fflush(stderr);
  };
  if (log_progress) log_line(true);
  bool ended = false;
  try {
    while (true) {
      if (programmes[k]->finished(sim)) {
        const std::string sum = programmes[k]->summary(sim);
        if (!sum.empty()) std::printf("%s\n", sum.c_str());
        curve_row();  // the state at the programme's end
        if (k + 1 == programmes.size()) {
          ended = true;
          break;
        }
        if (programmes[k]->name() == "preparation") {
          prep_curve.finish();
          Trajectory specimen;
          specimen.metadata = meta;
          specimen.metadata.provenance += " (prepared specimen)";
          specimen.frames.push_back(sim.frame());
          write_hdf5_trajectory(out / scene.output.specimen, specimen);
        }
        ++k;
        programmes[k]->start(sim);
        open_curve(k);
        curve_row();
        last_frame = programmes[k]->frame_index(sim);
        write_frame();
        if (log_progress) log_line(true);
        continue;
      }
      if (stop_at && sim.step_count() >= *stop_at) break;
      programmes[k]->control(sim);
      if (programmes[k]->finished(sim)) continue;  // ended by its control (a stage check)
      sim.step();
      const std::int64_t s = sim.step_count();
      if (s % scene.output.history_every == 0) {
        sim.check_energy();
        history.append(history_row(sim, scene.output.track_ids));
      }
      if (s % scene.output.curve_every == 0) curve_row();
      if (programmes[k]->name() != "preparation") {
        const std::int64_t fi = programmes[k]->frame_index(sim);
        if (fi > last_frame) {
          last_frame = fi;
          write_frame();
        }
      }
      if (s % scene.output.checkpoint_every == 0) checkpoint(s);
      if (log_progress && s % 64 == 0) log_line(false);
      if (tty) {
        const auto now = std::chrono::steady_clock::now();
        if (now - last_print > std::chrono::milliseconds(500)) {
          const double el = std::chrono::duration<double>(now - t0).count();
          const double rate = static_cast<double>(s - first) / std::max(el, 1e-9);
          const double prog = programmes[k]->progress(sim);
          const double done_frac = (static_cast<double>(k) + prog) / programmes.size();
          const double eta = done_frac > 0 ? el * (1 - done_frac) / done_frac : 0;
          std::fprintf(stderr, "\r%s %zu/%zu: step %lld  %.1f%%  %.3g steps/s  ETA %.0f s   ",
                       programmes[k]->name().c_str(), k + 1, programmes.size(),
                       static_cast<long long>(s), 100.0 * prog, rate, eta);
          last_print = now;
        }
      }
    }
  } catch (const solver::FillError& e) {
    history.flush();
    throw InputError(a.scene, e.what());
  } catch (const solver::BlowUp& e) {
    history.flush();
    throw InputError(a.scene, std::string("blow-up: ") + e.what() +
                                  "; last good checkpoint at step " + ck["step"] + " in " +
                                  (out / ck["state"]).string());
  }
  if (tty) std::fprintf(stderr, "\n");
  // Final rows and frame, unless the last step already wrote them.
  const std::int64_t s = sim.step_count();
  if (s % scene.output.history_every != 0) history.append(history_row(sim, scene.output.track_ids));
  if (programmes[k]->name() != "preparation" && last_frame_step != s) write_frame();
  history.finish();
  curve.finish();
  prep_curve.finish();
  if (writer) writer->finish();
  Results results;
  if (ended) results = programmes[k]->results(sim);
  if (!results.empty()) write_results(out / "results.csv", results);
  // The index first: a kill from here on leaves a complete run, which --resume recognises.
  fs::remove(ckpt_index, ec);
  fs::remove(out / ck["state"], ec);
  fs::remove(scene_copy, ec);
  const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double ps = static_cast<double>(s - first) * static_cast<double>(sim.particles().size());
  const auto& e = sim.energy();
  std::printf("%s: %lld steps of %zu particles in %.2f s (%.3g particle-steps/s, %d thread(s))\n",
              scene.name.c_str(), static_cast<long long>(s - first), sim.particles().size(), el,
              ps / std::max(el, 1e-9), scene.config.threads);
  std::printf(
      "final: %zu contacts, unbalanced force %.3g, kinetic energy %.3g J, energy residual %.3g J "
      "(%.2g of the energy turnover)\n",
      sim.contact_count(), sim.unbalanced_force(), e.kinetic, e.residual(),
      std::abs(e.residual()) / std::max(1e-300, e.stored() + e.dissipated()));
  std::printf("wrote %s, %s", traj.string().c_str(), history.path().string().c_str());
  if (!scene.test.empty()) std::printf(", %s", curve.path().string().c_str());
  if (!results.empty()) std::printf(", %s", (out / "results.csv").string().c_str());
  std::printf("\n");
  return results;
}

/// A scene with [sweep]: one run per value, each in OUT/<key leaf>_<value>/ (resumed, or read
/// back when complete, with --resume), and OUT/sweep.csv: the value and each run's results.
void run_sweep(const Args& a, const solver::Scene& first) {
  const solver::SweepInfo& sw = *first.sweep;
  const std::string leaf = sw.key.substr(sw.key.rfind('.') + 1);
  const fs::path out = a.out.empty() ? fs::path("out") / first.name : fs::path(a.out);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw InputError(out.string(), "cannot create output directory", ec.message());
  std::vector<std::pair<std::string, Results>> rows;
  std::vector<std::string> failed;
  for (std::size_t i = 0; i < sw.values.size(); ++i) {
    Args one = a;
    one.out = (out / (leaf + "_" + sw.values[i])).string();
    const bool started = fs::exists(fs::path(one.out) / "checkpoint.txt") ||
                         fs::exists(fs::path(one.out) / "results.csv");
    one.resume = a.resume && started;
    std::printf("sweep %s = %s (%zu of %zu) -> %s\n", sw.key.c_str(), sw.values[i].c_str(), i + 1,
                sw.values.size(), one.out.c_str());
    std::fflush(stdout);
    try {
      rows.emplace_back(sw.values[i], run(one, static_cast<int>(i)));
    } catch (const InputError& e) {
      // A point that fails (a blow-up, a jam) does not stop the others: its row stays empty.
      std::printf("sweep %s = %s failed: %s\n", sw.key.c_str(), sw.values[i].c_str(), e.what());
      std::fflush(stdout);
      rows.emplace_back(sw.values[i], Results{});
      failed.push_back(sw.values[i]);
    }
    // The table so far, after every point.
    std::vector<std::string> names;
    for (const auto& [v, r] : rows)
      for (const auto& [n, x] : r)
        if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    AtomicOutput table(out / "sweep.csv");
    {
      std::ofstream o(table.temp_path());
      o << leaf;
      for (const auto& n : names) o << "," << n;
      o << ",run\n";
      char buf[64];
      for (std::size_t j = 0; j < rows.size(); ++j) {
        o << rows[j].first;
        for (const auto& n : names) {
          const auto it = std::find_if(rows[j].second.begin(), rows[j].second.end(),
                                       [&](const auto& p) { return p.first == n; });
          if (it != rows[j].second.end()) {
            std::snprintf(buf, sizeof buf, "%.9g", it->second);
            o << "," << buf;
          } else {
            o << ",";
          }
        }
        o << "," << leaf << "_" << rows[j].first << "\n";
      }
      if (!o.flush()) throw InputError((out / "sweep.csv").string(), "cannot write output");
    }
    table.commit();
  }
  std::printf("wrote %s\n", (out / "sweep.csv").string().c_str());
  if (!failed.empty()) {
    std::string list;
    for (const auto& v : failed) list += (list.empty() ? "" : ", ") + v;
    throw InputError(a.scene,
                     "sweep: " + std::to_string(failed.size()) + " of " +
                         std::to_string(sw.values.size()) + " runs failed (see the output above)",
                     list);
  }
}

void run_scene(const Args& a) {
  if (solver::scene_has_sweep(a.scene)) return run_sweep(a, solver::load_scene(a.scene));
  run(a);
}

}  // namespace

void register_simulate(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Run a DEM scene (TOML, docs/scenes.md)");
  auto a = std::make_shared<Args>();
  cmd->add_option("SCENE", a->scene, "scene file (.toml)")->required();
  cmd->add_option("-o,--out", a->out, "output directory (default out/<scene name>)");
  cmd->add_option("--steps", a->steps,
                  "stop at this step (a plain scene: its number of steps; a laboratory test "
                  "ends earlier if its programme ends first)")
      ->check(CLI::Range(std::int64_t{0}, std::numeric_limits<std::int64_t>::max()));
  cmd->add_option("--threads", a->threads,
                  "override the thread count (1 to " + std::to_string(solver::kMaxThreads) + ")")
      ->check(CLI::Range(1, solver::kMaxThreads));
  cmd->add_flag("--resume", a->resume, "continue from the last checkpoint in the output directory");
  cmd->add_flag("-q,--quiet", a->quiet, "no progress line");
  cmd->callback([a] { run_scene(*a); });
}

}  // namespace gs::cli
