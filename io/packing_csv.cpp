#include "packing_csv.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "atomic_file.hpp"
#include "errors.hpp"
#include "text_parse.hpp"

namespace gs {

Frame read_packing_csv(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string text = text::read_text_file(path);
  const auto lines = text::split_lines(text);
  std::size_t li = 0;
  while (li < lines.size() && text::trim(lines[li]).empty()) ++li;
  if (li == lines.size()) throw InputError(name, "empty file");
  const auto header = text::split_csv(lines[li]);
  const std::array<const char*, 5> need{"id", "x", "y", "z", "r"};
  const auto col = text::column_indices(header, {need.begin(), need.end()});
  for (std::size_t k = 0; k < need.size(); ++k)
    if (col[k] == header.size()) throw InputError(name, "missing column in header", need[k]);
  // Optional velocities (all three or none).
  const std::array<const char*, 3> vel{"vx", "vy", "vz"};
  const auto vcol = text::column_indices(header, {vel.begin(), vel.end()});
  const std::size_t nv = static_cast<std::size_t>(
      std::count_if(vcol.begin(), vcol.end(), [&](std::size_t c) { return c < header.size(); }));
  if (nv != 0 && nv != 3) throw InputError(name, "velocity columns: give vx, vy and vz, or none");
  Frame f;
  for (++li; li < lines.size(); ++li) {
    const auto l = text::trim(lines[li]);
    if (l.empty() || l.front() == '#') continue;
    const auto fields = text::split_csv(l);
    if (fields.size() != header.size())
      throw InputError(name,
                       "line " + std::to_string(li + 1) + ": expected " +
                           std::to_string(header.size()) + " fields",
                       std::to_string(fields.size()));
    Particle p;
    p.id = text::to_int(fields[col[0]], name, li + 1, "id");
    for (int d = 0; d < 3; ++d)
      p.position[d] = text::to_double(fields[col[1 + d]], name, li + 1, need[1 + d]);
    p.radius = text::to_double(fields[col[4]], name, li + 1, "r");
    for (std::size_t d = 0; nv == 3 && d < 3; ++d) {
      p.velocity[static_cast<int>(d)] = text::to_double(fields[vcol[d]], name, li + 1, vel[d]);
      if (!std::isfinite(p.velocity[static_cast<int>(d)]))
        throw InputError(name, "line " + std::to_string(li + 1) + ": " + vel[d] + " not finite",
                         std::string(fields[vcol[d]]));
    }
    f.particles.push_back(p);
  }
  if (f.particles.empty()) throw InputError(name, "no particles");
  validate_frame(f, name);
  std::tie(f.domain.lo, f.domain.hi) = particle_bounds(f);
  return f;
}

void write_packing_csv(const std::filesystem::path& path, const Frame& frame) {
  AtomicOutput out(path);
  {
    std::ofstream o(out.temp_path());
    if (!o) throw InputError(path.string(), "cannot write file");
    o << "id,x,y,z,r\n";
    char buf[256];
    for (const auto& p : frame.particles) {
      std::snprintf(buf, sizeof buf, "%lld,%.17g,%.17g,%.17g,%.17g\n", static_cast<long long>(p.id),
                    p.position.x(), p.position.y(), p.position.z(), p.radius);
      o << buf;
    }
    if (!o.flush()) throw InputError(path.string(), "write failed");
  }
  out.commit();
}

}  // namespace gs
