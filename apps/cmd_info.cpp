// `granoscope info FILE`: format, frames, counts, time range, bounding box, d50.
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "errors.hpp"
#include "grain_size.hpp"
#include "hdf5_trajectory.hpp"
#include "import_options.hpp"

namespace gs::cli {

namespace {

void print_info(const std::string& file, const std::string& format, std::size_t frames,
                std::size_t p_first, std::size_t p_last, std::size_t c_first, std::size_t c_last,
                double t0, double t1, std::int64_t s0, std::int64_t s1, const Frame& last) {
  const auto [lo, hi] = particle_bounds(last);
  std::printf("file:         %s\n", file.c_str());
  std::printf("format:       %s\n", format.c_str());
  std::printf("frames:       %zu\n", frames);
  std::printf("particles:    %zu (first frame), %zu (last frame)\n", p_first, p_last);
  std::printf("contacts:     %zu (first frame), %zu (last frame)\n", c_first, c_last);
  std::printf("time:         %.9g .. %.9g s (steps %lld .. %lld)\n", t0, t1,
              static_cast<long long>(s0), static_cast<long long>(s1));
  std::printf("bounding box: [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g] m (last frame)\n", lo.x(),
              lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
  if (last.domain.periodic) {
    const Eigen::Matrix3d& h = last.domain.cell;
    std::printf(
        "cell:         periodic, H = [%.6g %.6g %.6g; %.6g %.6g %.6g; %.6g %.6g %.6g] m "
        "(columns: base vectors), volume %.6g m^3 (last frame)\n",
        h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2), h(2, 0), h(2, 1), h(2, 2),
        h.determinant());
  }
  if (last.two_d) std::printf("dimension:    2D (in the xy plane)\n");
  if (!last.particles.empty())
    std::printf("d50:          %.6g m (by %s, last frame)\n", analysis::d50(last),
                last.two_d ? "area: 2D" : "volume");
  std::printf("walls:        %zu\n", last.walls.size());
  if (!last.clumps.empty())
    std::printf("clumps:       %zu bodies (last frame)\n", last.clumps.size());
  if (!last.facet_loads.empty())
    std::printf("facet loads:  %zu triangles (last frame)\n", last.facet_loads.size());
}

}  // namespace

void register_info(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("info", "Summarise a snapshot or trajectory file of any supported format");
  auto file = std::make_shared<std::string>();
  auto imp = std::make_shared<ImportArgs>();
  cmd->add_option("FILE", *file,
                  "HDF5 trajectory, .vtu, .pvd, YADE .vtk, packing .csv, LIGGGHTS dump")
      ->required();
  imp->add_to(*cmd);
  cmd->callback([file, imp] {
    const auto fmt = detect_format(*file);
    if (fmt == SnapshotFormat::Hdf5) {  // without loading every frame
      TrajectoryReader r(*file);
      if (r.frame_count() == 0) throw InputError(*file, "trajectory holds no frame");
      const std::size_t n = r.frame_count();
      const Frame first = r.frame(0);
      const Frame last = n > 1 ? r.frame(n - 1) : first;
      print_info(*file, format_name(fmt), n, first.particles.size(), last.particles.size(),
                 first.contacts.size(), last.contacts.size(), first.time, last.time, first.step,
                 last.step, last);
      return;
    }
    const Trajectory t = read_snapshots(*file, imp->options());
    if (t.frames.empty()) throw InputError(*file, "no frame");
    const Frame& a = t.frames.front();
    const Frame& b = t.frames.back();
    print_info(*file, format_name(fmt), t.frames.size(), a.particles.size(), b.particles.size(),
               a.contacts.size(), b.contacts.size(), a.time, b.time, a.step, b.step, b);
  });
}

}  // namespace gs::cli
