// Reader for legacy ASCII VTK POLYDATA files (what YADE's export.VTKExporter writes).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace gs {

struct LegacyPolyData {
  std::vector<double> points;                    // 3 per point
  std::vector<std::vector<long long>> vertices;  // VERTICES cells
  std::vector<std::vector<long long>> lines;     // LINES cells
  struct Array {
    int components = 1;
    std::vector<double> values;  // components per tuple
  };
  std::map<std::string, Array> point_data, cell_data;
};

/// Parses POINTS, VERTICES, LINES, POLYGONS (skipped), POINT_DATA / CELL_DATA with SCALARS
/// (+ LOOKUP_TABLE), VECTORS, NORMALS and FIELD arrays. Throws InputError on anything else or
/// on inconsistent counts.
LegacyPolyData read_legacy_polydata(const std::filesystem::path& path);

}  // namespace gs
