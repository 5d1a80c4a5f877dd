// `granoscope simulate`: outputs, bit-for-bit resume after a kill, bad scenes.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include "../io/test_util.hpp"
#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"
#include "triangle_mesh.hpp"

namespace {

using gs::test::slurp;

const std::filesystem::path kData = GS_TEST_DATA_DIR;
const std::string kExe = std::string(GS_BINARY_DIR) + "/bin/granoscope";

int run(const std::string& args, std::string* err = nullptr) {
  const auto e =
      std::filesystem::temp_directory_path() / ("gs_sim_err_" + std::to_string(::getpid()));
  const int status =
      std::system((kExe + " " + args + " >/dev/null 2>" + e.string() + " </dev/null").c_str());
  if (err) *err = slurp(e);
  std::filesystem::remove(e);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

}  // namespace

TEST(Simulate, ResumeAfterKillIsBitForBitIdentical) {
  gs::test::ScratchDir dir("simulate");
  const std::string scene = (kData / "scenes" / "drop.toml").string();
  ASSERT_EQ(run("simulate " + scene + " -q -o " + (dir / "straight").string()), 0);

  const auto killed = dir / "killed";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int devnull = ::open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    dup2(devnull, 2);
    execl(kExe.c_str(), kExe.c_str(), "simulate", scene.c_str(), "-q", "-o", killed.c_str(),
          nullptr);
    _exit(127);
  }
  // Kill once a checkpoint past step 2000 is on disk, mid-run.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    const std::string idx = slurp(killed / "checkpoint.txt");
    const auto k = idx.find("\nstep ");
    if (k != std::string::npos && std::stol(idx.substr(k + 6)) >= 2000) break;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run finished before it could be killed";
  EXPECT_FALSE(std::filesystem::exists(killed / "drop.h5"));
  EXPECT_TRUE(std::filesystem::exists(killed / "drop.h5.partial"));
  // The partial trajectory is readable.
  EXPECT_GE(gs::TrajectoryReader(killed / "drop.h5.partial").frame_count(), 5u);

  ASSERT_EQ(run("simulate " + scene + " -q --resume -o " + killed.string()), 0);
  EXPECT_EQ(slurp(dir / "straight" / "history.csv"), slurp(killed / "history.csv"));
  const auto a = gs::read_hdf5_trajectory(dir / "straight" / "drop.h5");
  const auto b = gs::read_hdf5_trajectory(killed / "drop.h5");
  ASSERT_EQ(a.frames.size(), 17u);  // steps 0, 500, ..., 8000
  ASSERT_EQ(a.frames.size(), b.frames.size());
  std::size_t contacts = 0;
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    gs::test::expect_same_frame(a.frames[i], b.frames[i]);
    contacts += a.frames[i].contacts.size();
  }
  EXPECT_GT(contacts, 10u);  // contacts (with histories) are part of the comparison
  EXPECT_FALSE(std::filesystem::exists(killed / "checkpoint.txt"));  // cleaned up at the end
}

// A checkpoint of format 07 written by an older binary (84bdc0b, whose ContactHistory was 176 B
// in memory and written raw; today's is 152 B and writes the same record field by field) resumes
// bit for bit: tests/data/checkpoint_v07/run is that binary's oedometer_fall run killed after its
// checkpoint of step 3000, with about 1 200 contacts carrying shear forces and rolling moments.
// A record read with a field out of place changes the forces, and so the run.
TEST(Simulate, OlderCheckpointResumesBitForBit) {
  gs::test::ScratchDir dir("simulate_v07");
  const auto fixture = kData / "checkpoint_v07";
  const std::string scene = (fixture / "oedometer_fall.toml").string();
  std::filesystem::copy(fixture / "run", dir / "resumed");
  EXPECT_NE(slurp(dir / "resumed" / "checkpoint.txt").find("\nstep 3000"), std::string::npos);
  ASSERT_EQ(run("simulate " + scene + " -q --resume -o " + (dir / "resumed").string()), 0);
  ASSERT_EQ(run("simulate " + scene + " -q -o " + (dir / "straight").string()), 0);
  EXPECT_EQ(slurp(dir / "straight" / "history.csv"), slurp(dir / "resumed" / "history.csv"));
  const auto a = gs::read_hdf5_trajectory(dir / "straight" / "oedometer_fall.h5");
  const auto b = gs::read_hdf5_trajectory(dir / "resumed" / "oedometer_fall.h5");
  ASSERT_EQ(a.frames.size(), 2u);  // steps 0 and 6000
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i)
    gs::test::expect_same_frame(a.frames[i], b.frames[i]);
  EXPECT_GT(a.frames.back().contacts.size(), 1000u);
}

// Bad scenes: exit code 2 and exactly one line "error: FILE: key: what (value)" naming the scene
// file, the offending key and, where there is one, the offending value (docs/scenes.md; the
// TOML syntax error names the line of the edit instead of a key).
TEST(Simulate, BadScenesGiveOneLineAndExit2) {
  gs::test::ScratchDir dir("simulate_bad");
  const std::string good = slurp(kData / "scenes" / "drop.toml");
  std::filesystem::copy_file(kData / "scenes" / "drop_packing.csv", dir / "drop_packing.csv");
  std::size_t line = 0;  // line of the last edit
  auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string s = good;
    const auto k = s.find(from);
    EXPECT_NE(k, std::string::npos) << from;
    line = static_cast<std::size_t>(std::count(s.begin(), s.begin() + k, '\n')) + 1;
    s.replace(k, from.size(), to);
    std::ofstream(dir / name) << s;
    return (dir / name).string();
  };
  struct Case {
    std::string file, message;  // the message after "error: FILE: "
    bool prefix = false;        // the message continues (a parser's description)
  };
  const std::string missing = (dir / "missing.toml").string();
  std::vector<Case> cases = {
      {missing, "no such scene file"},
      {variant("young.toml", "young_Pa = 5.0e7", "young_Pa = -5.0e7"),
       "material.young_Pa: must be positive (-50000000)"},
      {variant("shape.toml", "shape = \"plane\"", "shape = \"sphere\""),
       "walls[0].shape: expected \"box\" or \"plane\" (sphere)"},
      {variant("nopack.toml", "drop_packing.csv", "nope.csv"),
       "scene.packing: no such file (" + (dir / "nope.csv").string() + ")"},
      {variant("damp.toml", "damping = 0.1", "damping = 1.5"),
       "solver.damping: outside [0, 1) (1.5)"},
      {variant("vec.toml", "normal = [0.0, 0.0, 1.0]", "normal = [0.0, 1.0]"),
       "walls[0].normal: expected an array of 3 numbers"},
      {variant("unit.toml", "young_Pa = 5.0e7", "young_MPa = 50.0"),
       "material.young_MPa: unknown key"},
      {variant("steps.toml", "steps = 8000", "steps = -5"),
       "solver.steps: must be at least 0 (-5)"},
      {variant("threads.toml", "threads = 1", "threads = \"many\""),
       "solver.threads: expected a number or \"auto\" (many)"},
      {variant("order.toml", "threads = 1", "order = \"hilbert\""),
       "solver.order: expected \"file\" or \"spatial\" (hilbert)"},
  };
  const std::string syntax = variant("syntax.toml", "[solver]", "[solver");
  cases.push_back({syntax, "TOML syntax error at line " + std::to_string(line) + " (", true});
  for (const auto& [file, what, prefix] : cases) {
    std::string err;
    EXPECT_EQ(run("simulate " + file + " -q -o " + (dir / "out").string(), &err), 2) << file;
    const std::string expected = "error: " + file + ": " + what;
    if (prefix)
      EXPECT_EQ(err.rfind(expected, 0), 0u) << err;
    else
      EXPECT_EQ(err, expected + "\n");
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
  // Resume without a checkpoint: the checkpoint index it looked for is named.
  std::string err;
  EXPECT_EQ(run("simulate " + (kData / "scenes" / "drop.toml").string() + " -q --resume -o " +
                    (dir / "empty").string(),
                &err),
            2);
  EXPECT_EQ(err, "error: " + (dir / "empty" / "checkpoint.txt").string() +
                     ": no checkpoint to resume from\n");
}

namespace {
std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> row;
    std::istringstream l(line);
    std::string field;
    while (std::getline(l, field, ',')) row.push_back(field);
    rows.push_back(row);
  }
  return rows;
}
}  // namespace

// --steps N stops the drop scene (which asks for 8000 steps) after exactly N = 1234 steps: the
// history has its rows at steps 0, 100, ..., 1200 and a last one at 1234; the trajectory its
// frames at 0, 500, 1000 and 1234, the last at time 1234·dt; the report says 1234 steps.
TEST(Simulate, StepsOptionRunsExactlyThatManySteps) {
  gs::test::ScratchDir dir("simulate_steps");
  const std::string scene = (kData / "scenes" / "drop.toml").string();
  const auto r = gs::test::run_cli(
      "simulate " + scene + " -q --steps 1234 -o " + (dir / "out").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("drop: 1234 steps of 150 particles"), std::string::npos) << r.out;
  const auto h = csv_rows(slurp(dir / "out" / "history.csv"));
  ASSERT_EQ(h.size(), 1u + 13u + 1u);  // header, steps 0..1200 every 100, step 1234
  EXPECT_EQ(h[0].at(0), "step");
  for (std::size_t i = 1; i + 1 < h.size(); ++i)
    EXPECT_EQ(h[i].at(0), std::to_string(100 * (i - 1)));
  EXPECT_EQ(h.back().at(0), "1234");
  const auto t = gs::read_hdf5_trajectory(dir / "out" / "drop.h5");
  ASSERT_EQ(t.frames.size(), 4u);
  const std::int64_t steps[4] = {0, 500, 1000, 1234};
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(t.frames[i].step, steps[i]);
  const double dt = t.frames.back().dt;
  EXPECT_NEAR(
      t.frames.back().time, 1234 * dt,
      1234 * std::numeric_limits<double>::epsilon() * (1234 * dt));  // a sum of 1234 steps dt
}

// --threads overrides the scene's thread count (the report says so), and the solver's results do
// not depend on it (docs/physics.md): with 1 and 2 threads the history and every trajectory
// frame (particles, contacts, walls) are identical bit for bit. The drop scene with gravity at
// 3000 m/s², so that the spheres pile up (~150 contacts by step 2000, where the runs stop).
TEST(Simulate, OneAndTwoThreadsWriteIdenticalOutputs) {
  gs::test::ScratchDir dir("simulate_threads");
  std::string text = slurp(kData / "scenes" / "drop.toml");
  const std::string g = "gravity_m_s2 = [0.0, 0.0, -9.81]";
  ASSERT_NE(text.find(g), std::string::npos);
  text.replace(text.find(g), g.size(), "gravity_m_s2 = [0.0, 0.0, -3000.0]");
  std::ofstream(dir / "pile.toml") << text;
  std::filesystem::copy_file(kData / "scenes" / "drop_packing.csv", dir / "drop_packing.csv");
  for (const char* n : {"1", "2"}) {
    const auto r =
        gs::test::run_cli("simulate " + (dir / "pile.toml").string() +
                              " -q --steps 2000 --threads " + n + " -o " + (dir / n).string(),
                          dir.path);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find(std::string(n) + " thread(s))"), std::string::npos) << r.out;
  }
  EXPECT_EQ(slurp(dir / "1" / "history.csv"), slurp(dir / "2" / "history.csv"));
  const auto a = gs::read_hdf5_trajectory(dir / "1" / "drop.h5");
  const auto b = gs::read_hdf5_trajectory(dir / "2" / "drop.h5");
  ASSERT_EQ(a.frames.size(), 5u);  // steps 0, 500, ..., 2000
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i)
    gs::test::expect_same_frame(a.frames[i], b.frames[i]);
  EXPECT_GT(a.frames.back().contacts.size(), 100u);  // the loads split between the threads
}

// `threads = "auto"` (and a scene without the key) starts on one thread below 5 000 particles
// and then picks by timing the steps (thread_tuner.hpp); 100 steps of 150 spheres end before the
// first window of 0.25 s does, so all on one thread. The summary line says so.
TEST(Simulate, AutoThreadsPickOneThreadForASmallScene) {
  gs::test::ScratchDir dir("simulate_auto_threads");
  std::string text = slurp(kData / "scenes" / "drop.toml");
  const std::string t = "threads = 1";
  ASSERT_NE(text.find(t), std::string::npos);
  std::filesystem::copy_file(kData / "scenes" / "drop_packing.csv", dir / "drop_packing.csv");
  for (const char* with : {"threads = \"auto\"", ""}) {
    std::string scene = text;
    scene.replace(scene.find(t), t.size(), with);
    std::ofstream(dir / "auto.toml") << scene;
    const auto r = gs::test::run_cli(
        "simulate " + (dir / "auto.toml").string() + " -q --steps 100 -o " + (dir / "o").string(),
        dir.path);
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("150 particles"), std::string::npos) << r.out;
    // (one core, as OpenMP sees the machine like the tool's machine_threads(): nothing to time)
    const bool cores = omp_get_num_procs() > 1;
    EXPECT_NE(r.out.find(cores ? ", 1 thread(s), picked by timing: 100 % of the steps on 1, 0 % on"
                               : ", 1 thread(s), picked by size)"),
              std::string::npos)
        << r.out;
  }
}

namespace {

void write_text(const std::filesystem::path& p, const std::string& s) {
  std::ofstream(p) << s;
}

/// The value of `column` in the last row of a history CSV (NaN, with a failure, if absent).
double last_history_value(const std::filesystem::path& history, const std::string& column) {
  std::istringstream in(slurp(history));
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::istringstream h(header), v(last);
  std::string hn, vv;
  while (std::getline(h, hn, ',') && std::getline(v, vv, ','))
    if (hn == column) return std::stod(vv);
  ADD_FAILURE() << "no column " << column << " in " << history;
  return std::nan("");
}

/// Each case (scene text appended to `base`, expected part of the message) fails with one line
/// containing the expected text, exit code 2.
void expect_one_line_errors(const std::filesystem::path& dir, const std::string& base,
                            const std::vector<std::pair<std::string, std::string>>& cases) {
  for (std::size_t k = 0; k < cases.size(); ++k) {
    std::string name = "case";
    name += std::to_string(k);
    name += ".toml";
    write_text(dir / name, base + cases[k].first);
    std::string err;
    EXPECT_EQ(run("simulate " + (dir / name).string() + " -q -o " + (dir / "o").string(), &err), 2)
        << k;
    EXPECT_NE(err.find(cases[k].second), std::string::npos) << k << ": " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << k << ": " << err;
  }
}

/// A floor of two 10 × 4 mm strips (4 triangles, ASCII STL, millimetres) with a 2 mm slot
/// between them along y at x ∈ [4, 6] mm.
std::string slotted_floor_stl() {
  auto facet = [](double x0, double y0, double x1, double y1, double x2, double y2) {
    std::ostringstream o;
    o << "facet normal 0 0 1\n outer loop\n  vertex " << x0 << " " << y0 << " 0\n  vertex " << x1
      << " " << y1 << " 0\n  vertex " << x2 << " " << y2 << " 0\n endloop\nendfacet\n";
    return o.str();
  };
  return "solid floor\n" + facet(0, 0, 4, 0, 4, 10) + facet(0, 0, 4, 10, 0, 10) +
         facet(6, 0, 10, 0, 10, 10) + facet(6, 0, 10, 10, 6, 10) + "endsolid floor\n";
}

}  // namespace

// Exact answer: 12 spheres of radius 0.8 mm at rest 3 mm above a slotted mesh floor; the six
// whose centres are over the 2 mm slot (x = 5 mm) fall through it and are removed below the
// outlet (z < −5 mm), the six over the strips come to rest on them. The history's last row
// counts 6 removed, of mass 6·ρ·(4/3)π r³, and the floor group carries the weight of the other
// six (Σ fz = −6·m·g once they rest, to 1e-6).
TEST(Simulate, MeshFloorWithAnOutletRemovesWhatFallsThrough) {
  gs::test::ScratchDir dir("sim_mesh_outlet");
  write_text(dir / "floor.stl", slotted_floor_stl());
  std::ostringstream packing;
  packing << "id,x,y,z,r\n";
  for (int i = 0; i < 12; ++i) {
    const double x = i < 6 ? 0.005 : (i < 9 ? 0.0015 : 0.0085);
    const double y = i < 6 ? 0.001 + 0.0016 * i : 0.002 + 0.003 * (i % 3);
    packing << i << "," << x << "," << y << ",0.003,0.0008\n";
  }
  write_text(dir / "packing.csv", packing.str());
  write_text(dir / "scene.toml", R"([scene]
name = "slot"
packing = "packing.csv"
[material]
young_Pa = 1.0e7
stiffness_ratio = 0.3
friction_deg = 30.0
density_kg_m3 = 2500.0
[solver]
dt_s = 2.0e-6
damping = 0.3
gravity_m_s2 = [0.0, 0.0, -9.81]
steps = 60000
[output]
trajectory = "slot.h5"
every = 20000
history_every = 1000
checkpoint_every = 60000
[[mesh]]
file = "floor.stl"
scale = 0.001
[outlet]
keep_lo_m = [-1.0, -1.0, -0.005]
keep_hi_m = [1.0, 1.0, 1.0]
)");
  std::string err;
  ASSERT_EQ(
      run("simulate " + (dir / "scene.toml").string() + " -q -o " + (dir / "out").string(), &err),
      0)
      << err;
  auto column = [&](const std::string& name) {
    return last_history_value(dir / "out" / "history.csv", name);
  };
  const double m = 2500.0 * 4.0 / 3.0 * M_PI * std::pow(0.0008, 3);
  EXPECT_EQ(column("removed"), 6.0);
  EXPECT_NEAR(column("removed_mass_kg"), 6 * m, 1e-15 * 6 * m);
  EXPECT_NEAR(column("floor_fz_N"), -6 * m * 9.81, 1e-6 * 6 * m * 9.81);
  const auto t = gs::read_hdf5_trajectory(dir / "out" / "slot.h5");
  EXPECT_EQ(t.frames.back().particles.size(), 6u);
}

// Bad [[mesh]] and [outlet] entries: one line naming the scene key (or the mesh file) and the
// value.
TEST(Simulate, BadMeshAndOutletNameTheKey) {
  gs::test::ScratchDir dir("sim_mesh_bad");
  write_text(dir / "floor.stl", slotted_floor_stl());
  write_text(dir / "nan.stl",
             "solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex nan 0 0\n  vertex "
             "0 1 0\n endloop\nendfacet\nendsolid x\n");
  write_text(dir / "packing.csv", "id,x,y,z,r\n0,0.005,0.005,0.003,0.0008\n");
  const std::string base =
      "[scene]\nname = \"b\"\npacking = \"packing.csv\"\n[material]\nyoung_Pa = 1e7\n"
      "stiffness_ratio = 0.3\nfriction_deg = 30.0\ndensity_kg_m3 = 2500.0\n"
      "[solver]\ndt_s = 1e-6\nsteps = 10\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[[mesh]]\nfile = \"none.stl\"\n", "mesh[0].file: no such file"},
      {"[[mesh]]\nfile = \"floor.stl\"\ncontact = \"glued\"\n",
       "mesh[0].contact: expected \"merged\" or \"yade\" (glued)"},
      {"[[mesh]]\nfile = \"floor.stl\"\nscale = -1.0\n", "mesh[0].scale"},
      {"[[mesh]]\nfile = \"nan.stl\"\n", "nan.stl: line 5: vertex coordinate is not finite (nan)"},
      {"[outlet]\nkeep_lo_m = [0.0, 0.0, 0.0]\nkeep_hi_m = [1.0, 1.0, -1.0]\n",
       "outlet.keep_hi_m: must exceed keep_lo_m"}};
  expect_one_line_errors(dir.path, base, cases);
}

// Exact answers: three dimers (two 1 mm spheres 1.4 mm apart, seed 003 §2.4's two-sphere clumps)
// with the true volume of the union (mass = ρ·(2·4/3·πr³ − lens), the lens of two spheres at
// distance 1.4 r) settle on a plane floor: once at rest the floor carries their weight, 3·M·g
// (to 1e-6), the members stay at 1.4 mm of each other (rigid to 1e-15 m), and the frames mark
// each member with its clump's id. (A single sphere settles beside them: its weight adds.)
TEST(Simulate, ClumpsFromTemplatesSettleWithTheirUnionWeight) {
  gs::test::ScratchDir dir("sim_clumps");
  write_text(dir / "packing.csv", "id,x,y,z,r\n0,0.05,0.05,0.05,0.001\n");  // a spectator sphere
  write_text(dir / "clumps.csv",
             "template,x,y,z,qw,qx,qy,qz\n"
             "dimer,0.0,0.0,0.003,1,0,0,0\n"
             "dimer,0.005,0.0,0.004,0.7071067811865476,0,0.7071067811865476,0\n"
             "dimer,0.0,0.006,0.002,0.9238795325112867,0.3826834323650898,0,0\n");
  const std::string scene = R"([scene]
name = "clumps"
packing = "packing.csv"
[material]
young_Pa = 1.0e7
stiffness_ratio = 0.3
friction_deg = 30.0
density_kg_m3 = 2500.0
[solver]
dt_s = 2.0e-6
damping = 0.4
gravity_m_s2 = [0.0, 0.0, -9.81]
steps = 150000
[output]
trajectory = "c.h5"
every = 50000
history_every = 50000
checkpoint_every = 150000
[[walls]]
name = "floor"
shape = "plane"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[walls]]
name = "roof"
shape = "plane"
point_m = [0.0, 0.0, 0.06]
normal = [0.0, 0.0, -1.0]
[[clump_template]]
name = "dimer"
members = [[-0.0007, 0.0, 0.0, 0.001], [0.0007, 0.0, 0.0, 0.001]]
[clumps]
packing = "clumps.csv"
mass = "union"
)";
  // And renumbered along a Morton curve ([solver] order = "spatial"): the spectator, listed
  // first, then comes last, and the clumps' members move to other rows with their clumps.
  for (const bool spatial : {false, true}) {
    write_text(dir / "scene.toml", spatial
                                       ? gs::test::replaced(scene, "steps = 150000\n",
                                                            "steps = 150000\norder = \"spatial\"\n")
                                       : scene);
    std::string err;
    ASSERT_EQ(
        run("simulate " + (dir / "scene.toml").string() + " -q -o " + (dir / "out").string(), &err),
        0)
        << err;
    const auto t = gs::read_hdf5_trajectory(dir / "out" / "c.h5");
    EXPECT_EQ(t.frames.front().particles.front().id == 0, !spatial);
    const auto& last = t.frames.back();
    ASSERT_EQ(last.particles.size(), 7u);
    std::map<std::int64_t, std::vector<Eigen::Vector3d>> members;
    for (const auto& p : last.particles)
      if (p.clump_id >= 0) members[p.clump_id].push_back(p.position);
    ASSERT_EQ(members.size(), 3u);
    for (const auto& [id, x] : members) {
      ASSERT_EQ(x.size(), 2u);
      EXPECT_NEAR((x[0] - x[1]).norm(), 0.0014, 1e-15) << id;
    }
    const double r = 0.001, d = 0.0014;
    const double lens = M_PI * std::pow(2 * r - d, 2) * (d * d + 4 * d * r) / (12 * d);
    const double m = 2500.0 * (2 * (4.0 / 3.0) * M_PI * r * r * r - lens);
    const double floor_fz = last_history_value(dir / "out" / "history.csv", "floor_fz_N");
    const double sphere = 2500.0 * (4.0 / 3.0) * M_PI * r * r * r;  // the spectator, settled too
    EXPECT_NEAR(floor_fz, -(3 * m + sphere) * 9.81, 1e-6 * (3 * m + sphere) * 9.81);
    std::filesystem::remove_all(dir / "out");
  }
}

// Bad clump input: one line naming the key or file, the field and the value.
TEST(Simulate, BadClumpsNameTheFieldAndValue) {
  gs::test::ScratchDir dir("sim_clumps_bad");
  write_text(dir / "packing.csv", "id,x,y,z,r\n0,0.05,0.05,0.05,0.001\n");
  write_text(dir / "ok.csv", "template,x,y,z,qw,qx,qy,qz\ndimer,0,0,0.003,1,0,0,0\n");
  write_text(dir / "unknown.csv", "template,x,y,z,qw,qx,qy,qz\ntrimer,0,0,0.003,1,0,0,0\n");
  const std::string base =
      "[scene]\nname = \"b\"\npacking = \"packing.csv\"\n[material]\nyoung_Pa = 1e7\n"
      "stiffness_ratio = 0.3\nfriction_deg = 30.0\ndensity_kg_m3 = 2500.0\n"
      "[solver]\ndt_s = 1e-6\nsteps = 10\n";
  const std::string dimer =
      "[[clump_template]]\nname = \"dimer\"\nmembers = [[-0.0007, 0.0, 0.0, 0.001], [0.0007, 0.0, "
      "0.0, 0.001]]\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[[clump_template]]\nname = \"dimer\"\nmembers = []\n[clumps]\npacking = \"ok.csv\"\n",
       "clump_template[0].members: a clump template needs member spheres"},
      {"[[clump_template]]\nname = \"dimer\"\nmembers = [[0.0, 0.0, 0.0, 0.0]]\n[clumps]\npacking "
       "= \"ok.csv\"\n",
       "clump_template[0].members[0]: member radius must be positive (0)"},
      {dimer + "[clumps]\npacking = \"unknown.csv\"\n",
       "unknown.csv: line 2: unknown clump template (trimer)"},
      {dimer + "[clumps]\npacking = \"ok.csv\"\nmass = \"heavy\"\n",
       "clumps.mass: expected \"member_sum\" or \"union\" (heavy)"}};
  expect_one_line_errors(dir.path, base, cases);
}

namespace {

/// Four plane walls around the 10 mm square x, y in [0, 0.01] (scene text).
std::string side_planes_10mm() {
  std::string walls;
  for (const char* w : {"point_m = [0.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]",
                        "point_m = [0.01, 0.0, 0.0]\nnormal = [-1.0, 0.0, 0.0]",
                        "point_m = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]",
                        "point_m = [0.0, 0.01, 0.0]\nnormal = [0.0, -1.0, 0.0]"})
    walls += std::string("[[walls]]\nshape = \"plane\"\n") + w + "\n";
  return walls;
}

}  // namespace

// Filling in layers, then the outlet opened (seed 004 §5.2's preparation and discharge): 3
// layers of 40 spheres fall onto a square mesh floor inside plane walls; the floor is switched
// off once the last layer has settled and every sphere then leaves through the outlet below it.
// The frames show the layers arriving (40, 80, 120 spheres in the scene), the history counts
// all 120 removed with their mass, and the filling ends before the discharge starts.
TEST(Simulate, FillInLayersThenOpenTheFloorAndDischargeEverything) {
  gs::test::ScratchDir dir("sim_fill");
  write_text(dir / "floor.stl",
             "solid floor\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 10 0 0\n  "
             "vertex 10 10 0\n endloop\nendfacet\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 "
             "0\n  vertex 10 10 0\n  vertex 0 10 0\n endloop\nendfacet\nendsolid floor\n");
  const std::string walls = side_planes_10mm();
  write_text(dir / "scene.toml", R"([scene]
name = "fill"
[material]
young_Pa = 1.0e6
stiffness_ratio = 0.3
friction_deg = 25.0
density_kg_m3 = 2550.0
[solver]
dt_s = 1.0e-5
damping = 0.3
gravity_m_s2 = [0.0, 0.0, -9.81]
steps = 20000
[output]
trajectory = "fill.h5"
every = 1000
history_every = 1000
checkpoint_every = 100000
[[mesh]]
file = "floor.stl"
scale = 0.001
off_after_fill = true
[fill]
region_lo_m = [0.0, 0.0, 0.006]
region_hi_m = [0.01, 0.01, 0.012]
layers = 3
count = 120
dmin_m = 0.0012
dmax_m = 0.0016
seed = 2
[outlet]
keep_lo_m = [-1.0, -1.0, -0.02]
keep_hi_m = [1.0, 1.0, 1.0]
)" + walls);
  std::string err;
  ASSERT_EQ(
      run("simulate " + (dir / "scene.toml").string() + " -q -o " + (dir / "out").string(), &err),
      0)
      << err;
  const auto t = gs::read_hdf5_trajectory(dir / "out" / "fill.h5");
  std::vector<std::size_t> counts;
  for (const auto& f : t.frames)
    if (counts.empty() || counts.back() != f.particles.size()) counts.push_back(f.particles.size());
  ASSERT_GE(counts.size(), 4u);
  EXPECT_EQ(counts[0], 40u);
  EXPECT_EQ(counts[1], 80u);
  EXPECT_EQ(counts[2], 120u);
  EXPECT_EQ(t.frames.back().particles.size(), 0u);  // all discharged
  const double removed = last_history_value(dir / "out" / "history.csv", "removed");
  EXPECT_EQ(removed, 120.0);
  // The four unnamed walls get columns of their own (wall0_fx_N …, by wall index).
  {
    std::istringstream in(slurp(dir / "out" / "history.csv"));
    std::string header, name;
    std::getline(in, header);
    std::istringstream h(header);
    std::set<std::string> names;
    while (std::getline(h, name, ',')) EXPECT_TRUE(names.insert(name).second) << name;
    EXPECT_TRUE(names.count("wall1_fx_N"));
  }
  double mass = 0;
  for (const auto& f : t.frames)
    if (f.particles.size() == 120u) {
      for (const auto& p : f.particles) mass += p.mass;
      break;
    }
  EXPECT_NEAR(last_history_value(dir / "out" / "history.csv", "removed_mass_kg"), mass,
              1e-12 * mass);
}

// A lattice-placed fill held by a lid that is a plain box wall, switched off when the fill has
// settled: every sphere was inserted at once (one layer, the first frame holds all 60) and all
// of them leave through the outlet under the lid.
TEST(Simulate, LatticeFillUnderALidWallThenDischarge) {
  gs::test::ScratchDir dir("sim_fill_lid");
  const std::string walls = side_planes_10mm();
  write_text(dir / "scene.toml", R"([scene]
name = "lid"
[material]
young_Pa = 1.0e6
stiffness_ratio = 0.3
friction_deg = 25.0
density_kg_m3 = 2550.0
[solver]
dt_s = 1.0e-5
damping = 0.0
gravity_m_s2 = [0.0, 0.0, -9.81]
steps = 20000
[output]
trajectory = "lid.h5"
every = 1000
history_every = 1000
checkpoint_every = 100000
[[walls]]
name = "lid"
shape = "box"
center_m = [0.005, 0.005, -0.001]
half_extents_m = [0.006, 0.006, 0.001]
off_after_fill = true
[fill]
region_lo_m = [0.0, 0.0, 0.002]
region_hi_m = [0.01, 0.01, 0.012]
layers = 1
count = 60
dmin_m = 0.0015
dmax_m = 0.0015
placement = "lattice"
damping = 0.3
[outlet]
keep_lo_m = [-1.0, -1.0, -0.02]
keep_hi_m = [1.0, 1.0, 1.0]
)" + walls);
  std::string err;
  ASSERT_EQ(
      run("simulate " + (dir / "scene.toml").string() + " -q -o " + (dir / "out").string(), &err),
      0)
      << err;
  const auto t = gs::read_hdf5_trajectory(dir / "out" / "lid.h5");
  ASSERT_GE(t.frames.size(), 3u);
  EXPECT_EQ(t.frames.front().particles.size(), 60u);
  EXPECT_EQ(t.frames.back().particles.size(), 0u);
  EXPECT_EQ(last_history_value(dir / "out" / "history.csv", "removed"), 60.0);
}

// A [fill] whose region cannot take a layer: one line saying how many fitted, exit 2.
TEST(Simulate, FillRegionTooSmallSaysHowManyFitted) {
  gs::test::ScratchDir dir("sim_fill_bad");
  write_text(dir / "floor.stl", slotted_floor_stl());
  const std::string base =
      "[scene]\nname = \"b\"\n[material]\nyoung_Pa = 1e7\n"
      "stiffness_ratio = 0.3\nfriction_deg = 30.0\ndensity_kg_m3 = 2500.0\n"
      "[solver]\ndt_s = 1e-6\nsteps = 10\ngravity_m_s2 = [0.0, 0.0, -9.81]\n";
  const std::string fill =
      "[fill]\nregion_lo_m = [0.0, 0.0, 0.0]\nregion_hi_m = [0.01, 0.01, 0.0025]\nlayers = 2\n"
      "dmin_m = 0.002\ndmax_m = 0.002\nmax_attempts = 500\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {fill + "count = 400\n", "fill.region_hi_m: the region takes "},
      {fill + "count = 400\n", " of the 200 particles of a layer"},
      {fill + "count = 1\n", "fill.count: must be at least 2 (1)"},
      {"[fill]\nregion_lo_m = [0.0, 0.0, 0.0]\nregion_hi_m = [0.01, 0.01, 0.0]\ncount = 10\n"
       "dmin_m = 0.001\ndmax_m = 0.001\n",
       "fill.region_hi_m: must exceed region_lo_m"},
      {fill + "count = 4\n[[mesh]]\nfile = \"floor.stl\"\noff_after_fill = 1\n",
       "mesh[0].off_after_fill: expected true or false"},
      {fill + "count = 4\nplacement = \"grid\"\n",
       "fill.placement: expected \"random\" or \"lattice\" (grid)"},
      {fill + "count = 4\ndamping = 1.0\n", "fill.damping: outside [0, 1) (1)"},
      {fill + "count = 4\nhold_steps = 0\n", "fill.hold_steps: must be at least 1 (0)"},
      {fill + "count = 4\nmax_steps = 500\nhold_steps = 501\n",
       "fill.hold_steps: more than max_steps (501)"},
      {fill + "count = 4\n[[walls]]\nshape = \"plane\"\npoint_m = [0.0, 0.0, 0.0]\n"
              "normal = [0.0, 0.0, 1.0]\noff_after_fill = \"yes\"\n",
       "walls[0].off_after_fill: expected true or false"},
      {fill + "count = 4\n[[walls]]\nshape = \"plane\"\npoint_m = [0.0, 0.0, 0.0]\n"
              "normal = [0.0, 0.0, 1.0]\noff_at_s = -0.5\n",
       "walls[0].off_at_s: must be >= 0 (-0.5)"}};
  expect_one_line_errors(dir.path, base, cases);
}

// Per-facet forces on request: the history gets a column triple per triangle, and the
// triangles' forces add up to their group's (the six spheres resting on the two strips).
TEST(Simulate, PerFacetForcesInTheHistoryAddUpToTheGroupForce) {
  gs::test::ScratchDir dir("sim_facet_forces");
  write_text(dir / "floor.stl", slotted_floor_stl());
  std::ostringstream packing;
  packing << "id,x,y,z,r\n";
  for (int i = 0; i < 6; ++i)
    packing << i << "," << (i < 3 ? 0.0015 : 0.0085) << "," << 0.002 + 0.003 * (i % 3)
            << ",0.001,0.0008\n";
  write_text(dir / "packing.csv", packing.str());
  write_text(dir / "scene.toml", R"([scene]
name = "ff"
packing = "packing.csv"
[material]
young_Pa = 1.0e7
stiffness_ratio = 0.3
friction_deg = 30.0
density_kg_m3 = 2500.0
[solver]
dt_s = 2.0e-6
damping = 0.3
gravity_m_s2 = [0.0, 0.0, -9.81]
steps = 20000
[output]
every = 20000
history_every = 1000
checkpoint_every = 20000
facet_forces = true
[[mesh]]
file = "floor.stl"
scale = 0.001
)");
  std::string err;
  ASSERT_EQ(
      run("simulate " + (dir / "scene.toml").string() + " -q -o " + (dir / "out").string(), &err),
      0)
      << err;
  const auto h = dir / "out" / "history.csv";
  double sum = 0;
  for (const char* w : {"floor:0.0", "floor:0.1", "floor:1.0", "floor:1.1"})
    sum += last_history_value(h, std::string(w) + "_fz_N");
  const double group = last_history_value(h, "floor_fz_N");
  const double m = 2500.0 * 4.0 / 3.0 * M_PI * std::pow(0.0008, 3);
  EXPECT_NEAR(group, -6 * m * 9.81, 1e-6 * 6 * m * 9.81);
  EXPECT_NEAR(sum, group, 1e-12 * std::abs(group));
  // The group's torque about the centre of the floor's bounding box (5, 5, 0) mm: the strips
  // carry three spheres each, symmetric about y = 5 mm and x = 5 mm: no net torque.
  EXPECT_NEAR(last_history_value(h, "floor_tx_Nm"), 0, 1e-9 * 6 * m * 9.81 * 0.005);
  EXPECT_NEAR(last_history_value(h, "floor_ty_Nm"), 0, 1e-9 * 6 * m * 9.81 * 0.005);
  // The trajectory's last frame holds the same per-triangle forces, summing to each wall's.
  const auto t = gs::read_hdf5_trajectory(dir / "out" / "trajectory.h5");
  const auto& f = t.frames.back();
  ASSERT_EQ(f.facet_loads.size(), 4u);
  double fz = 0;
  for (const auto& l : f.facet_loads) fz += l.force.z();
  EXPECT_NEAR(fz, group, 1e-12 * std::abs(group));
  for (const auto& w : f.walls) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& l : f.facet_loads)
      if (l.wall_id == w.id) sum += l.force;
    EXPECT_LT((sum - w.force).norm(), 1e-12 * 6 * m * 9.81) << w.id;
  }
}

// Bad mesh motion keys: one line naming the key and value.
TEST(Simulate, BadMeshMotionNamesTheKey) {
  gs::test::ScratchDir dir("sim_mesh_motion_bad");
  write_text(dir / "floor.stl", slotted_floor_stl());
  write_text(dir / "packing.csv", "id,x,y,z,r\n0,0.005,0.005,0.003,0.0008\n");
  const std::string base =
      "[scene]\nname = \"b\"\npacking = \"packing.csv\"\n[material]\nyoung_Pa = 1e7\n"
      "stiffness_ratio = 0.3\nfriction_deg = 30.0\ndensity_kg_m3 = 2500.0\n"
      "[solver]\ndt_s = 1e-6\nsteps = 10\n[[mesh]]\nfile = \"floor.stl\"\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"off_at_s = -1.0\n", "mesh[0].off_at_s: must be >= 0 (-1)"},
      {"servo = { stress_Pa = 1e3, area_m2 = 1e-4, gain_m_s_per_Pa = 1e-6, max_velocity_m_s = "
       "0.1, axis = [0.0, 0.0, 0.0] }\n",
       "mesh[0].servo.axis: must not be zero"},
      {"angular_velocity_rad_s = [0.0, 1.0]\n", "mesh[0].angular_velocity_rad_s"},
      {"off_after_fill = true\n", ": off_after_fill: there is no [fill] section"},
      {"[output]\nfacet_forces = \"yes\"\n", "output.facet_forces: expected true or false"}};
  expect_one_line_errors(dir.path, base, cases);
}

// Seed 003 §2.4's preparation in a scene: each sphere of the packing replaced by a clump of
// seed 004's four-sphere shape with the sphere's volume, randomly turned: the frames hold four
// members per sphere and the clump bodies, each weighing what its sphere weighed (true union
// volume, to the 2e-5 of the union's quadrature), centred where the sphere was at step 0.
TEST(Simulate, SpheresReplacedByEqualVolumeClumps) {
  gs::test::ScratchDir dir("sim_clump_replace");
  write_text(dir / "packing.csv",
             "id,x,y,z,r\n0,0.000,0.0,0.002,0.0010\n1,0.004,0.0,0.002,0.0008\n"
             "2,0.000,0.004,0.002,0.0009\n3,0.004,0.004,0.002,0.0011\n");
  write_text(dir / "scene.toml", R"([scene]
name = "replace"
packing = "packing.csv"
[material]
young_Pa = 1.0e7
stiffness_ratio = 0.3
friction_deg = 30.0
density_kg_m3 = 2650.0
[solver]
dt_s = 2.0e-6
damping = 0.4
gravity_m_s2 = [0.0, 0.0, -9.81]
steps = 2000
[output]
trajectory = "r.h5"
every = 1000
history_every = 1000
checkpoint_every = 2000
[[walls]]
name = "floor"
shape = "plane"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[clump_template]]
name = "sand"
shape = "asymmetric4"
diameter_m = 0.001
[clumps]
replace = "sand"
mass = "union"
seed = 3
)");
  std::string err;
  ASSERT_EQ(
      run("simulate " + (dir / "scene.toml").string() + " -q -o " + (dir / "out").string(), &err),
      0)
      << err;
  const auto t = gs::read_hdf5_trajectory(dir / "out" / "r.h5");
  const auto& f0 = t.frames.front();
  ASSERT_EQ(f0.particles.size(), 16u);
  ASSERT_EQ(f0.clumps.size(), 4u);
  const double r[4] = {0.0010, 0.0008, 0.0009, 0.0011};
  const Eigen::Vector3d x[4] = {
      {0, 0, 0.002}, {0.004, 0, 0.002}, {0, 0.004, 0.002}, {0.004, 0.004, 0.002}};
  for (std::size_t c = 0; c < 4; ++c) {
    const double m = 2650.0 * 4.0 / 3.0 * M_PI * std::pow(r[c], 3);
    EXPECT_NEAR(f0.clumps[c].mass, m, 2e-5 * m) << c;
    EXPECT_LT((f0.clumps[c].position - x[c]).norm(), 1e-5 * r[c]) << c;
    EXPECT_EQ(f0.clumps[c].template_name, "sand");
    int members = 0;
    for (const auto& p : f0.particles) members += p.clump_id == f0.clumps[c].id;
    EXPECT_EQ(members, 4);
  }
  // Different orientations.
  EXPECT_LT(std::abs(f0.clumps[0].orientation.dot(f0.clumps[1].orientation)), 0.999);
}

TEST(Simulate, BadClumpShapesAndReplacementNameTheKey) {
  gs::test::ScratchDir dir("sim_clump_replace_bad");
  write_text(dir / "packing.csv", "id,x,y,z,r\n0,0.05,0.05,0.05,0.001\n");
  write_text(dir / "ok.csv", "template,x,y,z,qw,qx,qy,qz\nsand,0,0,0.003,1,0,0,0\n");
  const std::string base =
      "[scene]\nname = \"b\"\npacking = \"packing.csv\"\n[material]\nyoung_Pa = 1e7\n"
      "stiffness_ratio = 0.3\nfriction_deg = 30.0\ndensity_kg_m3 = 2500.0\n"
      "[solver]\ndt_s = 1e-6\nsteps = 10\n";
  const std::string sand =
      "[[clump_template]]\nname = \"sand\"\nshape = \"asymmetric4\"\ndiameter_m = 0.001\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[[clump_template]]\nname = \"sand\"\nshape = \"potato\"\n[clumps]\nreplace = \"sand\"\n",
       "clump_template[0].shape: expected \"asymmetric4\" or \"dimer\" (potato)"},
      {"[[clump_template]]\nname = \"sand\"\nshape = \"asymmetric4\"\ndiameter_m = -1.0\n"
       "[clumps]\nreplace = \"sand\"\n",
       "clump_template[0].diameter_m: must be positive (-1)"},
      {sand + "[clumps]\nreplace = \"gravel\"\n",
       "clumps.replace: unknown clump template (gravel)"},
      {sand + "[clumps]\nreplace = \"sand\"\npacking = \"ok.csv\"\n",
       "clumps.replace: give either packing or replace"},
      {sand + "[clumps]\npacking = \"ok.csv\"\nseed = 2\n", "clumps.seed: only with replace"}};
  expect_one_line_errors(dir.path, base, cases);
}

// `granoscope surface`: seed 004 §5.2's rough silo wall (R_n = 1, d50 = 1.5 mm: h_g = 1.5 mm,
// s_g = 6 mm, α_g = 45°) as STL, 25 teeth over 15 cm: 6 triangles a tooth (ramp, vertical back
// face, land), tips at h_g, every normal into the material (+z side), and the area of the
// profile W·25·(h√2 + h + s − h) exactly; bad parameters: one line naming the output, no file.
TEST(Surface, SawToothWallAsStlForAScene) {
  gs::test::ScratchDir dir("surface");
  const auto stl = dir / "rough.stl";
  std::string err;
  ASSERT_EQ(run("surface sawtooth --length 0.15 --width 0.02 --height 0.0015 --spacing 0.006 "
                "--group wall -o " +
                    stl.string(),
                &err),
            0)
      << err;
  const gs::TriangleMesh m = gs::read_mesh(stl);
  ASSERT_EQ(m.triangles.size(), 150u);
  EXPECT_EQ(m.group_names.at(0), "wall");
  double area = 0, top = -1;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    area += gs::triangle_area(m, t);
    EXPECT_GE(gs::triangle_normal(m, t).z(), -1e-12) << t;
  }
  for (const auto& v : m.vertices) top = std::max(top, v.z());
  const double h = 0.0015, s = 0.006;
  EXPECT_NEAR(area, 0.02 * 25 * (h * std::sqrt(2.0) + h + s - h), 1e-12 * area);
  EXPECT_NEAR(top, h, 1e-15);
  ASSERT_EQ(run("surface sawtooth --length 0.15 --width 0.02 --height -0.0015 --spacing 0.006 -o " +
                    (dir / "bad.stl").string(),
                &err),
            2);
  EXPECT_NE(err.find("bad.stl: saw_tooth_wall: height_m must be finite and > 0 (-0.0015)"),
            std::string::npos)
      << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.stl"));
}

using gs::test::run_and_kill;

// Issue 15, resume edge cases: killed between the final renames (history already final, the
// trajectory still .partial) and with a checkpoint's temporary left behind, --resume finishes
// the run bit for bit and leaves no temporary; killed during the final cleanup, --resume says
// the run is complete; an edited scene is refused naming the keys (more steps are allowed); a
// second run into a directory in use is refused.
TEST(Simulate, ResumeEdgeCasesEditedScenesAndConcurrentRuns) {
  gs::test::ScratchDir dir("simulate_edges");
  const std::string scene = (kData / "scenes" / "drop.toml").string();
  ASSERT_EQ(run("simulate " + scene + " -q -o " + (dir / "straight").string()), 0);

  const auto killed = dir / "killed";
  ASSERT_TRUE(run_and_kill(scene, killed, 2000));
  std::filesystem::rename(killed / "history.csv.partial", killed / "history.csv");
  std::ofstream(killed / "checkpoint.txt.tmp-999999-0") << "half";
  std::string err;
  ASSERT_EQ(run("simulate " + scene + " -q --resume -o " + killed.string(), &err), 0) << err;
  EXPECT_EQ(slurp(dir / "straight" / "history.csv"), slurp(killed / "history.csv"));
  const auto a = gs::read_hdf5_trajectory(dir / "straight" / "drop.h5");
  const auto b = gs::read_hdf5_trajectory(killed / "drop.h5");
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i)
    gs::test::expect_same_frame(a.frames[i], b.frames[i]);
  for (const auto& e : std::filesystem::directory_iterator(killed))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();

  // Complete, with a checkpoint state the cleanup did not get to remove.
  std::ofstream(killed / "checkpoint-8000.bin") << "stale";
  const auto log = dir / "log";
  std::filesystem::create_directories(log);
  const auto done =
      gs::test::run_cli("simulate " + scene + " -q --resume -o " + killed.string(), log);
  EXPECT_EQ(done.rc, 0) << done.err;
  EXPECT_EQ(done.out, "drop: the run is complete (" + (killed / "drop.h5").string() +
                          "); nothing to resume\n");
  EXPECT_FALSE(std::filesystem::exists(killed / "checkpoint-8000.bin"));

  // An edited scene.
  const auto edited = dir / "edited";
  ASSERT_TRUE(run_and_kill(scene, edited, 2000));
  std::filesystem::copy_file(kData / "scenes" / "drop_packing.csv", dir / "drop_packing.csv");
  std::string text = slurp(scene);
  text.replace(text.find("damping = 0.1"), 13, "damping = 0.2");
  text.replace(text.find("friction_deg = 25.0"), 19, "friction_deg = 30.0");
  std::ofstream(dir / "drop.toml") << text;
  const auto refused = gs::test::run_cli(
      "simulate " + (dir / "drop.toml").string() + " -q --resume -o " + edited.string(), log);
  EXPECT_EQ(refused.rc, 2);
  EXPECT_EQ(refused.err, "error: " + (dir / "drop.toml").string() +
                             ": scene differs from the run being resumed (rerun without --resume) "
                             "(material.friction_deg, solver.damping)\n");
  std::string more = slurp(scene);
  more.replace(more.find("steps = 8000"), 12, "steps = 9000");
  std::ofstream(dir / "drop.toml") << more;
  EXPECT_EQ(
      run("simulate " + (dir / "drop.toml").string() + " -q --resume -o " + edited.string(), &err),
      0)
      << err;
  EXPECT_EQ(gs::read_hdf5_trajectory(edited / "drop.h5").frames.back().step, 9000);

  // Two runs into one directory (the first one long enough to be still running).
  std::string long_run = slurp(scene);
  long_run.replace(long_run.find("steps = 8000"), 12, "steps = 100000000");
  std::ofstream(dir / "long.toml") << long_run;
  const std::string long_scene = (dir / "long.toml").string();
  const auto busy = dir / "busy";
  const pid_t first = fork();
  ASSERT_GE(first, 0);
  if (first == 0) {
    const int devnull = ::open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    dup2(devnull, 2);
    execl(kExe.c_str(), kExe.c_str(), "simulate", long_scene.c_str(), "-q", "-o", busy.c_str(),
          nullptr);
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!std::filesystem::exists(busy / "checkpoint.txt") &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  const auto second = gs::test::run_cli("simulate " + scene + " -q -o " + busy.string(), log);
  int status = 0;
  const bool still_running = waitpid(first, &status, WNOHANG) == 0;
  kill(first, SIGKILL);
  waitpid(first, &status, 0);
  ASSERT_TRUE(still_running) << "the first run ended before the second started";
  EXPECT_EQ(second.rc, 2);
  EXPECT_EQ(second.err, "error: " + busy.string() +
                            ": output directory is in use by another simulate run (pid " +
                            std::to_string(first) + ")\n");
}

// Issue 15, item 9: with stderr a log rather than a terminal, a progress line when a phase starts
// and at each 10 % of it (the 8-minute plane-strain run of scripts/demo printed nothing); the
// oedometer scene of scripts/demo runs on a bare clone (its packing is shipped in data/).
TEST(Simulate, ProgressLinesInALogAndTheShippedOedometerPacking) {
  gs::test::ScratchDir dir("simulate_progress");
  const auto log = dir / "log";
  std::filesystem::create_directories(log);
  const auto r = gs::test::run_cli(
      "simulate " + (kData / "scenes" / "drop.toml").string() + " -o " + (dir / "run").string(),
      log);
  ASSERT_EQ(r.rc, 0) << r.err;
  std::vector<std::string> lines;
  std::istringstream in(r.err);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 11u) << r.err;
  EXPECT_EQ(lines.front().rfind("steps 1/1: step 0  0%  ", 0), 0u) << lines.front();
  for (std::size_t i = 1; i < lines.size(); ++i) {
    EXPECT_NE(lines[i].find("  " + std::to_string(10 * i) + "%  "), std::string::npos) << lines[i];
    EXPECT_NE(lines[i].find(" steps/s  ETA "), std::string::npos) << lines[i];
  }
  const auto q = gs::test::run_cli("simulate " + (kData / "scenes" / "drop.toml").string() +
                                       " -q -o " + (dir / "quiet").string(),
                                   log);
  EXPECT_EQ(q.err, "");

  const auto oed = gs::test::run_cli(std::string("simulate ") + GS_SOURCE_DIR +
                                         "/data/scenes/oedometer_yade.toml -q --steps 10 -o " +
                                         (dir / "oed").string(),
                                     log);
  EXPECT_EQ(oed.rc, 0) << oed.err;
  EXPECT_EQ(gs::TrajectoryReader(dir / "oed" / "oedometer_yade.h5").particle_count(0), 883u);
}

// Every scene shipped in data/scenes (the laptop and the paper sizes) reads, builds and takes a
// step: a key renamed in the schema, a file moved or a paper-size scene that no longer fits its
// region shows here, not hours into a run on a bigger box. Scenes that read the DEM8 inputs from
// ../shared are skipped, with a message, where that folder is absent.
TEST(Simulate, EveryShippedSceneLoadsAndSteps) {
  gs::test::ScratchDir dir("shipped");
  const std::filesystem::path scenes = std::filesystem::path(GS_SOURCE_DIR) / "data" / "scenes";
  const bool shared = std::filesystem::is_directory(std::filesystem::path(GS_SOURCE_DIR) / ".." /
                                                    "shared" / "dem8");
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(scenes))
    if (e.path().extension() == ".toml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 20u);
  int ran = 0;
  for (const auto& f : files) {
    if (!shared && slurp(f).find("shared/dem8") != std::string::npos) {
      std::printf("skipped %s: ../shared/dem8 is absent\n", f.filename().c_str());
      continue;
    }
    const auto out = dir / f.stem();
    const auto r =
        gs::test::run_cli("simulate " + f.string() + " -q --steps 1 -o " + out.string(), dir.path);
    EXPECT_EQ(r.rc, 0) << f.filename() << ": " << r.err;
    // (a history, or, for a scene with a [sweep], one per run in its folders)
    bool history = false;
    if (std::filesystem::is_directory(out))
      for (const auto& e : std::filesystem::recursive_directory_iterator(out))
        history = history || e.path().filename() == "history.csv";
    EXPECT_TRUE(history) << f.filename();
    std::filesystem::remove_all(out);
    ++ran;
  }
  EXPECT_GE(ran, 16);  // (the scenes without the DEM8 inputs)
}

// [output] track_ids: the history holds those particles' position and velocity, the same
// numbers the trajectory's frames hold at the same steps; a Hertz–Mindlin run adds its viscous
// dissipation column; an id that no particle has is one line naming the key.
TEST(Simulate, TrackedParticlesInTheHistory) {
  gs::test::ScratchDir dir("track");
  std::filesystem::copy_file(kData / "yade_hertz" / "packing.csv", dir / "packing.csv");
  std::string text = slurp(kData / "yade_hertz" / "scene.toml");
  text.replace(text.find("steps = 5000"), 12, "steps = 3000");
  text.replace(text.find("every = 2500"), 12, "every = 1000\ntrack_ids = [7, 200]");
  text.replace(text.find("history_every = 500"), 19, "history_every = 1000");
  write_text(dir / "t.toml", text);
  const auto r = gs::test::run_cli(
      "simulate " + (dir / "t.toml").string() + " -q -o " + (dir / "out").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  const auto traj = gs::read_hdf5_trajectory(dir / "out" / "trajectory.h5");
  const gs::Frame& last = traj.frames.back();
  ASSERT_EQ(last.step, 3000);
  for (const long id : {7L, 200L}) {
    const auto it = std::find_if(last.particles.begin(), last.particles.end(),
                                 [&](const gs::Particle& p) { return p.id == id; });
    ASSERT_NE(it, last.particles.end());
    const std::string p = "p" + std::to_string(id);
    const auto h = dir / "out" / "history.csv";
    EXPECT_EQ(last_history_value(h, p + "_x_m"), it->position.x());
    EXPECT_EQ(last_history_value(h, p + "_z_m"), it->position.z());
    EXPECT_EQ(last_history_value(h, p + "_vz_m_s"), it->velocity.z());
  }
  EXPECT_GT(last_history_value(dir / "out" / "history.csv", "viscous_dissipation_J"), 0.0);
  text.replace(text.find("track_ids = [7, 200]"), 20, "track_ids = [7, 240]");
  write_text(dir / "bad.toml", text);
  std::string err;
  EXPECT_EQ(run("simulate " + (dir / "bad.toml").string() + " -q -o " + (dir / "o").string(), &err),
            2);
  EXPECT_NE(err.find("output.track_ids: no particle with this id (240)"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

// [solver] order = "spatial" (DEM8's drum bed lists its grains in random spatial order): the
// rows renumbered along a Morton curve before the run, the particles themselves (ids, radii,
// masses) and their motion the same as in the file's order up to the order of the force sums
// (round-off), and a run resumed from a checkpoint bit for bit the straight one.
TEST(Simulate, SpatialOrderRenumbersTheRowsNotTheParticles) {
  gs::test::ScratchDir dir("spatial_order");
  std::filesystem::copy_file(kData / "scenes" / "drop_packing.csv", dir / "drop_packing.csv");
  std::string text = slurp(kData / "scenes" / "drop.toml");
  const std::string g = "gravity_m_s2 = [0.0, 0.0, -9.81]";
  text.replace(text.find(g), g.size(), "gravity_m_s2 = [0.0, 0.0, -3000.0]");
  text.replace(text.find("threads = 1"), 11, "threads = 1\norder = \"spatial\"");
  write_text(dir / "long.toml", text);  // 8000 steps
  text.replace(text.find("steps = 8000"), 12, "steps = 2000");
  write_text(dir / "spatial.toml", text);
  text.replace(text.find("\norder = \"spatial\""), 18, "");
  write_text(dir / "file.toml", text);
  auto simulate = [&](const std::string& scene, const std::string& out, const std::string& more) {
    const auto r = gs::test::run_cli(
        "simulate " + (dir / scene).string() + " -q " + more + " -o " + (dir / out).string(),
        dir.path);
    EXPECT_EQ(r.rc, 0) << r.err;
  };
  simulate("file.toml", "file", "");
  simulate("spatial.toml", "spatial", "");
  const auto a = gs::read_hdf5_trajectory(dir / "file" / "drop.h5");
  const auto b = gs::read_hdf5_trajectory(dir / "spatial" / "drop.h5");
  ASSERT_EQ(a.frames.size(), 5u);  // steps 0, 500, ..., 2000
  ASSERT_EQ(b.frames.size(), 5u);
  std::size_t moved_rows = 0;
  for (std::size_t i = 0; i < a.frames[0].particles.size(); ++i)
    moved_rows += a.frames[0].particles[i].id != b.frames[0].particles[i].id;
  EXPECT_GT(moved_rows, a.frames[0].particles.size() / 2);
  // At step 1000 (a frame every 500): later, the pile's chaos has grown the round-off (after
  // 2000 steps 2e-7 m: what any change in the last bits does, as the one-ulp twins measure).
  const gs::Frame& fa = a.frames[2];
  const gs::Frame& fb = b.frames[2];
  ASSERT_EQ(fa.step, 1000);
  ASSERT_EQ(fa.particles.size(), fb.particles.size());
  EXPECT_EQ(fa.contacts.size(), fb.contacts.size());
  EXPECT_GT(fa.contacts.size(), 40u);  // landed: forces summed from several contacts
  std::map<std::int64_t, const gs::Particle*> by_id;
  for (const auto& p : fa.particles) by_id[p.id] = &p;
  double dx = 0, dv = 0;
  for (const auto& q : fb.particles) {
    ASSERT_TRUE(by_id.count(q.id)) << q.id;
    const gs::Particle& p = *by_id[q.id];
    EXPECT_EQ(p.radius, q.radius);
    EXPECT_EQ(p.mass, q.mass);
    dx = std::max(dx, (p.position - q.position).norm());
    dv = std::max(dv, (p.velocity - q.velocity).norm());
  }
  // Radii about 1 mm, speeds about 0.1 m/s: round-off, not a different motion.
  EXPECT_LT(dx, 1e-12) << "m";
  EXPECT_LT(dv, 1e-9) << "m/s";
  EXPECT_GT(dx, 0.0);  // (the sums did change order)

  std::filesystem::create_directories(dir / "resume");
  gs::test::expect_resume_bit_for_bit(dir / "resume", (dir / "long.toml").string(), {2000},
                                      {"history.csv"}, "drop.h5");
}
