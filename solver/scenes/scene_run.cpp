// A run of a scene (see scene_run.hpp): the loop of programmes, outputs and checkpoints.
#include "scene_run.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "atomic_file.hpp"
#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "mesh_walls.hpp"
#include "spatial_order.hpp"
#include "text_parse.hpp"

namespace gs::solver {
namespace {

namespace fs = std::filesystem;

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

std::string flat_scene(const Scene& scene) {
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

std::string history_header(const Simulation& sim, const std::vector<std::int64_t>& track_ids) {
  std::string h =
      "step,time_s,contacts,kinetic_J,unbalanced_force,inertial_number,elastic_J,"
      "friction_dissipation_J,rolling_dissipation_J,damping_dissipation_J,gravity_work_J,"
      "wall_work_J,external_work_J,energy_residual_J";
  if (sim.config().law == ContactLaw::HertzMindlin) h += ",viscous_dissipation_J";
  for (std::size_t k = 0; k < sim.walls().size(); ++k) {
    const auto& w = sim.walls()[k];
    if (w.spec.shape == WallShape::Facets) continue;  // (per mesh group, below)
    // An unnamed wall is named by its index, so that no two columns share a name.
    const std::string n = w.spec.name.empty() ? "wall" + std::to_string(k) : w.spec.name;
    for (const char* c : {"_fx_N", "_fy_N", "_fz_N", "_x_m", "_y_m", "_z_m"}) h += "," + n + c;
  }
  auto groups = group_forces(sim);
  for (const auto& g : mesh_forces(sim)) groups.push_back(g);
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

std::string history_row(Simulation& sim, const std::vector<std::int64_t>& track_ids) {
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
  if (sim.config().law == ContactLaw::HertzMindlin) {
    std::snprintf(buf, sizeof buf, ",%.17g", e.viscous_dissipation);
    row += buf;
  }
  for (const auto& w : sim.walls()) {
    if (w.spec.shape == WallShape::Facets) continue;
    std::snprintf(buf, sizeof buf, ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", w.force.x(), w.force.y(),
                  w.force.z(), w.pos.x(), w.pos.y(), w.pos.z());
    row += buf;
  }
  auto groups = group_forces(sim);
  for (const auto& g : mesh_forces(sim)) groups.push_back(g);
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

// [solver] order = "spatial": the loaded particles (those before a [fill]'s) renumbered along a
// Morton curve through cells of the largest diameter; clump members follow them; ids unchanged.
void order_spatially(Scene& scene) {
  const std::size_t n = scene.fill ? scene.fill_first : scene.particles.size();
  if (n < 2) return;
  std::vector<Eigen::Vector3d> centres(n);
  double d_max = 0;
  for (std::size_t i = 0; i < n; ++i) {
    centres[i] = scene.particles[i].position;
    d_max = std::max(d_max, 2 * scene.particles[i].radius);
  }
  const auto order = spatial_order(centres, d_max);
  std::vector<std::uint32_t> new_index(n);
  std::vector<Particle> moved(scene.particles.size());
  for (std::size_t i = 0; i < n; ++i) {
    new_index[order[i]] = static_cast<std::uint32_t>(i);
    moved[i] = std::move(scene.particles[order[i]]);
  }
  std::move(scene.particles.begin() + static_cast<std::ptrdiff_t>(n), scene.particles.end(),
            moved.begin() + static_cast<std::ptrdiff_t>(n));
  scene.particles = std::move(moved);
  for (auto& c : scene.clumps)
    for (auto& m : c.members)
      if (m < n) m = new_index[m];
}

}  // namespace

void write_run_results(const fs::path& path, const RunResults& r) {
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

RunResults read_run_results(const fs::path& path) {
  RunResults r;
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

RunOutcome run_scene(Scene scene, const RunOptions& a) {
  const std::string scene_file = scene.file.string();
  const auto print = [&a](const std::string& line) {
    if (a.print) a.print(line);
  };
  const auto warn = [&a](const std::string& line) {
    if (a.warn) a.warn(line);
  };
  auto programmes = scene_programmes(scene);
  if (a.threads > 0) scene.config.threads = a.threads;
  const RunOptions::Parallel* par = a.parallel ? &*a.parallel : nullptr;
  const bool threads_by_size = scene.config.threads == 0;
  if (threads_by_size)  // "auto"; under mpirun one thread a process (the processes take the cores)
    scene.config.threads = par ? 1 : auto_threads(scene.particles.size());
  // "auto" in one process: the count then follows the steps' timing (thread_tuner.hpp).
  std::optional<ThreadTuner> tuner;
  if (threads_by_size && !par && machine_threads() > 1)
    tuner.emplace(scene.config.threads, machine_threads(), a.thread_tuning);
  // Where the run stops at the latest: `steps`, or a plain scene's own number of steps.
  std::optional<std::int64_t> stop_at = a.steps;
  if (scene.test.empty() && !scene.fill) {
    if (!stop_at) stop_at = scene.steps;
    programmes.clear();
    programmes.push_back(std::make_unique<FixedSteps>(*stop_at, scene.output.every));
  }  // (with a [fill]: the filling, then `steps` more; `steps` stops at that step)
  const fs::path out = a.out.empty() ? fs::path("out") / scene.name : a.out;
  RunOutcome outcome;
  outcome.out = out;
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw InputError(out.string(), "cannot create output directory", ec.message());
  const DirectoryLock lock(out);
  remove_stale_temporaries(out);
  const fs::path traj = out / scene.output.trajectory;
  const fs::path ckpt_index = out / "checkpoint.txt";
  const fs::path scene_copy = out / kSceneCopy;
  outcome.trajectory = traj;
  outcome.history = out / scene.output.history;
  if (!scene.test.empty()) outcome.curve = out / scene.output.curve;

  if (scene.config.dt > scene.dt_pwave)
    warn("warning: " + scene_file + ": dt " + value_str(scene.config.dt) +
         " s exceeds the P-wave time step " + value_str(scene.dt_pwave) +
         " s (YADE's PWaveTimeStep); the run may be unstable");

  if (scene.spatial_order) order_spatially(scene);
  Simulation sim(scene.config, scene.particles, scene.walls);
  std::vector<Particle>().swap(scene.particles);  // (the engine holds them now: not twice)
  if (!scene.clumps.empty()) sim.set_clumps(scene.clumps);
  if (scene.outlet) sim.set_outlet(scene.outlet->first, scene.outlet->second);
  if (scene.cell) {
    try {
      sim.set_periodic(scene.cell->hsize, scene.cell->planar);
      if (scene.cell->disks) sim.set_disks(scene.cell->hsize(2, 2));
      sim.set_velocity_gradient(scene.cell->vel_grad);
      if (scene.cell->servo) sim.set_cell_servo(*scene.cell->servo);
    } catch (const std::invalid_argument& e) {
      throw InputError(scene_file, "[cell]", e.what());
    }
  }
  if (scene.output.facet_forces) sim.set_facet_forces(true);
  // (a laboratory programme reads the walls' loads between steps: under mpirun each step sums
  // them as one process does)
  if (!scene.test.empty()) sim.set_exact_wall_loads(true);
  RunMetadata meta;
  meta.provenance = a.provenance.empty() ? "granoscope simulate " + scene_file : a.provenance;
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

  // Under a domain decomposition, what reads the whole state runs after a gather (process 0
  // then holds it) and before the release.
  auto whole = [&](auto&& fn) {
    if (!par) return fn();
    par->gather(sim);
    fn();
    par->release(sim);
  };
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
      whole([&] { c.append(programmes[k]->curve_row(sim)); });
      c.flush();  // a few rows per thousand steps: keep them readable while the run goes on
      last_curve_step = sim.step_count();
    }
  };
  // The ledger's check on the whole (process 0), its verdict shared by every process.
  auto check_energy = [&] {
    if (!par) return sim.check_energy();
    std::string error;
    if (par->root) {
      try {
        sim.check_energy();
      } catch (const BlowUp& e) {
        error = e.what();
      }
    }
    if (par->any(!error.empty()))
      throw BlowUp(error.empty() ? "energy ledger out of bounds (process 0)" : error);
  };
  auto history_append = [&](bool check) {
    whole([&] {
      if (check) check_energy();
      history.append(history_row(sim, scene.output.track_ids));
    });
  };
  auto write_frame_now = [&] {
    if (!writer) writer.emplace(traj, meta, TrajectoryWriter::Options{.discard_unfinished = false});
    // In pieces of 65 536 particles and candidate pairs: a frame of a million spheres and
    // their contacts (about 500 MB as Particle and Contact rows) is never held whole.
    writer->append(sim.frame_head(), [&](std::size_t i, Frame& piece) {
      const bool more = sim.frame_piece(i, 65536, piece);
      if (!scene.output.contacts) piece.contacts.clear();
      return more;
    });
    last_frame_step = sim.step_count();
  };
  auto write_frame = [&] { whole(write_frame_now); };
  auto checkpoint_now = [&](std::int64_t s) {
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
  auto checkpoint = [&](std::int64_t s) { whole([&] { checkpoint_now(s); }); };

  if (a.resume) {
    if (!fs::exists(ckpt_index)) {
      // Killed during the final cleanup (the index goes first): the run is complete.
      if (fs::exists(traj) && !fs::exists(partial_path(traj))) {
        for (const auto& e : fs::directory_iterator(out, ec)) {
          const std::string n = e.path().filename().string();
          if (n.rfind("checkpoint-", 0) == 0) fs::remove(e.path(), ec);
        }
        print(scene.name + ": the run is complete (" + traj.string() + "); nothing to resume");
        outcome.was_complete = outcome.ended = true;
        if (fs::exists(out / "results.csv"))
          outcome.results = read_run_results(out / "results.csv");
        return outcome;
      }
      throw InputError(ckpt_index.string(), "no checkpoint to resume from");
    }
    if (fs::exists(scene_copy)) {
      std::vector<std::string> changed;
      for (const auto& key :
           scene_differences(text::read_text_file(scene_copy, 1 << 26), flat_scene(scene)))
        if (key != "solver.steps") changed.push_back(key);  // more (or fewer) steps: safe
      if (!changed.empty()) {
        std::string keys;
        for (const auto& k : changed) keys += (keys.empty() ? "" : ", ") + k;
        throw InputError(scene_file,
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
    if (par) par->attach(sim);
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
    warn("resuming " + scene.name + " from step " + std::to_string(sim.step_count()) + " (" +
         programmes[k]->name() + ")");
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
    // (the domain after the start: a filling's particles waiting to enter are then known, and
    // its first layer is in place, so the bricks are cut where the particles are)
    programmes[0]->start(sim);
    if (par) par->attach(sim);
    open_curve(0);
    history_append(false);
    curve_row();
    if (programmes[0]->name() != "preparation") {
      last_frame = programmes[0]->frame_index(sim);
      write_frame();
    }
    checkpoint(sim.step_count());
  }

  const auto t0 = std::chrono::steady_clock::now();
  const std::int64_t first = sim.step_count();
  bool stop_requested = false;
  std::exception_ptr thrown;  // by the callback: rethrown after the stop's checkpoint
  // The progress report; false from the callback stops the run.
  auto report = [&](bool phase_start) {
    if (!a.progress) return;
    RunProgress p;
    p.phase = programmes[k]->name();
    p.phase_index = k;
    p.phases = programmes.size();
    p.step = sim.step_count();
    p.time_s = sim.time();
    p.phase_fraction = std::clamp(programmes[k]->progress(sim), 0.0, 1.0);
    p.fraction = (static_cast<double>(k) + p.phase_fraction) / programmes.size();
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    p.steps_per_s = static_cast<double>(sim.step_count() - first) / std::max(el, 1e-9);
    p.eta_s = p.fraction > 0 ? el * (1 - p.fraction) / p.fraction : 0;
    p.phase_start = phase_start;
    try {
      if (!a.progress(p)) stop_requested = true;
    } catch (...) {
      thrown = std::current_exception();
      stop_requested = true;
    }
  };
  // (under a decomposition every process stops at the same step when one is asked to)
  auto report_all = [&](bool phase_start) {
    report(phase_start);
    if (par) stop_requested = par->any(stop_requested);
  };
  const std::int64_t every = std::max<std::int64_t>(1, a.progress_every);
  report_all(true);
  bool ended = false;
  try {
    while (!stop_requested) {
      if (programmes[k]->finished(sim)) {
        std::string sum;
        whole([&] { sum = programmes[k]->summary(sim); });
        if (!sum.empty()) print(sum);
        curve_row();  // the state at the programme's end
        if (k + 1 == programmes.size()) {
          ended = true;
          break;
        }
        if (programmes[k]->name() == "preparation") {
          prep_curve.finish();
          whole([&] {
            Trajectory specimen;
            specimen.metadata = meta;
            specimen.metadata.provenance += " (prepared specimen)";
            specimen.frames.push_back(sim.frame());
            write_hdf5_trajectory(out / scene.output.specimen, specimen);
          });
        }
        ++k;
        programmes[k]->start(sim);
        open_curve(k);
        curve_row();
        last_frame = programmes[k]->frame_index(sim);
        write_frame();
        report_all(true);
        continue;
      }
      if (stop_at && sim.step_count() >= *stop_at) break;
      programmes[k]->control(sim);
      if (programmes[k]->finished(sim)) continue;  // ended by its control (a stage check)
      if (tuner) {
        const auto before = std::chrono::steady_clock::now();
        sim.step();
        const int t = tuner->record(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count());
        if (t != sim.config().threads) sim.set_threads(t);
      } else {
        sim.step();
      }
      const std::int64_t s = sim.step_count();
      if (s % scene.output.history_every == 0) history_append(true);
      if (s % scene.output.curve_every == 0) curve_row();
      if (programmes[k]->name() != "preparation") {
        const std::int64_t fi = programmes[k]->frame_index(sim);
        if (fi > last_frame) {
          last_frame = fi;
          write_frame();
        }
      }
      if (s % scene.output.checkpoint_every == 0) checkpoint(s);
      if (s % every == 0) report_all(false);
    }
  } catch (const FillError& e) {
    history.flush();
    throw InputError(scene_file, e.what());
  } catch (const ProgrammeError& e) {
    history.flush();
    throw InputError(scene_file, e.what());
  } catch (const BlowUp& e) {
    history.flush();
    throw InputError(scene_file, std::string("blow-up: ") + e.what() +
                                     "; last good checkpoint at step " + ck["step"] + " in " +
                                     (out / ck["state"]).string());
  }
  const std::int64_t s = sim.step_count();
  const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  outcome.step = s;
  outcome.steps_run = s - first;
  outcome.particles = sim.particles().size();
  outcome.seconds = el;
  if (stop_requested && !ended) {
    // Stopped from outside: a checkpoint of this step, the outputs left as partial files; a
    // run with `resume` continues from here bit for bit.
    if (ck["step"] != std::to_string(s)) checkpoint(s);
    history.flush();
    outcome.stopped = true;
    print(scene.name + ": stopped at step " + std::to_string(s) + "; resume to continue");
    if (thrown) std::rethrow_exception(thrown);
    return outcome;
  }
  // Final rows and frame, unless the last step already wrote them (the whole state stays on
  // process 0 from here).
  if (par) par->gather(sim);
  if (s % scene.output.history_every != 0) history.append(history_row(sim, scene.output.track_ids));
  if (programmes[k]->name() != "preparation" && last_frame_step != s) write_frame_now();
  history.finish();
  curve.finish();
  prep_curve.finish();
  if (writer) writer->finish();
  RunResults results;
  if (ended) results = programmes[k]->results(sim);
  if (!results.empty()) write_run_results(out / "results.csv", results);
  // The index first: a kill from here on leaves a complete run, which --resume recognises.
  fs::remove(ckpt_index, ec);
  fs::remove(out / ck["state"], ec);
  fs::remove(scene_copy, ec);
  const double ps = static_cast<double>(s - first) * static_cast<double>(sim.particles().size());
  const auto& e = sim.energy();
  char buf[512];
  std::string how;  // (which count, and how it was picked)
  int threads = scene.config.threads;
  if (tuner) {
    // the count of most steps, and the share of the steps on each count
    std::int64_t all = 0, most = -1;
    for (const int c : tuner->counts()) all += tuner->steps_on(c);
    how = ", picked by timing: ";
    for (const int c : tuner->counts()) {
      const std::int64_t n = tuner->steps_on(c);
      if (n > most) {
        most = n;
        threads = c;
      }
      std::snprintf(
          buf, sizeof buf, "%s%.0f %%%s on %d", c == 1 ? "" : ", ",
          100.0 * static_cast<double>(n) / static_cast<double>(std::max<std::int64_t>(1, all)),
          c == 1 ? " of the steps" : "", c);
      how += buf;
    }
  } else if (threads_by_size) {
    how = ", picked by size";
  }
  std::snprintf(buf, sizeof buf,
                "%s: %lld steps of %zu particles in %.2f s (%.3g particle-steps/s, %d thread(s)%s)",
                scene.name.c_str(), static_cast<long long>(s - first), sim.particles().size(), el,
                ps / std::max(el, 1e-9), threads, how.c_str());
  print(buf);
  std::snprintf(
      buf, sizeof buf,
      "final: %zu contacts, unbalanced force %.3g, kinetic energy %.3g J, energy residual %.3g J "
      "(%.2g of the energy turnover)",
      sim.contact_count(), sim.unbalanced_force(), e.kinetic, e.residual(),
      std::abs(e.residual()) / std::max(1e-300, e.stored() + e.dissipated()));
  print(buf);
  // The files this run wrote (a run stopped by --steps during a preparation has no frame or
  // curve yet).
  std::string wrote;
  for (const fs::path& f :
       {traj, history.path(), prep_curve.path(), curve.path(), out / "results.csv"})
    if (fs::is_regular_file(f)) wrote += (wrote.empty() ? "wrote " : ", ") + f.string();
  if (!wrote.empty()) print(wrote);
  outcome.ended = ended;
  outcome.results = results;
  return outcome;
}

}  // namespace gs::solver
