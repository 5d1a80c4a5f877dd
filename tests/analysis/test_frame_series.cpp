// `granoscope analyze ... --frames A:B` (issue 23): the analyses of a range of frames, run in
// worker processes, in one output with a frame axis. Every frame's slice of the series equals
// the single-frame analysis of that frame exactly; ragged results are concatenated with
// offsets; bad ranges and failing frames are one error line, exit code 2, and no output.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cli_util.hpp"

namespace fs = std::filesystem;
using gs::test::read_array;
using gs::test::read_attr;
using gs::test::read_doubles;
using gs::test::read_format;
using gs::test::run;

namespace {

const fs::path kFall = fs::path(GS_TEST_DATA_DIR) / "scenes" / "oedometer_fall.toml";

/// The test scene of 883 spheres dropped in a box under slanted gravity: 7 frames (steps 0,
/// 1 000, …, 6 000), each with hundreds of contacts.
fs::path drop_run(const fs::path& dir) {
  EXPECT_EQ(run("simulate " + kFall.string() + " -q -o " + (dir / "run").string(), dir / "sim.log"),
            0);
  return dir / "run" / "oedometer_fall.h5";
}

std::string root_string_attr(const fs::path& file, const char* name) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t a = H5Aopen(f, name, H5P_DEFAULT);
  const hid_t t = H5Aget_type(a);
  std::string s;
  if (H5Tis_variable_str(t) > 0) {
    char* c = nullptr;
    const hid_t m = H5Tcopy(H5T_C_S1);
    H5Tset_size(m, H5T_VARIABLE);
    H5Aread(a, m, &c);
    s = c ? c : "";
    H5free_memory(c);
    H5Tclose(m);
  } else {
    s.assign(H5Tget_size(t), '\0');
    H5Aread(a, t, s.data());
    s = s.c_str();
  }
  H5Tclose(t);
  H5Aclose(a);
  H5Fclose(f);
  return s;
}

}  // namespace

// Fabric over frames 1, 3, 5 (--frames 1:7:2) with two workers: /frame, the stacked tensors
// and the per-frame attributes equal the single-frame runs of those frames to the bit.
TEST(FrameSeries, FabricOverFramesEqualsEachFrame) {
  const fs::path dir = gs::test::temp_dir("frame_series");
  const fs::path traj = drop_run(dir);
  const fs::path series = dir / "fabric.h5";
  ASSERT_EQ(
      run("analyze fabric " + traj.string() + " --frames 1:7:2 --jobs 2 -o " + series.string(),
          dir / "series.log"),
      0)
      << gs::test::slurp(dir / "series.log");
  EXPECT_EQ(read_format(series), "granoscope-series");
  EXPECT_EQ(root_string_attr(series, "of"), "granoscope-fabric");
  EXPECT_EQ(read_array<long long>(series, "/frame", H5T_NATIVE_LLONG),
            (std::vector<long long>{1, 3, 5}));
  const std::vector<double> m = read_doubles(series, "/M");
  const std::vector<double> omega = read_doubles(series, "/attributes/omega");
  const std::vector<double> bodies = read_doubles(series, "/attributes/orientation/bodies");
  ASSERT_EQ(m.size(), 27u);
  ASSERT_EQ(omega.size(), 3u);
  ASSERT_EQ(bodies.size(), 3u);
  double contacts = 0;
  for (int k = 0; k < 3; ++k) {
    const fs::path one = dir / ("f" + std::to_string(k) + ".h5");
    ASSERT_EQ(run("analyze fabric " + traj.string() + " --frame " + std::to_string(1 + 2 * k) +
                      " -o " + one.string(),
                  dir / "one.log"),
              0);
    const std::vector<double> m1 = read_doubles(one, "/M");
    for (int j = 0; j < 9; ++j) EXPECT_EQ(m[9 * k + j], m1[j]) << "frame " << 1 + 2 * k;
    EXPECT_EQ(omega[k], read_attr(one, "/", "omega"));
    contacts += read_attr(one, "/", "contacts");
  }
  EXPECT_GT(contacts, 100);  // (the frames are not empty)
  // No parts left beside the output.
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".fabric.h5.frames"), std::string::npos);
  fs::remove_all(dir);
}

// The strong-force network has a different number of chains in each frame: concatenated along
// the first axis, frame f's rows between offsets[f] and offsets[f + 1]; one worker and three
// give the same file contents.
TEST(FrameSeries, RaggedResultsAreConcatenatedWithOffsets) {
  const fs::path dir = gs::test::temp_dir("frame_series_ragged");
  const fs::path traj = drop_run(dir);
  const fs::path a = dir / "a.h5", b = dir / "b.h5";
  ASSERT_EQ(run("analyze chains " + traj.string() + " --frames -4: --jobs 1 -o " + a.string(),
                dir / "a.log"),
            0)
      << gs::test::slurp(dir / "a.log");
  ASSERT_EQ(run("analyze chains " + traj.string() + " --frames 3:7 --jobs 3 -o " + b.string(),
                dir / "b.log"),
            0);
  EXPECT_EQ(read_array<long long>(a, "/frame", H5T_NATIVE_LLONG),
            (std::vector<long long>{3, 4, 5, 6}));
  // Find a ragged dataset: its offsets run from 0 to its row count in 5 values.
  const hid_t f = H5Fopen(a.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  std::vector<std::string> ragged;
  H5Ovisit2(
      f, H5_INDEX_NAME, H5_ITER_INC,
      [](hid_t, const char* name, const H5O_info_t* info, void* data) -> herr_t {
        const std::string n = name;
        if (info->type == H5O_TYPE_DATASET && n.size() > 8 && n.ends_with("_offsets"))
          static_cast<std::vector<std::string>*>(data)->push_back("/" + n);
        return 0;
      },
      &ragged, H5O_INFO_BASIC);
  H5Fclose(f);
  ASSERT_FALSE(ragged.empty()) << "no ragged dataset in the chains series";
  for (const std::string& off : ragged) {
    const auto o = read_array<long long>(a, off.c_str(), H5T_NATIVE_LLONG);
    ASSERT_EQ(o.size(), 5u) << off;
    EXPECT_EQ(o.front(), 0);
    EXPECT_TRUE(std::is_sorted(o.begin(), o.end()));
    const std::string data = off.substr(0, off.size() - 8);
    const auto v = read_doubles(a, data.c_str());
    EXPECT_EQ(v.size() % static_cast<std::size_t>(std::max<long long>(o.back(), 1)), 0u) << data;
    EXPECT_EQ(v, read_doubles(b, data.c_str())) << data;
    EXPECT_EQ(o, read_array<long long>(b, off.c_str(), H5T_NATIVE_LLONG));
  }
  fs::remove_all(dir);
}

// Bad ranges, --frames with --frame or --csv, and a frame whose analysis fails: one line, exit
// code 2, no output and no parts left.
TEST(FrameSeries, BadRangesAndFailingFramesGiveOneLine) {
  const fs::path dir = gs::test::temp_dir("frame_series_bad");
  const fs::path traj = drop_run(dir);
  const fs::path out = dir / "o.h5";
  const std::string t = traj.string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"fabric " + t + " --frames 5:2", "error: " + t +
                                            ": --frames: no frame in the range (the "
                                            "trajectory has 7) (5:2)"},
      {"fabric " + t + " --frames a:3", "error: " + t + ": --frames: not an integer (a)"},
      {"fabric " + t + " --frames 1:3:0", "error: " + t +
                                              ": --frames: the step must be at "
                                              "least 1 (1:3:0)"},
      {"fabric " + t + " --frames 7", "error: " + t + ": --frames: expected A:B or A:B:S (7)"},
      {"fabric " + t + " --frames 1:3 --frame 2", "error: --frame excludes --frames"},
      {"fabric " + t + " --frames 1:3 --csv x.csv", "error: --csv excludes --frames"},
      {"rev " + t + " --frames 1:3 --cell 0", ""},
  };
  for (const auto& [args, want] : cases) {
    const fs::path log = dir / "log";
    EXPECT_EQ(run("analyze " + args + " -o " + out.string(), log), 2) << args;
    const std::string text = gs::test::slurp(log);
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << args << ": " << text;
    if (!want.empty()) {
      EXPECT_EQ(text, want + "\n") << args;
    } else {
      EXPECT_EQ(text.rfind("error: ", 0), 0u) << text;
    }
    EXPECT_FALSE(fs::exists(out)) << args;
  }
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".o.h5.frames"), std::string::npos);
  fs::remove_all(dir);
}
