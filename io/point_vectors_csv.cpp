#include "point_vectors_csv.hpp"

#include <array>
#include <cmath>
#include <string>

#include "errors.hpp"
#include "text_parse.hpp"

namespace gs {

PointVectors read_point_vectors_csv(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string text = text::read_text_file(path);
  const auto lines = text::split_lines(text);
  std::size_t li = 0;
  while (li < lines.size() &&
         (text::trim(lines[li]).empty() || text::trim(lines[li]).front() == '#'))
    ++li;
  if (li == lines.size()) throw InputError(name, "empty file");
  const auto header = text::split_csv(lines[li]);
  const std::array<const char*, 7> names{"x", "y", "z", "ux", "uy", "uz", "id"};
  const auto col = text::column_indices(header, {names.begin(), names.end()});
  const auto has = [&](std::size_t k) { return col[k] < header.size(); };
  for (std::size_t k : {0u, 1u, 3u, 4u})
    if (!has(k))
      throw InputError(name, "missing column in header (need x,y[,z],ux,uy[,uz])", names[k]);
  if (has(2) != has(5)) throw InputError(name, "missing column in header", has(2) ? "uz" : "z");
  PointVectors p;
  p.dim = has(2) ? 3 : 2;
  for (++li; li < lines.size(); ++li) {
    const auto l = text::trim(lines[li]);
    if (l.empty() || l.front() == '#') continue;
    const auto fields = text::split_csv(l);
    if (fields.size() != header.size()) {
      throw InputError(name,
                       "line " + std::to_string(li + 1) + ": expected " +
                           std::to_string(header.size()) + " fields",
                       std::to_string(fields.size()));
    }
    Eigen::Vector3d x = Eigen::Vector3d::Zero(), u = Eigen::Vector3d::Zero();
    for (int d = 0; d < p.dim; ++d) {
      const auto kx = static_cast<std::size_t>(d), ku = static_cast<std::size_t>(3 + d);
      x[d] = text::to_double(fields[col[kx]], name, li + 1, names[kx]);
      u[d] = text::to_double(fields[col[ku]], name, li + 1, names[ku]);
      for (const auto k : {kx, ku}) {
        if (!std::isfinite(k == kx ? x[d] : u[d])) {
          throw InputError(name,
                           "line " + std::to_string(li + 1) + ": non-finite value in " + names[k],
                           std::string(fields[col[k]]));
        }
      }
    }
    p.id.push_back(has(6) ? text::to_int(fields[col[6]], name, li + 1, "id")
                          : static_cast<std::int64_t>(p.x.size()));
    p.x.push_back(x);
    p.u.push_back(u);
  }
  if (p.x.empty()) throw InputError(name, "no data rows");
  return p;
}

}  // namespace gs
