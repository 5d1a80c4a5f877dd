// Command-line options shared by every subcommand that reads snapshots of any format.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "trajectory_io.hpp"

namespace gs::cli {

struct ImportArgs {
  std::string contacts;
  double dt = 0;
  std::string pair_columns;

  void add_to(CLI::App& cmd) {
    cmd.add_option("--contacts", contacts,
                   "contacts file kept apart from the particles (YADE interactions .vtk, "
                   "LIGGGHTS local dump); default: found by naming convention");
    cmd.add_option("--dt", dt, "time step in s for LIGGGHTS dumps (time = step x dt)")
        ->check(CLI::NonNegativeNumber);
    cmd.add_option("--pair-columns", pair_columns,
                   "comma-separated meaning of the LIGGGHTS pair dump columns (default "
                   "x1,y1,z1,x2,y2,z2,id1,id2,periodic,fx,fy,fz)");
  }

  ImportOptions options() const {
    ImportOptions o;
    if (!contacts.empty()) o.contacts = contacts;
    o.liggghts.dt = dt;
    if (!pair_columns.empty()) {
      o.liggghts.pair_columns.clear();
      std::string cur;
      for (char c : pair_columns + ",") {
        if (c == ',') {
          o.liggghts.pair_columns.push_back(cur);
          cur.clear();
        } else {
          cur += c;
        }
      }
    }
    return o;
  }
};

}  // namespace gs::cli
