#include "triangle_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <unordered_map>

#include "atomic_file.hpp"
#include "errors.hpp"
#include "text_parse.hpp"

namespace gs {

namespace {

constexpr const char* kDefaultGroup = "mesh";

std::string fmt17(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string corners_str(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c) {
  std::string s;
  for (const Eigen::Vector3d* v : {&a, &b, &c}) {
    if (!s.empty()) s += " | ";
    s += fmt17(v->x()) + " " + fmt17(v->y()) + " " + fmt17(v->z());
  }
  return s;
}

std::string zero_area_what(std::size_t t) {
  return "triangle " + std::to_string(t) + " has zero area";
}

std::string line_prefix(std::size_t line) {
  return "line " + std::to_string(line) + ": ";
}

std::string lower(std::string_view s) {
  std::string o(s);
  for (auto& c : o) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return o;
}

bool is_blank(unsigned char c) {
  return c == ' ' || (c >= '\t' && c <= '\r');
}

// Builds a mesh, merging exactly equal vertices (−0 and +0 count as equal) and numbering the
// groups in order of first use.
class MeshBuilder {
 public:
  int vertex(const Eigen::Vector3d& v) {
    const Key k{v.x() + 0.0, v.y() + 0.0, v.z() + 0.0};  // + 0.0 turns −0 into +0
    const auto [it, fresh] = index_.try_emplace(k, static_cast<int>(mesh_.vertices.size()));
    if (fresh) mesh_.vertices.push_back(v);
    return it->second;
  }
  void select_group(const std::string& name) {
    current_ = name.empty() ? std::string(kDefaultGroup) : name;
  }
  void triangle(int a, int b, int c) {
    const auto [it, fresh] =
        groups_.try_emplace(current_, static_cast<int>(mesh_.group_names.size()));
    if (fresh) mesh_.group_names.push_back(current_);
    mesh_.triangles.push_back({a, b, c});
    mesh_.group.push_back(it->second);
  }
  std::size_t triangle_count() const { return mesh_.triangles.size(); }
  TriangleMesh take() { return std::move(mesh_); }

 private:
  using Key = std::array<double, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 0x9e3779b97f4a7c15ull;
      for (double d : k) {
        h ^= std::bit_cast<std::uint64_t>(d) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
      }
      return static_cast<std::size_t>(h);
    }
  };
  TriangleMesh mesh_;
  std::unordered_map<Key, int, KeyHash> index_;
  std::unordered_map<std::string, int> groups_;
  std::string current_ = kDefaultGroup;
};

// ---- ASCII STL -------------------------------------------------------------------------------

TriangleMesh parse_ascii_stl(const std::string& name, std::string_view text) {
  const auto lines = text::split_lines(text);
  MeshBuilder mb;
  enum class State { Outside, InSolid, InFacet, InLoop, EndLoop };
  State st = State::Outside;
  std::string solid;
  std::size_t facet_line = 0;
  std::vector<Eigen::Vector3d> corners;
  auto expect = [&](std::size_t line, const char* what, std::string_view got) {
    return InputError(name, line_prefix(line) + "expected " + what, std::string(got.substr(0, 40)));
  };
  for (std::size_t li = 0; li < lines.size(); ++li) {
    const std::size_t ln = li + 1;
    const auto tok = text::split_ws(lines[li]);
    if (tok.empty()) continue;
    const std::string kw = lower(tok[0]);
    switch (st) {
      case State::Outside:
        if (kw != "solid") throw expect(ln, "solid", tok[0]);
        solid = std::string(text::trim(text::trim(lines[li]).substr(5)));
        mb.select_group(solid);
        st = State::InSolid;
        break;
      case State::InSolid:
        if (kw == "endsolid") {
          st = State::Outside;
          break;
        }
        if (kw != "facet") throw expect(ln, "facet or endsolid", tok[0]);
        if (tok.size() > 1) {
          if (lower(tok[1]) != "normal" || tok.size() != 5)
            throw expect(ln, "facet normal NX NY NZ", lines[li]);
          for (int d = 0; d < 3; ++d) (void)text::to_double(tok[2 + d], name, ln, "facet normal");
        }
        facet_line = ln;
        st = State::InFacet;
        break;
      case State::InFacet:
        if (kw != "outer" || tok.size() != 2 || lower(tok[1]) != "loop")
          throw expect(ln, "outer loop", lines[li]);
        corners.clear();
        st = State::InLoop;
        break;
      case State::InLoop: {
        if (kw == "endloop") {
          if (corners.size() != 3)
            throw InputError(name, line_prefix(facet_line) + "facet has " +
                                       std::to_string(corners.size()) + " vertices, expected 3");
          st = State::EndLoop;
          break;
        }
        if (kw != "vertex" || tok.size() != 4)
          throw expect(ln, "vertex X Y Z or endloop", lines[li]);
        static const char* field[3] = {"vertex x", "vertex y", "vertex z"};
        Eigen::Vector3d v;
        for (int d = 0; d < 3; ++d) {
          v[d] = text::to_double(tok[1 + d], name, ln, field[d]);
          if (!std::isfinite(v[d]))
            throw InputError(name, line_prefix(ln) + "vertex coordinate is not finite",
                             value_str(v[d]));
        }
        corners.push_back(v);
        break;
      }
      case State::EndLoop: {
        if (kw != "endfacet") throw expect(ln, "endfacet", tok[0]);
        const std::size_t t = mb.triangle_count();
        if (degenerate_triangle(corners[0], corners[1], corners[2]))
          throw InputError(name, line_prefix(facet_line) + zero_area_what(t),
                           corners_str(corners[0], corners[1], corners[2]));
        mb.triangle(mb.vertex(corners[0]), mb.vertex(corners[1]), mb.vertex(corners[2]));
        st = State::InSolid;
        break;
      }
    }
  }
  if (st != State::Outside)
    throw InputError(name, "unexpected end of file inside solid",
                     solid.empty() ? std::string(kDefaultGroup) : solid);
  if (mb.triangle_count() == 0) throw InputError(name, "no triangles");
  return mb.take();
}

// ---- binary STL ------------------------------------------------------------------------------

std::uint32_t le_u32(const char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

double le_f32(const char* p) {
  return static_cast<double>(std::bit_cast<float>(le_u32(p)));
}

TriangleMesh parse_binary_stl(const std::string& name, const std::string& bytes) {
  if (bytes.size() < 84)
    throw InputError(name, "file too short for a binary STL",
                     std::to_string(bytes.size()) + " bytes");
  const std::uint64_t n = le_u32(bytes.data() + 80);
  const std::uint64_t need = 84 + 50 * n;
  if (bytes.size() < need)
    throw InputError(
        name, "truncated binary STL: the header says " + std::to_string(n) + " triangles",
        "file holds " + std::to_string(bytes.size()) + " bytes, needs " + std::to_string(need));
  if (bytes.size() > need)
    throw InputError(
        name, "binary STL has bytes after its " + std::to_string(n) + " triangles",
        "file holds " + std::to_string(bytes.size()) + " bytes, expected " + std::to_string(need));
  if (n == 0) throw InputError(name, "no triangles");
  MeshBuilder mb;
  for (std::uint64_t t = 0; t < n; ++t) {
    const char* rec = bytes.data() + 84 + 50 * t;
    std::array<Eigen::Vector3d, 3> c;
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) {
        c[k][d] = le_f32(rec + 12 + 12 * k + 4 * d);  // after the 12-byte normal
        if (!std::isfinite(c[k][d]))
          throw InputError(name,
                           "triangle " + std::to_string(t) + ": vertex coordinate is not finite",
                           value_str(c[k][d]));
      }
    if (degenerate_triangle(c[0], c[1], c[2]))
      throw InputError(name, zero_area_what(t), corners_str(c[0], c[1], c[2]));
    mb.triangle(mb.vertex(c[0]), mb.vertex(c[1]), mb.vertex(c[2]));
  }
  return mb.take();
}

// ---- OBJ -------------------------------------------------------------------------------------

struct ObjFace {
  std::vector<std::int64_t> corner;  // resolved 0-based, or ≥ 1 (1-based) for a deferred check
  std::vector<bool> absolute;        // corner given as a positive index
  std::string group;
  std::size_t line = 0;
};

}  // namespace

double triangle_area(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return 0.5 * (b - a).cross(c - b).norm();
}

double triangle_area(const TriangleMesh& mesh, std::size_t t) {
  const auto& tr = mesh.triangles.at(t);
  return triangle_area(mesh.vertices.at(tr[0]), mesh.vertices.at(tr[1]), mesh.vertices.at(tr[2]));
}

Eigen::Vector3d triangle_normal(const TriangleMesh& mesh, std::size_t t) {
  const auto& tr = mesh.triangles.at(t);
  const Eigen::Vector3d& a = mesh.vertices.at(tr[0]);
  const Eigen::Vector3d& b = mesh.vertices.at(tr[1]);
  const Eigen::Vector3d& c = mesh.vertices.at(tr[2]);
  return (b - a).cross(c - b).normalized();
}

bool degenerate_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  const double twice_area = (b - a).cross(c - b).norm();
  const double longest2 =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return !(twice_area > 1e-14 * longest2);
}

void validate_mesh(const TriangleMesh& mesh, const std::string& source) {
  if (mesh.triangles.empty()) throw InputError(source, "no triangles");
  if (mesh.group.size() != mesh.triangles.size())
    throw InputError(source, "one group per triangle expected",
                     std::to_string(mesh.group.size()) + " groups for " +
                         std::to_string(mesh.triangles.size()) + " triangles");
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    for (int d = 0; d < 3; ++d)
      if (!std::isfinite(mesh.vertices[v][d]))
        throw InputError(source, "vertex " + std::to_string(v) + " coordinate is not finite",
                         value_str(mesh.vertices[v][d]));
  const auto nv = static_cast<long long>(mesh.vertices.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tr = mesh.triangles[t];
    for (int k = 0; k < 3; ++k)
      if (tr[k] < 0 || tr[k] >= nv)
        throw InputError(source, "triangle " + std::to_string(t) + ": vertex index out of range",
                         std::to_string(tr[k]) + " of " + std::to_string(nv) + " vertices");
    if (mesh.group[t] < 0 || static_cast<std::size_t>(mesh.group[t]) >= mesh.group_names.size())
      throw InputError(source, "triangle " + std::to_string(t) + ": group index out of range",
                       std::to_string(mesh.group[t]) + " of " +
                           std::to_string(mesh.group_names.size()) + " groups");
    const auto& a = mesh.vertices[tr[0]];
    const auto& b = mesh.vertices[tr[1]];
    const auto& c = mesh.vertices[tr[2]];
    if (degenerate_triangle(a, b, c))
      throw InputError(source, zero_area_what(t), corners_str(a, b, c));
  }
}

TriangleMesh read_stl(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string bytes = text::read_file_bytes(path);
  std::size_t b = 0;
  while (b < bytes.size() && is_blank(static_cast<unsigned char>(bytes[b]))) ++b;
  if (b == bytes.size()) throw InputError(name, "empty file");
  const bool solid = lower(std::string_view(bytes).substr(b, 5)) == "solid";
  bool exact_binary = false;
  if (bytes.size() >= 84)
    exact_binary = bytes.size() == 84 + 50 * static_cast<std::uint64_t>(le_u32(bytes.data() + 80));
  if (solid && !exact_binary && bytes.find('\0') == std::string::npos)
    return parse_ascii_stl(name, bytes);
  return parse_binary_stl(name, bytes);
}

TriangleMesh read_obj(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string text = text::read_text_file(path);
  if (text::trim(text).empty()) throw InputError(name, "empty file");
  const auto lines = text::split_lines(text);
  std::vector<Eigen::Vector3d> verts;
  std::vector<ObjFace> faces;
  std::string group = kDefaultGroup;
  for (std::size_t li = 0; li < lines.size(); ++li) {
    const std::size_t ln = li + 1;
    const auto tok = text::split_ws(lines[li]);
    if (tok.empty() || tok[0].front() == '#') continue;
    if (tok[0] == "v") {
      if (tok.size() < 4)
        throw InputError(name, line_prefix(ln) + "v needs 3 coordinates",
                         std::to_string(tok.size() - 1) + " given");
      static const char* field[3] = {"vertex x", "vertex y", "vertex z"};
      Eigen::Vector3d v;
      for (int d = 0; d < 3; ++d) {
        v[d] = text::to_double(tok[1 + d], name, ln, field[d]);
        if (!std::isfinite(v[d]))
          throw InputError(name, line_prefix(ln) + "vertex coordinate is not finite",
                           value_str(v[d]));
      }
      verts.push_back(v);
    } else if (tok[0] == "f") {
      if (tok.size() < 4)
        throw InputError(name, line_prefix(ln) + "face needs at least 3 vertices",
                         std::to_string(tok.size() - 1) + " given");
      ObjFace f;
      f.group = group;
      f.line = ln;
      for (std::size_t k = 1; k < tok.size(); ++k) {
        const auto slash = tok[k].find('/');
        const auto idx_tok = tok[k].substr(0, slash);
        const std::int64_t i = text::to_int(idx_tok, name, ln, "face vertex index");
        if (i == 0)
          throw InputError(name,
                           line_prefix(ln) + "face vertex index must not be 0, OBJ counts from 1",
                           std::string(tok[k].substr(0, 40)));
        if (i < 0) {
          const std::int64_t r = static_cast<std::int64_t>(verts.size()) + i;
          if (r < 0)
            throw InputError(
                name, line_prefix(ln) + "vertex index out of range",
                std::to_string(i) + " with " + std::to_string(verts.size()) + " vertices defined");
          f.corner.push_back(r);
          f.absolute.push_back(false);
        } else {
          f.corner.push_back(i);
          f.absolute.push_back(true);
        }
      }
      faces.push_back(std::move(f));
    } else if (tok[0] == "g" || tok[0] == "o") {
      group = std::string(text::trim(text::trim(lines[li]).substr(1)));
      if (group.empty()) group = kDefaultGroup;
    }
  }
  MeshBuilder mb;  // used for its groups only: OBJ vertices are kept as listed
  TriangleMesh out;
  out.vertices = verts;
  for (const auto& f : faces) {
    std::vector<int> c(f.corner.size());
    for (std::size_t k = 0; k < c.size(); ++k) {
      std::int64_t r = f.corner[k];
      if (f.absolute[k]) {
        if (r > static_cast<std::int64_t>(verts.size()))
          throw InputError(name, line_prefix(f.line) + "vertex index out of range",
                           std::to_string(r) + " with " + std::to_string(verts.size()) +
                               " vertices in the file");
        r -= 1;
      }
      c[k] = static_cast<int>(r);
    }
    mb.select_group(f.group);
    for (std::size_t k = 1; k + 1 < c.size(); ++k) {
      const std::size_t t = mb.triangle_count();
      const auto& a = verts[c[0]];
      const auto& b = verts[c[k]];
      const auto& d = verts[c[k + 1]];
      if (degenerate_triangle(a, b, d))
        throw InputError(name, line_prefix(f.line) + zero_area_what(t), corners_str(a, b, d));
      mb.triangle(c[0], c[k], c[k + 1]);
    }
  }
  if (mb.triangle_count() == 0) throw InputError(name, "no triangles");
  TriangleMesh g = mb.take();
  out.triangles = std::move(g.triangles);
  out.group = std::move(g.group);
  out.group_names = std::move(g.group_names);
  return out;
}

TriangleMesh read_triangle_text(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string text = text::read_text_file(path);
  const auto lines = text::split_lines(text);
  MeshBuilder mb;
  static const char* field[9] = {"vertex1_X", "vertex1_Y", "vertex1_Z", "vertex2_X", "vertex2_Y",
                                 "vertex2_Z", "vertex3_X", "vertex3_Y", "vertex3_Z"};
  bool header = false;
  for (std::size_t li = 0; li < lines.size(); ++li) {
    const std::size_t ln = li + 1;
    const auto tok = text::split_ws(lines[li]);
    if (tok.empty() || tok[0].front() == '#') continue;
    if (!header) {  // the first non-blank line names the nine columns
      if (tok.size() != 9 || tok[0].substr(0, 9) != "vertex1_X")
        throw InputError(name,
                         line_prefix(ln) + "expected the header vertex1_X[m] ... vertex3_Z[m]",
                         std::string(tok[0].substr(0, 40)));
      header = true;
      continue;
    }
    if (tok.size() != 9)
      throw InputError(name, line_prefix(ln) + "expected 9 numbers",
                       std::to_string(tok.size()) + " given");
    std::array<Eigen::Vector3d, 3> c;
    for (int k = 0; k < 9; ++k) {
      const double v = text::to_double(tok[static_cast<std::size_t>(k)], name, ln, field[k]);
      if (!std::isfinite(v))
        throw InputError(name, line_prefix(ln) + "vertex coordinate is not finite", value_str(v));
      c[static_cast<std::size_t>(k / 3)][k % 3] = v;
    }
    const std::size_t t = mb.triangle_count();
    if (degenerate_triangle(c[0], c[1], c[2]))
      throw InputError(name, line_prefix(ln) + zero_area_what(t), corners_str(c[0], c[1], c[2]));
    mb.triangle(mb.vertex(c[0]), mb.vertex(c[1]), mb.vertex(c[2]));
  }
  if (mb.triangle_count() == 0) throw InputError(name, "no triangles");
  return mb.take();
}

TriangleMesh read_mesh(const std::filesystem::path& path, double scale) {
  if (!(std::isfinite(scale) && scale > 0))
    throw std::invalid_argument("read_mesh: scale must be finite and > 0 (" + value_str(scale) +
                                ")");
  const std::string ext = lower(path.extension().string());
  TriangleMesh m;
  if (ext == ".stl") {
    m = read_stl(path);
  } else if (ext == ".obj") {
    m = read_obj(path);
  } else if (ext == ".txt") {
    m = read_triangle_text(path);
  } else {
    throw InputError(path.string(), "unknown mesh format (expected .stl, .obj or .txt)",
                     ext.empty() ? std::string("no extension") : ext);
  }
  if (scale != 1.0) {
    for (auto& v : m.vertices) v *= scale;
    validate_mesh(m, path.string());
  }
  return m;
}

void write_stl_ascii(const TriangleMesh& mesh, const std::filesystem::path& path) {
  const std::string name = path.string();
  validate_mesh(mesh, name);
  AtomicOutput out(path);
  {
    std::ofstream o(out.temp_path(), std::ios::binary);
    if (!o) throw InputError(name, "cannot write file");
    char buf[256];
    for (std::size_t g = 0; g < mesh.group_names.size(); ++g) {
      if (std::find(mesh.group.begin(), mesh.group.end(), static_cast<int>(g)) == mesh.group.end())
        continue;
      std::string label(text::trim(mesh.group_names[g]));
      for (auto& ch : label)
        if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = '_';
      if (label.empty()) label = kDefaultGroup;
      o << "solid " << label << "\n";
      for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (mesh.group[t] != static_cast<int>(g)) continue;
        const Eigen::Vector3d n = triangle_normal(mesh, t);
        std::snprintf(buf, sizeof buf, "  facet normal %.17g %.17g %.17g\n    outer loop\n", n.x(),
                      n.y(), n.z());
        o << buf;
        for (int k = 0; k < 3; ++k) {
          const auto& v = mesh.vertices[mesh.triangles[t][k]];
          std::snprintf(buf, sizeof buf, "      vertex %.17g %.17g %.17g\n", v.x(), v.y(), v.z());
          o << buf;
        }
        o << "    endloop\n  endfacet\n";
      }
      o << "endsolid " << label << "\n";
    }
    if (!o.flush()) throw InputError(name, "write failed");
  }
  out.commit();
}

}  // namespace gs
