#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "../apps/cli_util.hpp"
#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "test_util.hpp"

using namespace gs;
using gs::test::random_frame;
using gs::test::ScratchDir;
using gs::test::with_clump_bodies;

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
  // Frames with different particle and contact counts, and an empty contact list; clump bodies
  // in the first and last frame only.
  t.frames = {with_clump_bodies(random_frame(50, 80, 1, 0.0), 1), random_frame(37, 0, 2, 0.5),
              with_clump_bodies(random_frame(61, 12, 3, 1.0), 3)};
  ASSERT_EQ(t.frames[0].clumps.size(), 13u);
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
  EXPECT_EQ(reader.clump_count(0), 13u);
  EXPECT_EQ(reader.clump_count(1), 0u);
  EXPECT_EQ(reader.clump_count(2), 16u);
  EXPECT_EQ(reader.schema_version(), kTrajectorySchemaVersion);
}

// tests/data/trajectory_v1.h5 was written by the schema_version 1 writer
// (tests/data/make_trajectory_v1.sh): it reads as before, with no clump bodies (its members keep
// their clump_id, as imported data), and resuming into it upgrades it to the current version.
TEST(Hdf5Trajectory, SchemaVersion1FilesReadWithoutClumpsAndUpgradeOnResume) {
  const auto v1 = std::filesystem::path(GS_TEST_DATA_DIR) / "trajectory_v1.h5";
  {
    TrajectoryReader r(v1);
    EXPECT_EQ(r.schema_version(), 1);
    ASSERT_EQ(r.frame_count(), 2u);
    EXPECT_EQ(r.clump_count(1), 0u);
    const Frame f = r.frame(1);
    EXPECT_EQ(f.time, 0.5);
    EXPECT_EQ(f.step, 1000);
    ASSERT_EQ(f.particles.size(), 3u);
    EXPECT_EQ(f.particles[1].position, Eigen::Vector3d(0.002, 0.001, 0.003));
    EXPECT_EQ(f.particles[1].clump_id, 7);
    EXPECT_EQ(f.particles[2].clump_id, -1);
    ASSERT_EQ(f.contacts.size(), 1u);
    EXPECT_EQ(f.contacts[0].normal_force, Eigen::Vector3d(0.25, 0, 0));
    ASSERT_EQ(f.walls.size(), 1u);
    EXPECT_TRUE(f.clumps.empty());
    EXPECT_EQ(r.metadata().provenance, "schema_version 1 fixture");
  }
  ScratchDir dir("h5v1");
  const auto path = dir / "run.h5";
  std::filesystem::copy_file(v1, partial_path(path));
  Frame extra = read_hdf5_trajectory(v1).frames[1];
  extra.time = 1.0;
  extra.particles[2].clump_id = 9;  // a second clump, of one sphere
  Clump a, b;
  a.id = 7;
  a.template_name = "dimer";
  a.mass = 2e-5;
  a.principal_inertia = {1e-12, 3e-12, 3e-12};
  b.id = 9;
  b.template_name = "single";
  b.mass = 1e-5;
  b.principal_inertia = {4e-12, 4e-12, 4e-12};
  extra.clumps = {a, b};
  {
    auto w = TrajectoryWriter::resume(path, 1, {.discard_unfinished = false});
    EXPECT_EQ(w.frames_written(), 1u);
    w.append(extra);
    w.finish();
  }
  TrajectoryReader r(path);
  EXPECT_EQ(r.schema_version(), kTrajectorySchemaVersion);
  ASSERT_EQ(r.frame_count(), 2u);
  EXPECT_EQ(r.clump_count(0), 0u);
  gs::test::expect_same_frame(read_hdf5_trajectory(v1).frames[0], r.frame(0));
  gs::test::expect_same_frame(extra, r.frame(1));
}

TEST(Hdf5Trajectory, ResumeKeepsTheClumpRowsOfTheKeptFrames) {
  ScratchDir dir("h5resume_clumps");
  const auto path = dir / "run.h5";
  std::vector<Frame> frames;
  for (unsigned i = 0; i < 4; ++i)
    frames.push_back(with_clump_bodies(random_frame(20 + i, 5, i + 1, 0.1 * i), i + 1));
  {
    TrajectoryWriter w(path, meta(), {.discard_unfinished = false});
    for (const auto& f : frames) w.append(f);
  }
  {
    auto w = TrajectoryWriter::resume(path, 2, {.discard_unfinished = false});
    w.append(frames[2]);
    w.append(frames[3]);
    w.finish();
  }
  const Trajectory r = read_hdf5_trajectory(path);
  ASSERT_EQ(r.frames.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) gs::test::expect_same_frame(frames[i], r.frames[i]);
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
  // Clump bodies: a template name over 64 bytes, a member without its body, a body without
  // members. Nothing is written.
  f = with_clump_bodies(random_frame(5, 2, 1), 1);
  f.clumps[0].template_name = std::string(65, 'x');
  EXPECT_EQ(error_of([&] { w.append(f); }), (dir / "x.h5").string() +
                                                ": clump template name longer than 64 bytes (" +
                                                std::string(65, 'x') + ")");
  f = with_clump_bodies(random_frame(5, 2, 1), 1);
  f.clumps.pop_back();
  EXPECT_THROW(w.append(f), InputError);
  f = with_clump_bodies(random_frame(5, 2, 1), 1);
  f.clumps.push_back(f.clumps[0]);
  f.clumps.back().id = 1000;
  EXPECT_EQ(error_of([&] { w.append(f); }),
            (dir / "x.h5").string() + ": clump has no member particle (1000)");
  EXPECT_EQ(w.frames_written(), 0u);
}

// A frame given in pieces (the solver's way to write a large frame without holding it whole)
// is the frame written whole, row for row; a bad piece is refused with the message the whole
// frame gets, and nothing of it is written.
TEST(Hdf5Trajectory, FrameInPiecesIsTheFrameWrittenWhole) {
  ScratchDir dir("h5pieces");
  const Frame whole = with_clump_bodies(random_frame(61, 40, 3, 1.0), 3);
  Frame head = whole;
  head.particles.clear();
  head.contacts.clear();
  // Pieces of 7 particles and 3 contacts (the particles run out first), and one empty piece.
  auto pieces_of = [](const Frame& f) {
    return [&f](std::size_t i, Frame& piece) {
      const std::size_t n = f.particles.size(), c = f.contacts.size();
      if (i == 2) return true;  // (an empty piece)
      const std::size_t j = i > 2 ? i - 1 : i;
      for (std::size_t k = 7 * j; k < std::min(n, 7 * j + 7); ++k)
        piece.particles.push_back(f.particles[k]);
      for (std::size_t k = 3 * j; k < std::min(c, 3 * j + 3); ++k)
        piece.contacts.push_back(f.contacts[k]);
      return 7 * j + 7 < n || 3 * j + 3 < c;
    };
  };
  const Frame after = random_frame(6, 0, 2);
  {
    TrajectoryWriter w(dir / "p.h5", meta());
    w.append(random_frame(5, 2, 1));
    w.append(head, pieces_of(whole));
    w.append(after);
    w.finish();
  }
  const Trajectory r = read_hdf5_trajectory(dir / "p.h5");
  ASSERT_EQ(r.frames.size(), 3u);
  gs::test::expect_same_frame(whole, r.frames[1]);
  gs::test::expect_same_frame(after, r.frames[2]);

  TrajectoryWriter w(dir / "q.h5", meta());
  Frame bad = whole;
  bad.particles[50].radius = 0;  // (in a later piece)
  std::string message = error_of([&] { TrajectoryWriter(dir / "r.h5", meta()).append(bad); });
  message.replace(message.find("r.h5"), 4, "q.h5");
  EXPECT_EQ(error_of([&] { w.append(head, pieces_of(bad)); }), message);
  EXPECT_NE(message.find("radius is not positive"), std::string::npos) << message;
  bad = whole;
  bad.particles[60].id = bad.particles[1].id;  // a duplicate across pieces
  EXPECT_EQ(error_of([&] { w.append(head, pieces_of(bad)); }),
            (dir / "q.h5").string() + ": duplicate particle id (" +
                std::to_string(bad.particles[1].id) + ")");
  bad = whole;
  bad.contacts[39].normal *= 2;
  EXPECT_NE(error_of([&] { w.append(head, pieces_of(bad)); }), "no error");
  Frame orphan = head;  // a body none of the pieces' particles belongs to
  orphan.clumps.push_back(orphan.clumps[0]);
  orphan.clumps.back().id = 1000;
  EXPECT_EQ(error_of([&] { w.append(orphan, pieces_of(whole)); }),
            (dir / "q.h5").string() + ": clump has no member particle (1000)");
  EXPECT_THROW(w.append(whole, pieces_of(whole)), std::invalid_argument);  // (rows in the head)
  EXPECT_EQ(w.frames_written(), 0u);
  w.append(head, pieces_of(whole));
  w.finish();
  const Trajectory q = read_hdf5_trajectory(dir / "q.h5");
  ASSERT_EQ(q.frames.size(), 1u);
  gs::test::expect_same_frame(whole, q.frames[0]);
}

// Debian's python3-h5py reads our files as plain arrays.
TEST(Hdf5Trajectory, ReadableByH5py) {
  ScratchDir dir("h5py");
  const auto path = dir / "run.h5";
  Trajectory t;
  t.metadata = meta();
  t.frames = {with_clump_bodies(random_frame(12, 4, 1), 1), random_frame(9, 3, 2)};
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
      "repr(float(f['particles/radius'][20])))\n"
      "k = f['clumps/template']\n"
      "print(k[0].decode(), len(k[2]), int(f['frames/clump_end'][-1]), "
      "repr(float(f['clumps/mass'][2])))\n";
  std::ofstream(dir / "read.py") << script;
  const std::string cmd =
      py + " " + (dir / "read.py").string() + " " + path.string() + " > " + out.string();
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(out);
  std::string fmt;
  int schema = 0, frames = 0;
  long long pend = 0, cend = 0;
  std::string y, r;
  std::string name0, kmass;
  int len2 = 0, kend = 0;
  in >> fmt >> schema >> frames >> pend >> cend >> y >> r >> name0 >> len2 >> kend >> kmass;
  EXPECT_EQ(fmt, "granoscope-trajectory");
  EXPECT_EQ(schema, kTrajectorySchemaVersion);
  EXPECT_EQ(frames, 2);
  EXPECT_EQ(pend, 21);
  EXPECT_EQ(cend, 7);
  EXPECT_EQ(std::stod(y), t.frames[1].particles[1].position.y());
  EXPECT_EQ(std::stod(r), t.frames[1].particles[8].radius);
  EXPECT_EQ(name0, "dimer");
  EXPECT_EQ(len2, 64);  // the longest template name fills the fixed-length string
  EXPECT_EQ(kend, 3);   // three clumps in frame 0, none in frame 1
  EXPECT_EQ(std::stod(kmass), t.frames[0].clumps[2].mass);
}

namespace {

// The datasets docs/format.md lists, group by group.
const std::vector<std::pair<std::string, std::vector<std::string>>> kDocumentedDatasets = {
    {"particles",
     {"id", "position", "radius", "velocity", "angular_velocity", "orientation", "rotation", "mass",
      "clump_id", "material_id"}},
    {"contacts",
     {"id1", "id2", "point", "normal", "normal_force", "shear_force", "bending_moment",
      "twisting_moment", "overlap"}},
    {"walls", {"id", "kind", "a", "b", "force", "torque"}},
    {"clumps",
     {"id", "template", "position", "orientation", "velocity", "angular_velocity", "mass",
      "principal_inertia"}},
    {"facet_loads", {"wall_id", "facet", "centroid", "force"}},
    {"frames",
     {"time", "step", "dt", "two_d", "domain_lo", "domain_hi", "periodic", "cell",
      "cell_velocity_gradient", "clump_end", "facet_end", "end"}},
};

}  // namespace

// docs/format.md: every array is chunked, shuffled, deflate-compressed and Fletcher-32
// checksummed. Exact answer: each documented dataset's creation property list holds exactly the
// pipeline shuffle -> deflate (level 1, the writer's default) -> Fletcher-32, in that order, on
// a chunked layout; and each group holds exactly the documented datasets.
TEST(Hdf5Trajectory, EveryDatasetIsChunkedShuffledDeflatedAndChecksummed) {
  ScratchDir dir("h5filters");
  const auto path = dir / "run.h5";
  Trajectory t;
  t.metadata = meta();
  t.frames = {with_clump_bodies(random_frame(40, 30, 1), 1), random_frame(41, 20, 2)};
  write_hdf5_trajectory(path, t);
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  int checked = 0;
  for (const auto& [group, names] : kDocumentedDatasets) {
    hid_t g = H5Gopen2(f, group.c_str(), H5P_DEFAULT);
    ASSERT_GE(g, 0) << group;
    H5G_info_t gi;
    ASSERT_GE(H5Gget_info(g, &gi), 0);
    EXPECT_EQ(gi.nlinks, names.size()) << group << ": undocumented or missing datasets";
    H5Gclose(g);
    for (const auto& n : names) {
      const std::string ds = "/" + group + "/" + n;
      hid_t d = H5Dopen2(f, ds.c_str(), H5P_DEFAULT);
      ASSERT_GE(d, 0) << ds;
      hid_t dcpl = H5Dget_create_plist(d);
      EXPECT_EQ(H5Pget_layout(dcpl), H5D_CHUNKED) << ds;
      ASSERT_EQ(H5Pget_nfilters(dcpl), 3) << ds;
      const H5Z_filter_t want[3] = {H5Z_FILTER_SHUFFLE, H5Z_FILTER_DEFLATE, H5Z_FILTER_FLETCHER32};
      for (unsigned k = 0; k < 3; ++k) {
        unsigned flags = 0, cd[8] = {};
        size_t ncd = 8;
        char name[64] = {};
        const H5Z_filter_t id =
            H5Pget_filter2(dcpl, k, &flags, &ncd, cd, sizeof name, name, nullptr);
        EXPECT_EQ(id, want[k]) << ds << " filter " << k << " (" << name << ")";
        if (id == H5Z_FILTER_DEFLATE) {
          ASSERT_GE(ncd, 1u);
          EXPECT_EQ(cd[0], 1u) << ds << ": deflate level";
        }
      }
      H5Pclose(dcpl);
      H5Dclose(d);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 49);
  H5Fclose(f);
}

namespace {

// File address and stored size of chunk `index` of a dataset.
std::pair<haddr_t, hsize_t> chunk_location(const std::filesystem::path& path, const char* ds,
                                           hsize_t index) {
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t d = H5Dopen2(f, ds, H5P_DEFAULT);
  hsize_t offset[2] = {};
  unsigned mask = 0;
  haddr_t addr = HADDR_UNDEF;
  hsize_t size = 0;
  hid_t sp = H5Dget_space(d);
  const herr_t rc = H5Dget_chunk_info(d, sp, index, offset, &mask, &addr, &size);
  H5Sclose(sp);
  H5Dclose(d);
  H5Fclose(f);
  if (rc < 0) return {HADDR_UNDEF, 0};
  return {addr, size};
}

void flip_byte(const std::filesystem::path& path, std::uint64_t at) {
  std::fstream io(path, std::ios::in | std::ios::out | std::ios::binary);
  io.seekg(static_cast<std::streamoff>(at));
  char c = 0;
  io.read(&c, 1);
  c = static_cast<char>(c ^ 0x5a);
  io.seekp(static_cast<std::streamoff>(at));
  io.write(&c, 1);
}

// Reads the whole /particles/position dataset; `edc` false disables checksum verification.
bool read_positions(const std::filesystem::path& path, bool edc, std::vector<double>& out) {
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t d = H5Dopen2(f, "/particles/position", H5P_DEFAULT);
  hid_t sp = H5Dget_space(d);
  out.assign(static_cast<std::size_t>(H5Sget_simple_extent_npoints(sp)), 0.0);
  H5Sclose(sp);
  hid_t dxpl = H5Pcreate(H5P_DATASET_XFER);
  H5Pset_edc_check(dxpl, edc ? H5Z_ENABLE_EDC : H5Z_DISABLE_EDC);
  const herr_t rc = H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, dxpl, out.data());
  H5Pclose(dxpl);
  H5Dclose(d);
  H5Fclose(f);
  return rc >= 0;
}

}  // namespace

// A flipped byte inside a chunk is caught by the Fletcher-32 checksum, never read silently:
// the reader throws one line naming the file and the dataset, `granoscope info` prints it as
// `error: ...` with exit code 2. Flipping a byte of the stored checksum itself (the chunk's
// last 4 bytes) leaves the data intact: with checksum verification disabled the read returns
// the written values bit for bit, with it enabled (the default) the read fails, so it is the
// checksum, not deflate, that detects the damage.
TEST(Hdf5Trajectory, FlippedChunkByteIsDetectedByTheChecksum) {
  ScratchDir dir("h5flip");
  const auto good = dir / "good.h5";
  Trajectory t;
  t.metadata = meta();
  t.frames = {random_frame(300, 50, 1)};
  write_hdf5_trajectory(good, t);
  const auto [addr, size] = chunk_location(good, "/particles/position", 0);
  ASSERT_NE(addr, HADDR_UNDEF);
  ASSERT_GT(size, 64u);
  std::vector<double> ref;
  ASSERT_TRUE(read_positions(good, true, ref));
  ASSERT_EQ(ref.size(), 900u);

  // Inside the compressed data.
  const auto data = dir / "data.h5";
  std::filesystem::copy_file(good, data);
  flip_byte(data, addr + size / 2);
  TrajectoryReader r(data);  // metadata and frame table are intact
  ASSERT_EQ(r.frame_count(), 1u);
  const std::string msg =
      data.string() + ": cannot read dataset (corrupt or truncated) (/particles/position)";
  EXPECT_EQ(error_of([&] { (void)r.frame(0); }), msg);
  gs::test::ScratchDir log("h5flip_log");
  const auto info = gs::test::run_cli("info " + data.string(), log.path);
  EXPECT_EQ(info.rc, 2);
  EXPECT_EQ(info.err, "error: " + msg + "\n");
  EXPECT_EQ(info.out, "");
  const auto conv =
      gs::test::run_cli("convert " + data.string() + " " + (dir / "out.vtu").string(), log.path);
  EXPECT_EQ(conv.rc, 2);
  EXPECT_EQ(conv.err, "error: " + msg + "\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "out.vtu"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out.vtp"));

  // In the stored checksum.
  const auto sum = dir / "sum.h5";
  std::filesystem::copy_file(good, sum);
  flip_byte(sum, addr + size - 2);
  std::vector<double> back;
  EXPECT_FALSE(read_positions(sum, true, back));
  ASSERT_TRUE(read_positions(sum, false, back));
  EXPECT_EQ(back, ref);
  EXPECT_EQ(error_of([&] { (void)TrajectoryReader(sum).frame(0); }),
            sum.string() + ": cannot read dataset (corrupt or truncated) (/particles/position)");
}

// Per-facet loads (docs/format.md, /facet_loads): exact round trip, frame by frame, including a
// frame without them; a load naming a missing wall is rejected with one line.
TEST(Hdf5Trajectory, FacetLoadsRoundTripExactly) {
  ScratchDir dir("h5facets");
  Trajectory t;
  t.metadata = meta();
  t.frames = {random_frame(10, 5, 1), random_frame(12, 4, 2), random_frame(9, 3, 3)};
  for (int k : {0, 2}) {
    auto& f = t.frames[static_cast<std::size_t>(k)];
    gs::Wall w;
    w.id = 1000 + k;
    w.kind = gs::WallKind::Facet;
    f.walls.push_back(w);
    for (int j = 0; j < 3 + k; ++j) {
      gs::FacetLoad l;
      l.wall_id = w.id;
      l.facet = j;
      l.centroid = Eigen::Vector3d(0.1 * j, -0.2, 1.0 / 3.0 + k);
      l.force = Eigen::Vector3d(std::sqrt(2.0) * j, -1e-9, M_PI * k);
      f.facet_loads.push_back(l);
    }
  }
  write_hdf5_trajectory(dir / "f.h5", t);
  const auto r = read_hdf5_trajectory(dir / "f.h5");
  ASSERT_EQ(r.frames.size(), 3u);
  EXPECT_EQ(r.frames[1].facet_loads.size(), 0u);
  for (int k : {0, 2}) {
    const auto& a = t.frames[static_cast<std::size_t>(k)].facet_loads;
    const auto& b = r.frames[static_cast<std::size_t>(k)].facet_loads;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t j = 0; j < a.size(); ++j) {
      EXPECT_EQ(a[j].wall_id, b[j].wall_id);
      EXPECT_EQ(a[j].facet, b[j].facet);
      EXPECT_EQ(a[j].centroid, b[j].centroid);
      EXPECT_EQ(a[j].force, b[j].force);
    }
  }
  Frame bad = t.frames[0];
  bad.facet_loads[1].wall_id = 77;
  try {
    gs::validate_frame(bad, "x.h5 frame 0");
    FAIL() << "accepted a load on a missing wall";
  } catch (const gs::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("facet load names a missing wall (77)"), std::string::npos)
        << e.what();
  }
}
