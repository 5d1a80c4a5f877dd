#include "liggghts_dump.hpp"

#include <algorithm>
#include <map>
#include <unordered_map>

#include "errors.hpp"
#include "text_parse.hpp"

namespace gs {

namespace {

struct Block {
  std::int64_t step = 0;
  std::size_t count = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  bool periodic = false;
  std::vector<std::string> columns;
  std::vector<std::vector<std::string_view>> rows;
  std::size_t first_row_line = 0;
  std::size_t line = 0;  // of its ITEM: TIMESTEP
};

// Parses ITEM: blocks. `entries_item` is "ATOMS" (custom dump) or "ENTRIES" (local dump).
std::vector<Block> parse_blocks(const std::string& text, const std::string& name,
                                const char* count_item, const char* rows_item) {
  const auto lines = text::split_lines(text);
  std::vector<Block> blocks;
  std::size_t i = 0;
  auto need_line = [&](std::size_t k) {
    if (k >= lines.size())
      throw InputError(name, "truncated dump at line " + std::to_string(k + 1));
    return lines[k];
  };
  while (i < lines.size()) {
    const auto l = text::trim(lines[i]);
    if (l.empty()) {
      ++i;
      continue;
    }
    if (l != "ITEM: TIMESTEP")
      throw InputError(name, "line " + std::to_string(i + 1) + ": expected ITEM: TIMESTEP",
                       std::string(l.substr(0, 40)));
    Block b;
    b.line = i + 1;
    b.step = text::to_int(text::trim(need_line(i + 1)), name, i + 2, "timestep");
    i += 2;
    const std::string count_hdr = std::string("ITEM: NUMBER OF ") + count_item;
    if (text::trim(need_line(i)) != count_hdr)
      throw InputError(name, "line " + std::to_string(i + 1) + ": expected " + count_hdr);
    const auto n = text::to_int(text::trim(need_line(i + 1)), name, i + 2, "count");
    if (n < 0 || n > (1ll << 31)) throw InputError(name, "bad count", std::to_string(n));
    b.count = static_cast<std::size_t>(n);
    i += 2;
    const auto box = text::trim(need_line(i));
    if (box.rfind("ITEM: BOX BOUNDS", 0) != 0)
      throw InputError(name, "line " + std::to_string(i + 1) + ": expected ITEM: BOX BOUNDS");
    const auto flags = text::split_ws(box.substr(16));
    b.periodic = !flags.empty();
    for (auto fl : flags)
      if (fl != "pp") b.periodic = false;
    for (int d = 0; d < 3; ++d) {
      const auto t = text::split_ws(need_line(i + 1 + d));
      if (t.size() < 2)
        throw InputError(name, "line " + std::to_string(i + 2 + d) + ": bad box bounds");
      b.lo[d] = text::to_double(t[0], name, i + 2 + d, "box bounds");
      b.hi[d] = text::to_double(t[1], name, i + 2 + d, "box bounds");
    }
    i += 4;
    const auto hdr = text::trim(need_line(i));
    const std::string rows_hdr = std::string("ITEM: ") + rows_item;
    if (hdr.rfind(rows_hdr, 0) != 0)
      throw InputError(name, "line " + std::to_string(i + 1) + ": expected " + rows_hdr);
    for (auto c : text::split_ws(hdr.substr(rows_hdr.size()))) b.columns.emplace_back(c);
    ++i;
    b.first_row_line = i + 1;
    b.rows.reserve(std::min(b.count, lines.size()));
    for (std::size_t r = 0; r < b.count; ++r) {
      const auto t = text::split_ws(need_line(i + r));
      if (!b.columns.empty() && t.size() != b.columns.size())
        throw InputError(name,
                         "line " + std::to_string(i + r + 1) + ": expected " +
                             std::to_string(b.columns.size()) + " columns",
                         std::to_string(t.size()));
      b.rows.push_back(t);
    }
    i += b.count;
    blocks.push_back(std::move(b));
  }
  if (blocks.empty()) throw InputError(name, "no ITEM: TIMESTEP block (not a LIGGGHTS dump)");
  // Frames (and the pairs matched to them) are keyed by timestep: a repeated one would put every
  // pair on the last frame of that step.
  std::map<std::int64_t, std::size_t> seen;
  for (const auto& b : blocks) {
    const auto [it, fresh] = seen.emplace(b.step, b.line);
    if (!fresh)
      throw InputError(name,
                       "line " + std::to_string(b.line) + ": timestep repeats the block at line " +
                           std::to_string(it->second),
                       std::to_string(b.step));
  }
  return blocks;
}

int find_col(const std::vector<std::string>& cols, std::initializer_list<const char*> names) {
  for (const char* n : names)
    for (std::size_t c = 0; c < cols.size(); ++c)
      if (cols[c] == n) return static_cast<int>(c);
  return -1;
}

}  // namespace

std::optional<std::filesystem::path> liggghts_pairs_sibling(const std::filesystem::path& atoms) {
  std::string fn = atoms.filename().string();
  const auto k = fn.rfind("atoms");
  if (k == std::string::npos) return std::nullopt;
  fn.replace(k, 5, "pairs");
  const auto p = atoms.parent_path() / fn;
  std::error_code ec;
  if (std::filesystem::is_regular_file(p, ec)) return p;
  return std::nullopt;
}

Trajectory read_liggghts_dump(const std::filesystem::path& atoms_path,
                              const LiggghtsImportOptions& opt) {
  const std::string name = atoms_path.string();
  const std::string text = text::read_text_file(atoms_path);
  const auto blocks = parse_blocks(text, name, "ATOMS", "ATOMS");
  Trajectory t;
  t.metadata.code_version = code_version();
  t.metadata.provenance = "imported from LIGGGHTS/LAMMPS dump " + name;
  t.metadata.parameters.emplace_back("source_format", "liggghts-dump");
  for (const auto& b : blocks) {
    const int cid = find_col(b.columns, {"id"});
    const int cx = find_col(b.columns, {"x", "xu"}), cy = find_col(b.columns, {"y", "yu"}),
              cz = find_col(b.columns, {"z", "zu"});
    const int cr = find_col(b.columns, {"radius"});
    const char* missing = cid < 0  ? "id"
                          : cx < 0 ? "x"
                          : cy < 0 ? "y"
                          : cz < 0 ? "z"
                          : cr < 0 ? "radius"
                                   : nullptr;
    if (missing)
      throw InputError(name, "timestep " + std::to_string(b.step) + ": missing column", missing);
    const int ctype = find_col(b.columns, {"type"}), cm = find_col(b.columns, {"mass"});
    const int cv[3] = {find_col(b.columns, {"vx"}), find_col(b.columns, {"vy"}),
                       find_col(b.columns, {"vz"})};
    const int cw[3] = {find_col(b.columns, {"omegax"}), find_col(b.columns, {"omegay"}),
                       find_col(b.columns, {"omegaz"})};
    Frame f;
    f.step = b.step;
    f.dt = opt.dt;
    f.time = static_cast<double>(b.step) * opt.dt;
    f.domain.lo = b.lo;
    f.domain.hi = b.hi;
    f.domain.periodic = b.periodic;
    f.domain.cell = (b.hi - b.lo).asDiagonal();
    f.particles.resize(b.rows.size());
    for (std::size_t r = 0; r < b.rows.size(); ++r) {
      const auto& row = b.rows[r];
      const std::size_t ln = b.first_row_line + r;
      auto& p = f.particles[r];
      p.id = text::to_int(row[cid], name, ln, "id");
      p.position = {text::to_double(row[cx], name, ln, "x"),
                    text::to_double(row[cy], name, ln, "y"),
                    text::to_double(row[cz], name, ln, "z")};
      p.radius = text::to_double(row[cr], name, ln, "radius");
      if (ctype >= 0)
        p.material_id = static_cast<std::int32_t>(text::to_int(row[ctype], name, ln, "type"));
      if (cm >= 0) p.mass = text::to_double(row[cm], name, ln, "mass");
      for (int d = 0; d < 3; ++d) {
        if (cv[d] >= 0) p.velocity[d] = text::to_double(row[cv[d]], name, ln, "velocity");
        if (cw[d] >= 0) p.angular_velocity[d] = text::to_double(row[cw[d]], name, ln, "omega");
      }
    }
    t.frames.push_back(std::move(f));
  }

  std::optional<std::filesystem::path> pairs = opt.pairs;
  if (!pairs) pairs = liggghts_pairs_sibling(atoms_path);
  if (pairs) {
    const std::string pname = pairs->string();
    const std::string ptext = text::read_text_file(*pairs);
    const auto pblocks = parse_blocks(ptext, pname, "ENTRIES", "ENTRIES");
    std::map<std::string, int> col;
    for (std::size_t k = 0; k < opt.pair_columns.size(); ++k)
      col[opt.pair_columns[k]] = static_cast<int>(k);
    for (const char* need : {"id1", "id2", "fx", "fy", "fz"})
      if (!col.count(need)) throw InputError(pname, "pair column mapping lacks", need);
    std::map<std::int64_t, Frame*> by_step;
    for (auto& f : t.frames) by_step[f.step] = &f;
    for (const auto& b : pblocks) {
      auto it = by_step.find(b.step);
      if (it == by_step.end())
        throw InputError(pname, "pair timestep has no atom frame", std::to_string(b.step));
      Frame& f = *it->second;
      std::unordered_map<std::int64_t, const Particle*> byid;
      for (const auto& p : f.particles) byid[p.id] = &p;
      for (std::size_t r = 0; r < b.rows.size(); ++r) {
        const auto& row = b.rows[r];
        const std::size_t ln = b.first_row_line + r;
        if (row.size() < opt.pair_columns.size())
          throw InputError(pname,
                           "line " + std::to_string(ln) + ": expected " +
                               std::to_string(opt.pair_columns.size()) + " columns",
                           std::to_string(row.size()));
        auto num = [&](const char* c) { return text::to_double(row[col.at(c)], pname, ln, c); };
        Contact c;
        c.id1 = text::to_int(row[col.at("id1")], pname, ln, "id1");
        c.id2 = text::to_int(row[col.at("id2")], pname, ln, "id2");
        const auto p1 = byid.find(c.id1), p2 = byid.find(c.id2);
        if (p1 == byid.end() || p2 == byid.end())
          throw InputError(pname, "line " + std::to_string(ln) + ": contact names an unknown atom",
                           std::to_string(p1 == byid.end() ? c.id1 : c.id2));
        const Eigen::Vector3d x1 = p1->second->position, x2 = p2->second->position;
        const double r1 = p1->second->radius, r2 = p2->second->radius;
        const Eigen::Vector3d branch = x2 - x1;
        const double dist = branch.norm();
        if (!(dist > 0))
          throw InputError(pname, "line " + std::to_string(ln) + ": coincident centres");
        c.normal = branch / dist;
        c.overlap = r1 + r2 - dist;
        c.point = x1 + (r1 - 0.5 * c.overlap) * c.normal;
        // LIGGGHTS reports the force on the first atom; YADE's convention stores the force on
        // the second one.
        const Eigen::Vector3d force = -Eigen::Vector3d(num("fx"), num("fy"), num("fz"));
        c.normal_force = force.dot(c.normal) * c.normal;
        c.shear_force = force - c.normal_force;
        f.contacts.push_back(c);
      }
    }
  }
  for (std::size_t i = 0; i < t.frames.size(); ++i)
    validate_frame(t.frames[i], name + " timestep " + std::to_string(t.frames[i].step));
  return t;
}

}  // namespace gs
