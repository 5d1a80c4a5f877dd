// HDF5 trajectory format (docs/format.md, schema_version 3; version 1 files, which have no
// /clumps group, and version 2 files, which have no cell velocity gradient, are read too): plain
// chunked, compressed, checksummed arrays, one row block per frame, appended frame by frame. The
// frame index /frames/end is appended last and flushed, so a run killed mid-write leaves every
// completed frame readable (HDF5 single-writer/multiple-reader mode keeps the file consistent).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "snapshot.hpp"

namespace gs {

/// Version written. 2 added the clump bodies (/clumps, /frames/clump_end); 1 is still read.
inline constexpr int kTrajectorySchemaVersion = 3;
/// Bytes of the fixed-length clump template names (/clumps/template); longer names are rejected.
inline constexpr std::size_t kClumpTemplateBytes = 64;
inline constexpr const char* kTrajectoryFormatName = "granoscope-trajectory";

/// Name under which a trajectory is written until finish() renames it to its final name.
std::filesystem::path partial_path(const std::filesystem::path& final_path);

class TrajectoryWriter {
 public:
  struct Options {
    /// When the writer is destroyed without finish(): true removes the .partial file (one-shot
    /// outputs such as `convert`); false keeps it readable (simulations, to resume from).
    bool discard_unfinished = true;
    int deflate_level = 1;
  };
  /// Creates `<path>.partial` (replacing any) and writes the metadata.
  TrajectoryWriter(std::filesystem::path path, const RunMetadata& metadata, Options options);
  TrajectoryWriter(std::filesystem::path path, const RunMetadata& metadata);
  /// Re-opens an existing `<path>.partial` to append further frames, first dropping every frame
  /// after the first `keep_frames` ones. A schema_version 1 or 2 file is upgraded in place to
  /// the current version (its frames have no clump bodies, or a zero cell velocity gradient).
  static TrajectoryWriter resume(std::filesystem::path path, std::size_t keep_frames,
                                 Options options);
  TrajectoryWriter(TrajectoryWriter&&) noexcept;
  TrajectoryWriter& operator=(TrajectoryWriter&&) noexcept;
  ~TrajectoryWriter();

  /// Appends one frame and flushes it to disk.
  void append(const Frame& frame);
  /// Appends frames in batches (each dataset written once per batch, one flush per batch): the
  /// way to write a whole trajectory in time linear in its length.
  void append(const std::vector<Frame>& frames);
  /// Fills `piece` (its particles and contacts, empty on entry) with piece `i` of a frame;
  /// false when `i` is the last piece.
  using FramePieces = std::function<bool(std::size_t i, Frame& piece)>;
  /// Appends one frame given in pieces, so that a large one is never held whole: `head` has
  /// all but the particles and contacts (it has none), `pieces` gives them in order. Each
  /// piece is asked for twice and must come out the same: all are checked before any is
  /// written.
  void append(const Frame& head, const FramePieces& pieces);
  std::size_t frames_written() const;
  /// Closes the file and renames `<path>.partial` to `<path>`.
  void finish();

 private:
  struct Impl;
  explicit TrajectoryWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// Random access to the frames of a trajectory file (also one still being written, or left
/// behind by a killed writer).
class TrajectoryReader {
 public:
  explicit TrajectoryReader(const std::filesystem::path& path);
  TrajectoryReader(TrajectoryReader&&) noexcept;
  ~TrajectoryReader();

  std::size_t frame_count() const;
  const RunMetadata& metadata() const;
  /// Reads and validates frame i (0-based).
  Frame frame(std::size_t i) const;
  /// Particle and contact counts of frame i without reading the rows.
  std::size_t particle_count(std::size_t i) const;
  std::size_t contact_count(std::size_t i) const;
  /// Clump bodies of frame i (0 for a schema_version 1 file).
  std::size_t clump_count(std::size_t i) const;
  double time(std::size_t i) const;
  /// The file's schema_version (1, 2 or 3).
  int schema_version() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

Trajectory read_hdf5_trajectory(const std::filesystem::path& path);
/// Writes a whole trajectory atomically (temporary name, renamed at the end).
void write_hdf5_trajectory(const std::filesystem::path& path, const Trajectory& trajectory);

/// True when the file starts with the HDF5 signature.
bool is_hdf5_file(const std::filesystem::path& path);

}  // namespace gs
