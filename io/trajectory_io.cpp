#include "trajectory_io.hpp"

#include <fstream>
#include <new>

#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "packing_csv.hpp"
#include "particle_text.hpp"
#include "vtk_io.hpp"

namespace gs {

std::string format_name(SnapshotFormat f) {
  switch (f) {
    case SnapshotFormat::Hdf5:
      return "granoscope HDF5 trajectory";
    case SnapshotFormat::Vtu:
      return "VTK XML particles (.vtu)";
    case SnapshotFormat::Pvd:
      return "ParaView series (.pvd)";
    case SnapshotFormat::YadeLegacyVtk:
      return "YADE VTKExporter legacy VTK";
    case SnapshotFormat::PackingCsv:
      return "packing CSV";
    case SnapshotFormat::LiggghtsDump:
      return "LIGGGHTS/LAMMPS dump";
    case SnapshotFormat::ParticleText:
      return "DEM8 particle text";
  }
  return "unknown";
}

namespace {
std::string lower_ext(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  for (auto& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}
}  // namespace

SnapshotFormat detect_format(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(name, "no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(name, "not a regular file");
  if (is_hdf5_file(path)) return SnapshotFormat::Hdf5;
  std::ifstream in(path, std::ios::binary);
  std::string head(64, '\0');
  in.read(head.data(), 64);
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.rfind("ITEM: TIMESTEP", 0) == 0) return SnapshotFormat::LiggghtsDump;
  if (head.rfind("# vtk DataFile", 0) == 0) return SnapshotFormat::YadeLegacyVtk;
  if (is_particle_text(path)) return SnapshotFormat::ParticleText;
  const std::string e = lower_ext(path);
  if (e == ".h5" || e == ".hdf5") throw InputError(name, "not an HDF5 file (bad signature)");
  if (e == ".vtu") return SnapshotFormat::Vtu;
  if (e == ".pvd") return SnapshotFormat::Pvd;
  if (e == ".csv") return SnapshotFormat::PackingCsv;
  if (e == ".vtk")
    throw InputError(name, "not a legacy VTK file (missing '# vtk DataFile' header)");
  throw InputError(name, "unknown file type", e.empty() ? "no extension" : e);
}

SnapshotFormat output_format(const std::filesystem::path& path) {
  const std::string e = lower_ext(path);
  if (e == ".h5" || e == ".hdf5") return SnapshotFormat::Hdf5;
  if (e == ".vtu") return SnapshotFormat::Vtu;
  if (e == ".pvd") return SnapshotFormat::Pvd;
  if (e == ".csv") return SnapshotFormat::PackingCsv;
  throw InputError(path.string(), "unknown output type (use .h5, .vtu, .pvd or .csv)",
                   e.empty() ? "no extension" : e);
}

namespace {
Trajectory read_any(const std::filesystem::path& path, const ImportOptions& opt) {
  const std::string name = path.string();
  auto single = [&](Frame f, const std::string& provenance) {
    Trajectory t;
    t.metadata.code_version = code_version();
    t.metadata.provenance = provenance;
    t.frames.push_back(std::move(f));
    return t;
  };
  switch (detect_format(path)) {
    case SnapshotFormat::Hdf5:
      return read_hdf5_trajectory(path);
    case SnapshotFormat::Vtu: {
      Frame f = read_vtu_particles(path);
      auto vtp = opt.contacts.value_or(std::filesystem::path(path).replace_extension(".vtp"));
      std::error_code ec;
      if (std::filesystem::exists(vtp, ec)) read_vtp_contacts(vtp, f);
      const auto clumps = clumps_sibling(path);
      if (std::filesystem::exists(clumps, ec)) read_vtu_clumps(clumps, f);
      return single(std::move(f), "read from " + name);
    }
    case SnapshotFormat::Pvd:
      return read_pvd_series(path);
    case SnapshotFormat::YadeLegacyVtk:
      return single(read_yade_legacy(path, opt.contacts.value_or(std::filesystem::path{})),
                    "imported from YADE VTKExporter " + name);
    case SnapshotFormat::PackingCsv:
      return single(read_packing_csv(path), "packing CSV " + name);
    case SnapshotFormat::ParticleText:
      return single(read_particle_text(path, opt.max_particles), "DEM8 particle text " + name);
    case SnapshotFormat::LiggghtsDump: {
      LiggghtsImportOptions lo = opt.liggghts;
      if (opt.contacts) lo.pairs = opt.contacts;
      return read_liggghts_dump(path, lo);
    }
  }
  throw InputError(name, "unknown file type");
}
}  // namespace

Trajectory read_snapshots(const std::filesystem::path& path, const ImportOptions& opt) {
  try {
    return read_any(path, opt);
  } catch (const std::bad_alloc&) {  // the readers bound what a file may claim; this is the rest
    throw InputError(path.string(), "not enough memory to read the file");
  }
}

void write_snapshots(const std::filesystem::path& path, const Trajectory& t, long frame) {
  const auto fmt = output_format(path);
  auto pick = [&]() -> const Frame& {
    const long n = static_cast<long>(t.frames.size());
    const long i = frame < 0 ? n + frame : frame;
    if (i < 0 || i >= n)
      throw InputError(path.string(), "no such frame to write",
                       std::to_string(frame) + " of " + std::to_string(n));
    return t.frames[static_cast<std::size_t>(i)];
  };
  if (t.frames.empty()) throw InputError(path.string(), "nothing to write (no frames)");
  switch (fmt) {
    case SnapshotFormat::Hdf5:
      write_hdf5_trajectory(path, t);
      return;
    case SnapshotFormat::Pvd:
      write_pvd_series(path, t);
      return;
    case SnapshotFormat::PackingCsv:
      write_packing_csv(path, pick());
      return;
    case SnapshotFormat::Vtu: {
      const Frame& f = pick();
      write_vtp_contacts(std::filesystem::path(path).replace_extension(".vtp"), f);
      const auto clumps = clumps_sibling(path);
      std::error_code ec;
      if (!f.clumps.empty())
        write_vtu_clumps(clumps, f);
      else
        std::filesystem::remove(clumps, ec);  // a stale one would be read back with this frame
      write_vtu_particles(path, f);
      return;
    }
    default:
      break;
  }
  throw InputError(path.string(), "unsupported output type");
}

}  // namespace gs
