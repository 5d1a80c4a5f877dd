#include "particle_text.hpp"

#include <array>
#include <fstream>
#include <string>

#include "errors.hpp"
#include "text_parse.hpp"

namespace gs {

namespace {
// "PosX[m]" -> "PosX"
std::string_view column_name(std::string_view tok) {
  return tok.substr(0, tok.find('['));
}
}  // namespace

bool is_particle_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    const auto t = text::trim(line);
    if (t.empty()) continue;
    return t.rfind("Radius", 0) == 0;
  }
  return false;
}

Frame read_particle_text(const std::filesystem::path& path, std::size_t max_rows) {
  const std::string name = path.string();
  const std::string text = text::read_text_file(path);
  const auto lines = text::split_lines(text);
  std::size_t li = 0;
  while (li < lines.size() && text::trim(lines[li]).empty()) ++li;
  if (li == lines.size()) throw InputError(name, "empty file");
  const auto header = text::split_ws(lines[li]);
  static const std::array<const char*, 4> need{"Radius", "PosX", "PosY", "PosZ"};
  std::array<std::size_t, 4> col{};
  for (std::size_t k = 0; k < need.size(); ++k) {
    col[k] = header.size();
    for (std::size_t c = 0; c < header.size(); ++c)
      if (column_name(header[c]) == need[k]) col[k] = c;
    if (col[k] == header.size())
      throw InputError(name, "line " + std::to_string(li + 1) + ": missing column in header",
                       need[k]);
  }
  Frame f;
  for (++li; li < lines.size() && f.particles.size() < max_rows; ++li) {
    const auto tok = text::split_ws(lines[li]);
    if (tok.empty() || tok[0].front() == '#') continue;
    if (tok.size() != header.size())
      throw InputError(name,
                       "line " + std::to_string(li + 1) + ": expected " +
                           std::to_string(header.size()) + " fields",
                       std::to_string(tok.size()));
    Particle p;
    p.id = static_cast<std::int64_t>(f.particles.size());
    p.radius = text::to_double(tok[col[0]], name, li + 1, "Radius");
    for (int d = 0; d < 3; ++d)
      p.position[d] = text::to_double(tok[col[1 + static_cast<std::size_t>(d)]], name, li + 1,
                                      need[1 + static_cast<std::size_t>(d)]);
    f.particles.push_back(p);
  }
  if (f.particles.empty()) throw InputError(name, "no particles");
  validate_frame(f, name);
  std::tie(f.domain.lo, f.domain.hi) = particle_bounds(f);
  return f;
}

}  // namespace gs
