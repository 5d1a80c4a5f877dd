// DIC outputs: one HDF5 file (root attribute format = "granoscope-dic"; datasets
// /u, /v, /exx, ... of shape frames x ny x nx), and per frame a CSV table and a VTK image
// (.vti) of the POI grid. Every file is written under a temporary name and renamed.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "dic_sequence.hpp"

namespace gs::dic {

inline constexpr const char* kDicFormatName = "granoscope-dic";

struct DicRunInfo {
  std::vector<std::string> images;  // reference first
  int subset_px = 31;
  int step_px = 2;
  std::string shape_function = "affine";  // or "quadratic"
  int strain_window_points = 15;          // 2m+1
  double vsg_px = 0.0;
  bool incremental = false;
  bool small_strain = false;  // CSV/VTK exx, eyy, exy: small strain instead of Green–Lagrange
  int image_rows = 0;
  int image_cols = 0;
};

/// A per-POI field of every frame, by its dataset name in the HDF5 file.
struct DicColumn {
  const char* name;
  const std::vector<double>& (*get)(const FrameResult&);
};
/// The HDF5 file's per-frame fields, in order: u, v, zncc, exx, eyy, exy (Green–Lagrange),
/// exx_small, eyy_small, exy_small (the Python package returns the same).
const std::vector<DicColumn>& dic_columns();
/// POI coordinates (px) along x (nx values) and y (ny values): the HDF5 file's /x and /y.
std::vector<double> grid_x(const PoiGrid& g);
std::vector<double> grid_y(const PoiGrid& g);

/// Writes the HDF5 file. Throws gs::InputError naming the file on failure.
void write_dic_hdf5(const std::filesystem::path& path, const SequenceResult& result,
                    const DicRunInfo& info);
/// x, y, u, v, exx, eyy, exy, zncc, valid for one frame (NaN written as "nan").
void write_dic_csv(const std::filesystem::path& path, const SequenceResult& result,
                   std::size_t frame, const DicRunInfo& info);
/// VTK XML image data of the POI grid (origin = first POI, spacing = step) with point arrays.
void write_dic_vti(const std::filesystem::path& path, const SequenceResult& result,
                   std::size_t frame, const DicRunInfo& info);
/// Per-frame name beside the HDF5 file: dic.h5, frame 0 -> dic_0001 + extension.
std::filesystem::path frame_output_path(const std::filesystem::path& h5, std::size_t frame,
                                        const std::string& extension);
/// All outputs of a run: the HDF5 file `h5` and, per frame, the CSV and VTI files named by
/// frame_output_path (when `csv` / `vtk`), on up to `threads` threads. Each file is written by
/// one thread; the HDF5 file and the VTK files each by one thread at a time (neither library is
/// thread-safe), the CSV files beside them. Throws the first gs::InputError of any file.
void write_dic_outputs(const std::filesystem::path& h5, const SequenceResult& result,
                       const DicRunInfo& info, bool csv, bool vtk, int threads);

}  // namespace gs::dic

namespace gs::dic {

struct GroundTruth;
struct Camera;

/// Ground truth of rendered frames (root attribute format = "granoscope-render-truth"):
/// /grain (rows x cols, index of the reference particle, -1 background), /u, /v, /visible
/// (frames x rows x cols; px, reference = frame 0), camera attributes.
void write_ground_truth_hdf5(const std::filesystem::path& path, const Camera& camera,
                             const std::string& view, const std::vector<GroundTruth>& frames);

}  // namespace gs::dic
