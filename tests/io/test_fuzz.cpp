// Bounded mutation fuzzing of every reader: each fixture is bit-flipped and truncated, and each
// mutant must give either a valid result or an InputError — no crash, no hang, no other error.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "errors.hpp"
#include "test_util.hpp"
#include "trajectory_io.hpp"

using namespace gs;

namespace {

const std::filesystem::path kData = GS_TEST_DATA_DIR;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void spit(const std::filesystem::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary | std::ios::trunc)
      .write(s.data(), static_cast<std::streamsize>(s.size()));
}

struct Outcome {
  int ok = 0, rejected = 0;
};

// Mutates `victim` (a copy inside dir) `rounds` times and reads `entry` each time.
Outcome fuzz(const std::filesystem::path& victim, const std::filesystem::path& entry, int rounds,
             unsigned seed) {
  const std::string original = slurp(victim);
  std::mt19937 rng(seed);
  Outcome out;
  for (int k = 0; k < rounds; ++k) {
    std::string m = original;
    switch (k % 4) {
      case 0:  // a few bit flips anywhere
      case 1: {
        const int flips = 1 + static_cast<int>(rng() % 8);
        for (int f = 0; f < flips && !m.empty(); ++f)
          m[rng() % m.size()] ^= static_cast<char>(1u << (rng() % 8));
        break;
      }
      case 2:  // truncation
        m.resize(rng() % (m.size() + 1));
        break;
      case 3: {  // a run of random bytes
        if (m.empty()) break;
        const std::size_t at = rng() % m.size(), len = 1 + rng() % 16;
        for (std::size_t i = at; i < std::min(m.size(), at + len); ++i)
          m[i] = static_cast<char>(rng());
        break;
      }
    }
    spit(victim, m);
    try {
      const Trajectory t = read_snapshots(entry);
      for (const auto& f : t.frames) validate_frame(f, "mutant");  // a valid result
      ++out.ok;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_FALSE(msg.empty());
      EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
      ++out.rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << victim << " mutant " << k << ": unexpected " << typeid(e).name() << ": "
                    << e.what();
    }
  }
  spit(victim, original);
  return out;
}

}  // namespace

class Fuzz : public ::testing::TestWithParam<std::vector<std::string>> {};

// Parameters: files copied into a scratch directory; the first is read, the last is mutated.
TEST_P(Fuzz, MutantsAreRejectedOrValid) {
  const auto files = GetParam();
  gs::test::ScratchDir dir("fuzz");
  for (const auto& f : files)
    std::filesystem::copy_file(kData / f, dir / std::filesystem::path(f).filename().string());
  const auto entry = dir / std::filesystem::path(files.front()).filename().string();
  const auto victim = dir / std::filesystem::path(files.back()).filename().string();
  const Outcome o = fuzz(victim, entry, 120, 12345u + static_cast<unsigned>(files.back().size()));
  EXPECT_GT(o.rejected, 0) << "mutations never detected";
  RecordProperty("ok", o.ok);
  RecordProperty("rejected", o.rejected);
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, Fuzz,
    ::testing::Values(std::vector<std::string>{"packing_small.csv"},
                      std::vector<std::string>{"yade/yade_spheres.20000.vtu"},
                      std::vector<std::string>{"yade/yade_export-spheres-00000000.vtk"},
                      std::vector<std::string>{"yade/yade_export-spheres-00000000.vtk",
                                               "yade/yade_export-intrs-00000000.vtk"},
                      std::vector<std::string>{"liggghts/dump.atoms"},
                      std::vector<std::string>{"liggghts/dump.atoms", "liggghts/dump.pairs"}));

// Our own binary formats, made on the fly.
TEST(FuzzOwnFormats, Hdf5VtuVtpPvd) {
  gs::test::ScratchDir dir("fuzz_own");
  Trajectory t;
  t.frames = {gs::test::random_frame(30, 20, 1, 0.0), gs::test::random_frame(25, 10, 2, 1.0)};
  for (auto& f : t.frames) f.walls.clear();
  write_snapshots(dir / "run.h5", t);
  write_snapshots(dir / "one.vtu", t);
  write_snapshots(dir / "series.pvd", t);
  for (const auto& [entry, victim] : std::vector<std::pair<std::string, std::string>>{
           {"run.h5", "run.h5"},
           {"one.vtu", "one.vtu"},
           {"one.vtu", "one.vtp"},
           {"series.pvd", "series.pvd"},
           {"series.pvd", "series_files/particles_000001.vtu"}}) {
    const Outcome o = fuzz(dir / victim, dir / entry, 120, 777u);
    EXPECT_GT(o.rejected, 0) << victim;
  }
}
