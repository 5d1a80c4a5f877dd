// One analysis output with a frame axis from the outputs of the same analysis on several frames
// (`granoscope analyze ... --frames A:B`, issue 23; docs/analysis.md "Frame series").
#pragma once

#include <filesystem>
#include <vector>

namespace gs {

/// Merges the per-frame HDF5 outputs `parts` of one analysis (files of H5FieldFile, one per
/// entry of `frames`, the trajectory's frame indices) into `out` (written to a temporary name
/// and renamed), root attribute format = "granoscope-series", `of` = the parts' format:
///  * `/frame` (int64, F): the frame indices;
///  * every numeric dataset of the parts at its own path: stacked along a new first axis,
///    shape (F, ...), when every frame has the same shape; otherwise concatenated along the
///    first axis, with `<path>_offsets` (int64, F + 1) giving frame f's rows
///    [offsets[f], offsets[f+1]);
///  * every numeric attribute (root, group or dataset) as a dataset `/attributes<object>/<name>`
///    of F values; string attributes as attributes of `out` when all frames agree (else that of
///    the first frame, and the attribute `<name>_varies` = 1).
/// Floating-point data are written as double and integers as int64. Throws InputError naming
/// the part on an unreadable file or a dataset missing from one of them or of another rank.
void merge_field_series(const std::vector<std::filesystem::path>& parts,
                        const std::vector<long>& frames, const std::filesystem::path& out);

}  // namespace gs
