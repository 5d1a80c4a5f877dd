// Finding and running a Python 3 interpreter that imports matplotlib, numpy and h5py.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace gs::cli {

/// $GRANOSCOPE_PYTHON, else /usr/bin/python3 (Debian's, which has the packages), else python3
/// on PATH: the first that imports matplotlib, numpy and h5py. Throws std::runtime_error naming
/// the interpreters tried when none does, or naming $GRANOSCOPE_PYTHON when it is set and unusable
/// (it is never passed over for another).
std::string find_python();

/// The directory holding the figure scripts: $GRANOSCOPE_FIGURES_DIR, else
/// <exe>/../share/granoscope/figures, else the source tree's apps/figures.
std::filesystem::path figures_dir();

/// Runs argv[0] with the arguments (no shell); returns its exit code (128+signal if killed).
int run_process(const std::vector<std::string>& argv);

}  // namespace gs::cli
