#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "test_util.hpp"

using namespace gs;
using gs::test::random_frame;
using gs::test::ScratchDir;

namespace {

RunMetadata meta() {
  RunMetadata m;
  m.provenance = "unit test";
  m.parameters = {{"scene", "oedometer"}, {"young_Pa", "3e7"}, {"walls.top.velocity", "0 0 -0.05"}};
  return m;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(Hdf5Trajectory, RoundTripsEveryFieldExactly) {
  ScratchDir dir("h5rt");
  Trajectory t;
  t.metadata = meta();
  // Frames with different particle and contact counts, and an empty contact list.
  t.frames = {random_frame(50, 80, 1, 0.0), random_frame(37, 0, 2, 0.5),
              random_frame(61, 12, 3, 1.0)};
  const auto path = dir / "run.h5";
  write_hdf5_trajectory(path, t);
  EXPECT_FALSE(std::filesystem::exists(partial_path(path)));
  const Trajectory r = read_hdf5_trajectory(path);
  ASSERT_EQ(r.frames.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) gs::test::expect_same_frame(t.frames[i], r.frames[i]);
  EXPECT_EQ(r.metadata.provenance, "unit test");
  EXPECT_EQ(r.metadata.code_version, code_version());
  EXPECT_EQ(r.metadata.parameters, t.metadata.parameters);  // creation order kept
  TrajectoryReader reader(path);
  EXPECT_EQ(reader.particle_count(1), 37u);
  EXPECT_EQ(reader.contact_count(0), 80u);
  EXPECT_EQ(reader.time(2), 1.0);
}

TEST(Hdf5Trajectory, UnfinishedWriterKeepsCompletedFramesAndDiscardsWhenAsked) {
  ScratchDir dir("h5partial");
  const auto path = dir / "run.h5";
  {
    TrajectoryWriter w(path, meta(), {.discard_unfinished = false});
    w.append(random_frame(10, 5, 1));
    w.append(random_frame(11, 6, 2));
    // Readable while still open for writing.
    TrajectoryReader r(partial_path(path));
    EXPECT_EQ(r.frame_count(), 2u);
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_EQ(TrajectoryReader(partial_path(path)).frame_count(), 2u);
  {
    TrajectoryWriter w(dir / "tmp.h5", meta());  // default: discard unfinished
    w.append(random_frame(10, 5, 1));
  }
  EXPECT_FALSE(std::filesystem::exists(partial_path(dir / "tmp.h5")));
  EXPECT_FALSE(std::filesystem::exists(dir / "tmp.h5"));
}

TEST(Hdf5Trajectory, ResumeTruncatesToCheckpointAndAppends) {
  ScratchDir dir("h5resume");
  const auto path = dir / "run.h5";
  std::vector<Frame> frames;
  for (unsigned i = 0; i < 5; ++i) frames.push_back(random_frame(20 + i, 10 + i, i + 1, 0.1 * i));
  {
    TrajectoryWriter w(path, meta(), {.discard_unfinished = false});
    for (const auto& f : frames) w.append(f);
  }
  {
    auto w = TrajectoryWriter::resume(path, 3, {.discard_unfinished = false});
    EXPECT_EQ(w.frames_written(), 3u);
    w.append(frames[3]);
    w.append(frames[4]);
    w.finish();
  }
  const Trajectory r = read_hdf5_trajectory(path);
  ASSERT_EQ(r.frames.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) gs::test::expect_same_frame(frames[i], r.frames[i]);
}

// A writer process killed at an arbitrary moment leaves a file in which every frame it had
// completed is readable and intact.
TEST(Hdf5Trajectory, KilledWriterLeavesCompletedFramesReadable) {
  ScratchDir dir("h5kill");
  const auto path = dir / "run.h5";
  for (int trial = 0; trial < 4; ++trial) {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      close(fds[0]);
      try {
        TrajectoryWriter w(path, meta(), {.discard_unfinished = false});
        for (unsigned i = 0;; ++i) {
          w.append(random_frame(3000, 6000, i % 7 + 1, i));
          char c = 'f';
          if (write(fds[1], &c, 1) != 1) _exit(3);
        }
      } catch (...) {
        _exit(4);
      }
    }
    close(fds[1]);
    // Wait for a few completed frames, then kill mid-write (the child never stops writing).
    const int wait_frames = 3 + trial;
    int got = 0;
    char c;
    while (got < wait_frames && read(fds[0], &c, 1) == 1) ++got;
    usleep(1000u * static_cast<unsigned>(trial * 7 % 11));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    while (read(fds[0], &c, 1) == 1) ++got;  // frames reported before the kill landed
    close(fds[0]);
    ASSERT_TRUE(WIFSIGNALED(status)) << "writer child failed on its own";
    TrajectoryReader r(partial_path(path));
    EXPECT_GE(r.frame_count(), static_cast<std::size_t>(got));
    for (std::size_t i = 0; i < r.frame_count(); ++i) {
      const Frame f = r.frame(i);
      gs::test::expect_same_frame(random_frame(3000, 6000, i % 7 + 1, static_cast<double>(i)), f);
    }
  }
}

TEST(Hdf5Trajectory, RejectsBadFilesWithOneClearMessage) {
  ScratchDir dir("h5bad");
  const auto good = dir / "good.h5";
  Trajectory t;
  t.metadata = meta();
  t.frames = {random_frame(30, 20, 1), random_frame(30, 20, 2)};
  write_hdf5_trajectory(good, t);

  EXPECT_EQ(error_of([&] { TrajectoryReader r(dir / "missing.h5"); }),
            (dir / "missing.h5").string() + ": no such file");

  // Truncated at several lengths.
  const auto size = std::filesystem::file_size(good);
  for (double frac : {0.05, 0.3, 0.6, 0.95}) {
    const auto cut = dir / "cut.h5";
    std::filesystem::copy_file(good, cut, std::filesystem::copy_options::overwrite_existing);
    std::filesystem::resize_file(cut,
                                 static_cast<std::uintmax_t>(frac * static_cast<double>(size)));
    const std::string e = error_of([&] { read_hdf5_trajectory(cut); });
    EXPECT_EQ(e.rfind(cut.string() + ": ", 0), 0u) << e;
  }

  // Wrong schema version.
  {
    const auto bad = dir / "schema.h5";
    std::filesystem::copy_file(good, bad);
    hid_t f = H5Fopen(bad.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    hid_t a = H5Aopen(f, "schema_version", H5P_DEFAULT);
    const long long v = 99;
    H5Awrite(a, H5T_NATIVE_LLONG, &v);
    H5Aclose(a);
    H5Fclose(f);
    EXPECT_EQ(error_of([&] { TrajectoryReader r(bad); }),
              bad.string() + ": unsupported schema_version (99)");
  }

  // NaN and negative radius written behind the library's back.
  for (double bad_r : {std::nan(""), -1e-3}) {
    const auto bad = dir / "radius.h5";
    std::filesystem::copy_file(good, bad, std::filesystem::copy_options::overwrite_existing);
    hid_t f = H5Fopen(bad.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t d = H5Dopen2(f, "/particles/radius", H5P_DEFAULT);
    hid_t fs = H5Dget_space(d);
    const hsize_t start = 35, count = 1;  // frame 1, particle 5
    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &start, nullptr, &count, nullptr);
    hid_t ms = H5Screate_simple(1, &count, nullptr);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, ms, fs, H5P_DEFAULT, &bad_r);
    H5Sclose(ms);
    H5Sclose(fs);
    H5Dclose(d);
    H5Fclose(f);
    TrajectoryReader r(bad);
    EXPECT_NO_THROW(r.frame(0));
    const std::string e = error_of([&] { r.frame(1); });
    const std::string id = std::to_string(t.frames[1].particles[5].id);
    EXPECT_EQ(e.rfind(bad.string() + " frame 1: particle " + id + " radius", 0), 0u) << e;
  }

  // Not HDF5 at all.
  {
    const auto txt = dir / "text.h5";
    std::ofstream(txt) << "id,x,y,z,r\n";
    EXPECT_EQ(error_of([&] { TrajectoryReader r(txt); }),
              txt.string() + ": not an HDF5 file (bad signature)");
  }
}

TEST(Hdf5Trajectory, WriterRejectsInvalidFrames) {
  ScratchDir dir("h5inv");
  TrajectoryWriter w(dir / "x.h5", meta());
  Frame f = random_frame(5, 2, 1);
  f.particles[2].radius = 0;
  EXPECT_THROW(w.append(f), InputError);
  f = random_frame(5, 2, 1);
  f.particles[3].id = f.particles[1].id;
  EXPECT_THROW(w.append(f), InputError);
  EXPECT_EQ(w.frames_written(), 0u);
}

// Debian's python3-h5py reads our files as plain arrays.
TEST(Hdf5Trajectory, ReadableByH5py) {
  ScratchDir dir("h5py");
  const auto path = dir / "run.h5";
  Trajectory t;
  t.metadata = meta();
  t.frames = {random_frame(12, 4, 1), random_frame(9, 3, 2)};
  write_hdf5_trajectory(path, t);
  const char* py_env = std::getenv("GRANOSCOPE_PYTHON");
  const std::string py = py_env && *py_env ? py_env : "/usr/bin/python3";
  const auto out = dir / "py.txt";
  const std::string script =
      "import h5py, sys\n"
      "f = h5py.File(sys.argv[1], 'r')\n"
      "print(f.attrs['format'].decode() if isinstance(f.attrs['format'], bytes) else "
      "f.attrs['format'])\n"
      "print(int(f.attrs['schema_version']))\n"
      "e = f['frames/end'][:]\n"
      "print(len(e), int(e[-1][0]), int(e[-1][1]))\n"
      "print(repr(float(f['particles/position'][13][1])), "
      "repr(float(f['particles/radius'][20])))\n";
  std::ofstream(dir / "read.py") << script;
  const std::string cmd =
      py + " " + (dir / "read.py").string() + " " + path.string() + " > " + out.string();
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(out);
  std::string fmt;
  int schema = 0, frames = 0;
  long long pend = 0, cend = 0;
  std::string y, r;
  in >> fmt >> schema >> frames >> pend >> cend >> y >> r;
  EXPECT_EQ(fmt, "granoscope-trajectory");
  EXPECT_EQ(schema, kTrajectorySchemaVersion);
  EXPECT_EQ(frames, 2);
  EXPECT_EQ(pend, 21);
  EXPECT_EQ(cend, 7);
  EXPECT_EQ(std::stod(y), t.frames[1].particles[1].position.y());
  EXPECT_EQ(std::stod(r), t.frames[1].particles[8].radius);
}
