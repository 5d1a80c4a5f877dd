#include "vtk_legacy.hpp"

#include "errors.hpp"
#include "text_parse.hpp"

namespace gs {

namespace {

// Token stream over the file's lines, remembering line numbers for messages.
struct Tokens {
  std::vector<std::pair<std::string_view, std::size_t>> tok;
  std::size_t i = 0;
  std::string name;

  bool done() const { return i >= tok.size(); }
  std::string_view peek() const { return done() ? std::string_view{} : tok[i].first; }
  std::size_t line() const {
    return done() ? (tok.empty() ? 0 : tok.back().second) : tok[i].second;
  }
  std::string_view next(const char* what) {
    if (done()) throw InputError(name, std::string("unexpected end of file, expected ") + what);
    return tok[i++].first;
  }
  long long next_int(const char* what) { return text::to_int(next(what), name, line(), what); }
  double next_double(const char* what) {
    const auto ln = line();
    return text::to_double(next(what), name, ln, what);
  }
  std::size_t next_count(const char* what, std::size_t limit) {
    const long long n = next_int(what);
    if (n < 0 || static_cast<std::size_t>(n) > limit)
      throw InputError(name, std::string("line ") + std::to_string(line()) + ": bad " + what,
                       std::to_string(n));
    return static_cast<std::size_t>(n);
  }
};

std::vector<std::vector<long long>> read_cells(Tokens& t, std::size_t npoints) {
  const std::size_t n = t.next_count("cell count", t.tok.size());
  const std::size_t size = t.next_count("cell list size", t.tok.size());
  std::vector<std::vector<long long>> cells(n);
  std::size_t used = 0;
  for (auto& c : cells) {
    const std::size_t k = t.next_count("cell size", t.tok.size());
    used += k + 1;
    c.resize(k);
    for (auto& v : c) {
      v = t.next_int("point index");
      if (v < 0 || static_cast<std::size_t>(v) >= npoints)
        throw InputError(t.name, "line " + std::to_string(t.line()) + ": point index out of range",
                         std::to_string(v));
    }
  }
  if (used != size) throw InputError(t.name, "cell list size mismatch", std::to_string(size));
  return cells;
}

void read_attributes(Tokens& t, std::size_t n, std::map<std::string, LegacyPolyData::Array>& out) {
  while (!t.done()) {
    const auto kw = t.peek();
    if (kw == "POINT_DATA" || kw == "CELL_DATA") return;
    t.next("attribute");
    LegacyPolyData::Array a;
    std::string name;
    std::size_t tuples = n;
    if (kw == "SCALARS") {
      name = std::string(t.next("name"));
      t.next("type");
      // Optional component count, then LOOKUP_TABLE.
      if (t.peek() != "LOOKUP_TABLE")
        a.components = static_cast<int>(t.next_count("components", 4));
      if (t.peek() == "LOOKUP_TABLE") {
        t.next("LOOKUP_TABLE");
        t.next("table name");
      }
    } else if (kw == "VECTORS" || kw == "NORMALS") {
      name = std::string(t.next("name"));
      t.next("type");
      a.components = 3;
    } else if (kw == "FIELD") {
      t.next("field name");
      const std::size_t arrays = t.next_count("array count", 1000);
      for (std::size_t k = 0; k < arrays; ++k) {
        LegacyPolyData::Array f;
        const std::string fname(t.next("array name"));
        f.components = static_cast<int>(t.next_count("components", 64));
        const std::size_t ft = t.next_count("tuples", t.tok.size());
        t.next("type");
        if (ft != n) throw InputError(t.name, "FIELD array length differs from data count", fname);
        f.values.resize(ft * static_cast<std::size_t>(f.components));
        for (auto& v : f.values) v = t.next_double(fname.c_str());
        out[fname] = std::move(f);
      }
      continue;
    } else {
      throw InputError(t.name, "line " + std::to_string(t.line()) + ": unsupported keyword",
                       std::string(kw.substr(0, 40)));
    }
    if (a.components < 1) throw InputError(t.name, "bad component count for", name);
    a.values.resize(tuples * static_cast<std::size_t>(a.components));
    for (auto& v : a.values) v = t.next_double(name.c_str());
    out[name] = std::move(a);
  }
}

}  // namespace

LegacyPolyData read_legacy_polydata(const std::filesystem::path& path) {
  Tokens t;
  t.name = path.string();
  const std::string text = text::read_text_file(path);
  const auto lines = text::split_lines(text);
  if (lines.size() < 4 || lines[0].rfind("# vtk DataFile", 0) != 0)
    throw InputError(t.name, "not a legacy VTK file (missing '# vtk DataFile' header)");
  if (text::trim(lines[2]) != "ASCII")
    throw InputError(t.name, "only ASCII legacy VTK is supported",
                     std::string(text::trim(lines[2]).substr(0, 20)));
  for (std::size_t l = 3; l < lines.size(); ++l)
    for (auto tok : text::split_ws(lines[l])) t.tok.emplace_back(tok, l + 1);
  if (t.next("DATASET") != "DATASET" || t.next("POLYDATA") != "POLYDATA")
    throw InputError(t.name, "only DATASET POLYDATA is supported");
  LegacyPolyData d;
  std::size_t npoints = 0;
  while (!t.done()) {
    const auto kw = t.next("keyword");
    if (kw == "POINTS") {
      npoints = t.next_count("point count", t.tok.size());
      t.next("type");
      d.points.resize(npoints * 3);
      for (auto& v : d.points) v = t.next_double("point coordinate");
    } else if (kw == "VERTICES") {
      d.vertices = read_cells(t, npoints);
    } else if (kw == "LINES") {
      d.lines = read_cells(t, npoints);
    } else if (kw == "POLYGONS" || kw == "TRIANGLE_STRIPS") {
      read_cells(t, npoints);
    } else if (kw == "POINT_DATA") {
      const std::size_t n = t.next_count("POINT_DATA count", t.tok.size());
      if (n != npoints)
        throw InputError(t.name, "POINT_DATA count differs from POINTS", std::to_string(n));
      read_attributes(t, n, d.point_data);
    } else if (kw == "CELL_DATA") {
      const std::size_t n = t.next_count("CELL_DATA count", t.tok.size());
      read_attributes(t, n, d.cell_data);
    } else {
      throw InputError(t.name, "line " + std::to_string(t.line()) + ": unsupported keyword",
                       std::string(kw.substr(0, 40)));
    }
  }
  return d;
}

}  // namespace gs
