// Shared by the YADE reference tests: a CSV table with a header, the folder of a reference case
// (../shared/reference/yade/<case>, or the copy of what the tests assert in tests/data), and an
// axis-aligned box wall.
#pragma once

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "simulation.hpp"
#include "text_parse.hpp"

namespace gs::test {

struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::size_t col(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return i;
    throw std::runtime_error("no column " + name);
  }
  double num(std::size_t r, const std::string& name) const {
    return std::strtod(rows.at(r).at(col(name)).c_str(), nullptr);
  }
  const std::string& str(std::size_t r, const std::string& name) const {
    return rows.at(r).at(col(name));
  }
};

inline CsvTable read_csv_table(const std::filesystem::path& p) {
  const std::string text = text::read_text_file(p);
  const auto lines = text::split_lines(text);
  CsvTable t;
  for (const auto h : text::split_csv(lines.at(0))) t.header.emplace_back(text::trim(h));
  for (std::size_t i = 1; i < lines.size(); ++i) {
    if (text::trim(lines[i]).empty()) continue;
    std::vector<std::string> v;
    for (const auto tok : text::split_csv(lines[i])) v.emplace_back(text::trim(tok));
    t.rows.push_back(std::move(v));
  }
  return t;
}

/// ../shared/reference/yade/<name> when the checkout has it beside it (`probe` is a file the
/// case holds), else tests/data/yade_<name>.
inline std::filesystem::path reference_case_dir(const std::string& name,
                                                const std::string& probe = "packing.csv") {
  const auto shared =
      std::filesystem::path(GS_SOURCE_DIR) / ".." / "shared" / "reference" / "yade" / name;
  if (std::filesystem::exists(shared / probe)) return shared;
  return std::filesystem::path(GS_TEST_DATA_DIR) / ("yade_" + name);
}

inline solver::WallSpec box_wall(const char* name, const Eigen::Vector3d& centre,
                                 const Eigen::Vector3d& half_extents,
                                 const Eigen::Vector3d& velocity) {
  solver::WallSpec w;
  w.name = name;
  w.shape = solver::WallShape::Box;
  w.center = centre;
  w.half_extents = half_extents;
  w.velocity = velocity;
  return w;
}

}  // namespace gs::test
