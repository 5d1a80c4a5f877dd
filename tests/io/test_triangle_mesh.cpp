// Triangle meshes: STL (ASCII, binary) and OBJ readers, the ASCII STL writer, their errors, and
// the YADE facets reference mesh. The test meshes are written by hand here, byte by byte.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "errors.hpp"
#include "test_util.hpp"
#include "triangle_mesh.hpp"

using namespace gs;
using gs::test::ScratchDir;
namespace fs = std::filesystem;

namespace {

void write_file(const fs::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << s;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// The unit cube [0,1]³: corner i has coordinates (i & 1, (i >> 1) & 1, (i >> 2) & 1). Each face
// is a quad, counter-clockwise seen from outside; faces 0–3 (x and y) form group "sides",
// faces 4–5 (z) group "caps".
const Eigen::Vector3d kCorner[8] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                    {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
const int kQuad[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                         {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
const Eigen::Vector3d kOutward[6] = {{-1, 0, 0}, {1, 0, 0},  {0, -1, 0},
                                     {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};

// The 12 triangles (quad split along its first diagonal) as corner triples.
std::vector<std::array<Eigen::Vector3d, 3>> cube_triangles() {
  std::vector<std::array<Eigen::Vector3d, 3>> t;
  for (const auto& q : kQuad) {
    t.push_back({kCorner[q[0]], kCorner[q[1]], kCorner[q[2]]});
    t.push_back({kCorner[q[0]], kCorner[q[2]], kCorner[q[3]]});
  }
  return t;
}

std::string cube_ascii_stl() {
  std::ostringstream s;
  const auto tri = cube_triangles();
  for (int solid = 0; solid < 2; ++solid) {
    s << "solid " << (solid == 0 ? "sides" : "caps") << "\n";
    for (std::size_t t = solid == 0 ? 0 : 8; t < (solid == 0 ? 8u : 12u); ++t) {
      const auto& n = kOutward[t / 2];
      s << "  facet normal " << n.x() << " " << n.y() << " " << n.z() << "\n    outer loop\n";
      for (const auto& v : tri[t])
        s << "      vertex " << v.x() << ".0 " << v.y() << "e0 " << v.z() << "\n";
      s << "    endloop\n  endfacet\n";
    }
    s << "endsolid\n";
  }
  return s.str();
}

void put_u32(std::string& b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b += static_cast<char>((v >> (8 * i)) & 0xff);
}
void put_f32(std::string& b, float f) {
  put_u32(b, std::bit_cast<std::uint32_t>(f));
}

// Binary STL; the header deliberately starts with "solid" (as many exporters write it).
std::string binary_stl(const std::vector<std::array<Eigen::Vector3d, 3>>& tri,
                       std::uint32_t count) {
  std::string b = "solid binary cube, which is not an ASCII file";
  b.resize(80, ' ');
  put_u32(b, count);
  for (const auto& t : tri) {
    for (int d = 0; d < 3; ++d) put_f32(b, 0.0f);  // normal: ignored by the reader
    for (const auto& v : t)
      for (int d = 0; d < 3; ++d) put_f32(b, static_cast<float>(v[d]));
    b += std::string(2, '\0');
  }
  return b;
}

// The cube as quads, exercising every corner form and negative indices.
std::string cube_obj() {
  std::ostringstream s;
  s << "# unit cube\nmtllib cube.mtl\no cube\n";
  for (const auto& v : kCorner) s << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  s << "vt 0 0\nvn 0 0 1\ng sides\n";
  s << "f 1 5 7 3\n";                  // v
  s << "f 2/1 4/1 8/1 6/1\n";          // v/vt
  s << "f 1/1/1 2/1/1 6/1/1 5/1/1\n";  // v/vt/vn
  s << "f 3//1 7//1 8//1 4//1\n";      // v//vn
  s << "usemtl steel\ns off\no caps\n";
  s << "f -8 -6 -5 -7\n";  // negative: relative to the 8 vertices so far
  s << "f 5 6 8 7\n";
  return s.str();
}

// Σ over triangles of v0·(v1 × v2)/6: the enclosed volume of a closed, outward-oriented surface.
double enclosed_volume(const TriangleMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles)
    v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
  return v;
}

double total_area(const TriangleMesh& m) {
  double a = 0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) a += triangle_area(m, t);
  return a;
}

// Every undirected edge in exactly two triangles, once in each direction (closed, consistently
// oriented; only possible when shared edges share vertex indices).
bool closed_and_consistent(const TriangleMesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;
    const auto r = directed.find({e.second, e.first});
    if (r == directed.end() || r->second != 1) return false;
  }
  return true;
}

void expect_unit_cube(const TriangleMesh& m, bool grouped) {
  EXPECT_EQ(m.vertices.size(), 8u);
  ASSERT_EQ(m.triangles.size(), 12u);
  ASSERT_EQ(m.group.size(), 12u);
  EXPECT_TRUE(closed_and_consistent(m));
  EXPECT_EQ(total_area(m), 6.0);
  EXPECT_NEAR(enclosed_volume(m), 1.0, 1e-15);
  const auto tri = cube_triangles();
  for (std::size_t t = 0; t < 12; ++t) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.vertices[m.triangles[t][k]], tri[t][k]) << t;
    EXPECT_EQ(triangle_normal(m, t), kOutward[t / 2]) << "triangle " << t;
    const std::string want = grouped ? (t < 8 ? "sides" : "caps") : "mesh";
    EXPECT_EQ(m.group_names.at(m.group[t]), want) << t;
  }
  EXPECT_EQ(m.group_names.size(), grouped ? 2u : 1u);
}

}  // namespace

// ASCII STL of the unit cube in two solids: 8 vertices after merging, 12 triangles, groups
// "sides" and "caps", area exactly 6, divergence-theorem volume 1 (1e-15), every facet normal
// the outward axis (orientation kept), every edge shared by two triangles.
TEST(TriangleMesh, AsciiStlCube) {
  ScratchDir dir("tmesh_ascii");
  write_file(dir / "cube.stl", cube_ascii_stl());
  expect_unit_cube(read_stl(dir / "cube.stl"), true);
}

// Binary STL of the same cube, header starting with "solid": read as binary (size 84 + 50·12
// = 684), same geometry, one group "mesh".
TEST(TriangleMesh, BinaryStlCubeWithSolidHeader) {
  ScratchDir dir("tmesh_binary");
  const std::string b = binary_stl(cube_triangles(), 12);
  ASSERT_EQ(b.size(), 684u);
  write_file(dir / "cube.stl", b);
  expect_unit_cube(read_stl(dir / "cube.stl"), false);
}

// OBJ quads (v, v/vt, v/vt/vn, v//vn, negative indices) fan-triangulated into the same 12
// triangles; groups from `g sides` and `o caps`; read_mesh with scale 1e-3 multiplies every
// coordinate (each vertex exactly v·1e-3) and the area becomes 6e-6.
TEST(TriangleMesh, ObjCubeAndScale) {
  ScratchDir dir("tmesh_obj");
  write_file(dir / "cube.obj", cube_obj());
  expect_unit_cube(read_obj(dir / "cube.obj"), true);
  const TriangleMesh mm = read_mesh(dir / "cube.obj", 1e-3);
  ASSERT_EQ(mm.vertices.size(), 8u);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(mm.vertices[i], kCorner[i] * 1e-3);
  EXPECT_NEAR(total_area(mm), 6e-6, 1e-21);
  write_file(dir / "CUBE.STL", cube_ascii_stl());
  EXPECT_EQ(read_mesh(dir / "CUBE.STL").triangles.size(), 12u);
}

// The DEM8 wall format (header of nine column names, nine numbers per triangle line, CRLF):
// the same cube, one group "mesh"; read_mesh picks it by the .txt extension. Bad input: a
// missing header, a short row, a zero-area triangle, each one line naming file and line.
TEST(TriangleMesh, TriangleTextCubeAndErrors) {
  ScratchDir dir("tmesh_txt");
  std::ostringstream o;
  o << "vertex1_X[m]\tvertex1_Y[m]\tvertex1_Z[m]\tvertex2_X[m]\tvertex2_Y[m]\tvertex2_Z[m]\t"
       "vertex3_X[m]\tvertex3_Y[m]\tvertex3_Z[m]\r\n";
  o.precision(17);
  for (const auto& t : cube_triangles()) {
    for (int k = 0; k < 3; ++k) o << t[k].x() << " " << t[k].y() << "\t" << t[k].z() << " ";
    o << "\r\n";
  }
  write_file(dir / "cube.txt", o.str());
  expect_unit_cube(read_triangle_text(dir / "cube.txt"), false);
  const TriangleMesh twice = read_mesh(dir / "cube.txt", 2.0);
  EXPECT_EQ(twice.vertices[twice.triangles[3][1]], cube_triangles()[3][1] * 2.0);
  const std::string h =
      "vertex1_X[m] vertex1_Y[m] vertex1_Z[m] vertex2_X[m] vertex2_Y[m] vertex2_Z[m] "
      "vertex3_X[m] vertex3_Y[m] vertex3_Z[m]\n";
  auto err = [&](const std::string& name, const std::string& text) {
    write_file(dir / name, text);
    return error_of([&] { (void)read_triangle_text(dir / name); });
  };
  const std::string f = (dir / "a.txt").string();
  EXPECT_EQ(err("a.txt", "0 0 0 1 0 0 0 1 0\n"),
            f + ": line 1: expected the header vertex1_X[m] ... vertex3_Z[m] (0)");
  EXPECT_EQ(err("a.txt", h + "0 0 0 1 0 0 0 1\n"), f + ": line 2: expected 9 numbers (8 given)");
  EXPECT_EQ(err("a.txt", h + "0 0 0 1 0 0 1 0 0\n"),
            f + ": line 2: triangle 0 has zero area (0 0 0 | 1 0 0 | 1 0 0)");
  EXPECT_EQ(err("a.txt", h), f + ": no triangles");
  EXPECT_EQ(err("a.txt", h + "0 0 0 1 0 0 0 x 0\n").substr(0, f.size() + 8), f + ": line 2");
}

// The DEM8 benchmark's wall files (../shared/dem8; skipped without them): the triangle counts
// their README gives, finite, no zero-area triangle (the reader would refuse one).
TEST(TriangleMesh, Dem8WallFiles) {
  const fs::path d = fs::path(GS_SOURCE_DIR) / ".." / "shared" / "dem8";
  if (!fs::exists(d / "case3_penetration" / "walls.txt"))
    GTEST_SKIP() << "DEM8 inputs absent: " << d.string();
  EXPECT_EQ(read_mesh(d / "case3_penetration" / "walls.txt").triangles.size(), 56u);
  EXPECT_EQ(read_mesh(d / "case2_drum" / "walls.txt").triangles.size(), 1200u);
  EXPECT_EQ(read_mesh(d / "case1_silo" / "walls_large_orifice.txt").triangles.size(), 7632u);
  EXPECT_EQ(read_mesh(d / "case1_silo" / "walls_small_orifice.txt").triangles.size(), 8636u);
}

// write_stl_ascii then read_stl: every corner bit-identical (17 significant digits), groups and
// their order kept, the written facet normals equal triangle_normal to the bit, and no temporary
// file left beside the output.
TEST(TriangleMesh, WriteStlRoundTripExact) {
  ScratchDir dir("tmesh_write");
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1e-4, 1e-4);
  TriangleMesh m;
  for (const auto& c : kCorner)
    m.vertices.push_back(0.0137 * c + Eigen::Vector3d(u(rng), u(rng), u(rng)) -
                         Eigen::Vector3d(0.3, 1.0 / 3.0, 2e-7));
  for (const auto& q : kQuad) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  m.group_names = {"walls x-y", "lids"};
  for (int t = 0; t < 12; ++t) m.group.push_back(t < 8 ? 0 : 1);
  write_stl_ascii(m, dir / "out.stl");
  const TriangleMesh r = read_stl(dir / "out.stl");
  ASSERT_EQ(r.triangles.size(), 12u);
  EXPECT_EQ(r.vertices.size(), 8u);
  EXPECT_EQ(r.group_names, m.group_names);
  for (int t = 0; t < 12; ++t) {
    EXPECT_EQ(r.group[t], m.group[t]);
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d)
        EXPECT_EQ(std::bit_cast<std::uint64_t>(r.vertices[r.triangles[t][k]][d]),
                  std::bit_cast<std::uint64_t>(m.vertices[m.triangles[t][k]][d]));
  }
  std::ifstream in(dir / "out.stl");
  std::string line;
  int t = 0;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string w1, w2;
    ls >> w1 >> w2;
    if (w1 != "facet") continue;
    std::string x, y, z;
    ls >> x >> y >> z;
    const Eigen::Vector3d n = triangle_normal(m, t++);
    EXPECT_EQ(std::strtod(x.c_str(), nullptr), n.x());
    EXPECT_EQ(std::strtod(y.c_str(), nullptr), n.y());
    EXPECT_EQ(std::strtod(z.c_str(), nullptr), n.z());
  }
  EXPECT_EQ(t, 12);
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir.path)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

// Each bad input gives its exact one-line message "FILE: what (value)".
TEST(TriangleMesh, BadInputErrors) {
  ScratchDir dir("tmesh_bad");
  const auto stl = [&](const std::string& name, const std::string& body) {
    const fs::path p = dir / name;
    write_file(p, body);
    return std::make_pair(p.string(), error_of([&] { (void)read_stl(p); }));
  };
  const auto obj = [&](const std::string& name, const std::string& body) {
    const fs::path p = dir / name;
    write_file(p, body);
    return std::make_pair(p.string(), error_of([&] { (void)read_obj(p); }));
  };
  const std::string facet_head = "solid s\nfacet normal 0 0 1\nouter loop\n";
  const std::string facet_tail = "endloop\nendfacet\nendsolid s\n";
  {
    const auto [f, e] =
        stl("nan.stl", facet_head + "vertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\n" + facet_tail);
    EXPECT_EQ(e, f + ": line 5: vertex coordinate is not finite (nan)");
  }
  {
    const auto [f, e] =
        stl("inf.stl", facet_head + "vertex 0 0 0\nvertex 1 0 0\nvertex 0 -inf 0\n" + facet_tail);
    EXPECT_EQ(e, f + ": line 6: vertex coordinate is not finite (-inf)");
  }
  {
    const auto [f, e] =
        stl("flat.stl", facet_head + "vertex 0 0 0\nvertex 1 0 0\nvertex 2 0 0\n" + facet_tail);
    EXPECT_EQ(e, f + ": line 2: triangle 0 has zero area (0 0 0 | 1 0 0 | 2 0 0)");
  }
  {
    const auto [f, e] =
        stl("num.stl", facet_head + "vertex 0 0 0\nvertex 1 0.5.1 0\nvertex 0 1 0\n" + facet_tail);
    EXPECT_EQ(e, f + ": line 5: bad number in vertex y (0.5.1)");
  }
  {
    const auto [f, e] = stl("four.stl", facet_head + "vertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\n" +
                                            "vertex 0 1 0\n" + facet_tail);
    EXPECT_EQ(e, f + ": line 2: facet has 4 vertices, expected 3");
  }
  {
    const auto [f, e] =
        stl("cut.stl", cube_ascii_stl().substr(0, cube_ascii_stl().find("endfacet\n") + 9));
    EXPECT_EQ(e, f + ": unexpected end of file inside solid (sides)");
  }
  {
    const auto [f, e] = stl("kw.stl",
                            "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                            "endfacet\n");
    EXPECT_EQ(e, f + ": line 5: expected vertex X Y Z or endloop (endfacet)");
  }
  {
    const auto [f, e] = stl("empty.stl", "");
    EXPECT_EQ(e, f + ": empty file");
  }
  {
    const auto [f, e] = stl("blank.stl", " \n\t\n");
    EXPECT_EQ(e, f + ": empty file");
  }
  {
    const auto [f, e] = stl("none.stl", "solid nothing\nendsolid nothing\n");
    EXPECT_EQ(e, f + ": no triangles");
  }
  {
    const auto tri = cube_triangles();
    std::string b = binary_stl(tri, 12);
    b.resize(84 + 50 * 5);  // the count says 12, the file holds 5
    const auto [f, e] = stl("trunc.stl", b);
    EXPECT_EQ(e, f + ": truncated binary STL: the header says 12 triangles (file holds 334 bytes, "
                     "needs 684)");
  }
  {
    const auto [f, e] = stl("extra.stl", binary_stl(cube_triangles(), 12) + "xyz");
    EXPECT_EQ(e, f + ": binary STL has bytes after its 12 triangles (file holds 687 bytes, "
                     "expected 684)");
  }
  {
    auto tri = cube_triangles();
    tri[3][1].y() = std::nan("");
    const auto [f, e] = stl("bnan.stl", binary_stl(tri, 12));
    EXPECT_EQ(e, f + ": triangle 3: vertex coordinate is not finite (nan)");
  }
  {
    auto tri = cube_triangles();
    tri[7][2] = tri[7][0];
    const auto [f, e] = stl("bflat.stl", binary_stl(tri, 12));
    EXPECT_EQ(e, f + ": triangle 7 has zero area (0 1 0 | 1 1 1 | 0 1 0)");
  }
  {
    const auto [f, e] = stl("zero.stl", binary_stl({}, 0));
    EXPECT_EQ(e, f + ": no triangles");
  }
  {
    const auto [f, e] = stl("short.stl", std::string("\x01\x02\x03", 3));
    EXPECT_EQ(e, f + ": file too short for a binary STL (3 bytes)");
  }
  const std::string v8 = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n";
  {
    const auto [f, e] = obj("range.obj", v8 + "f 1 2 3\nf 1 2 9\n");
    EXPECT_EQ(e, f + ": line 10: vertex index out of range (9 with 8 vertices in the file)");
  }
  {
    const auto [f, e] = obj("neg.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\n" + v8);
    EXPECT_EQ(e, f + ": line 3: vertex index out of range (-3 with 2 vertices defined)");
  }
  {
    const auto [f, e] = obj("idx0.obj", v8 + "f 0 1 2\n");
    EXPECT_EQ(e, f + ": line 9: face vertex index must not be 0, OBJ counts from 1 (0)");
  }
  {
    const auto [f, e] = obj("badidx.obj", v8 + "f 1 2/1 x/3\n");
    EXPECT_EQ(e, f + ": line 9: bad number in face vertex index (x)");
  }
  {
    const auto [f, e] = obj("badv.obj", "v 1 x 0\n");
    EXPECT_EQ(e, f + ": line 1: bad number in vertex y (x)");
  }
  {
    const auto [f, e] = obj("nanv.obj", "# c\nv 1 0 NaN\n");
    EXPECT_EQ(e, f + ": line 2: vertex coordinate is not finite (nan)");
  }
  {
    const auto [f, e] = obj("rep.obj", v8 + "g top\nf 5 6 8 7\nf 1 2 2\n");
    EXPECT_EQ(e, f + ": line 11: triangle 2 has zero area (0 0 0 | 1 0 0 | 1 0 0)");
  }
  {
    const auto [f, e] = obj("short.obj", v8 + "f 1 2\n");
    EXPECT_EQ(e, f + ": line 9: face needs at least 3 vertices (2 given)");
  }
  {
    const auto [f, e] = obj("nof.obj", v8);
    EXPECT_EQ(e, f + ": no triangles");
  }
  {
    const auto [f, e] = obj("empty.obj", "");
    EXPECT_EQ(e, f + ": empty file");
  }
  {
    const fs::path p = dir / "cube.ply";
    write_file(p, "ply\n");
    EXPECT_EQ(error_of([&] { (void)read_mesh(p); }),
              p.string() + ": unknown mesh format (expected .stl, .obj or .txt) (.ply)");
    const fs::path missing = dir / "missing.stl";
    EXPECT_EQ(error_of([&] { (void)read_mesh(missing); }), missing.string() + ": no such file");
  }
  {
    write_file(dir / "ok.obj", cube_obj());
    EXPECT_THROW((void)read_mesh(dir / "ok.obj", 0.0), std::invalid_argument);
    EXPECT_THROW((void)read_mesh(dir / "ok.obj", std::nan("")), std::invalid_argument);
    try {
      (void)read_mesh(dir / "ok.obj", -2);
    } catch (const std::invalid_argument& e) {
      EXPECT_STREQ(e.what(), "read_mesh: scale must be finite and > 0 (-2)");
    }
    // A scale so small that the squared edges underflow to 0 leaves no usable area: the scaled
    // mesh is validated again (first triangle (c0, c4, c6) of the OBJ).
    char tiny[32];
    std::snprintf(tiny, sizeof tiny, "%.17g", 1e-170);
    const std::string t(tiny);
    EXPECT_EQ(error_of([&] { (void)read_mesh(dir / "ok.obj", 1e-170); }),
              (dir / "ok.obj").string() + ": triangle 0 has zero area (0 0 0 | 0 0 " + t + " | 0 " +
                  t + " " + t + ")");
  }
  {
    TriangleMesh m;
    m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.triangles = {{0, 1, 3}};
    m.group = {0};
    m.group_names = {"g"};
    const fs::path p = dir / "w.stl";
    EXPECT_EQ(error_of([&] { write_stl_ascii(m, p); }),
              p.string() + ": triangle 0: vertex index out of range (3 of 3 vertices)");
    EXPECT_FALSE(fs::exists(p));
  }
}

// Bounded mutation fuzz (150 mutants of each of the three cube files: bit flips, truncation,
// random byte runs): every reader returns a mesh that validate_mesh accepts or throws InputError,
// never anything else.
TEST(TriangleMesh, MutatedFilesGiveAMeshOrAnInputError) {
  ScratchDir dir("tmesh_fuzz");
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"a.stl", cube_ascii_stl()},
      {"b.stl", binary_stl(cube_triangles(), 12)},
      {"c.obj", cube_obj()}};
  std::mt19937 rng(11);
  int meshes = 0, errors = 0;
  for (const auto& [name, body] : seeds) {
    for (int it = 0; it < 150; ++it) {
      std::string m = body;
      const int kind = it % 3;
      if (kind == 0) {
        for (int k = 0; k < 1 + it % 4; ++k)
          m[rng() % m.size()] ^= static_cast<char>(1 << (rng() % 8));
      } else if (kind == 1) {
        m.resize(rng() % m.size());
      } else {
        const std::size_t at = rng() % m.size(), len = 1 + rng() % 16;
        for (std::size_t k = at; k < std::min(m.size(), at + len); ++k)
          m[k] = static_cast<char>(rng());
      }
      const fs::path p = dir / name;
      write_file(p, m);
      try {
        const TriangleMesh r = read_mesh(p);
        validate_mesh(r, p.string());
        ++meshes;
      } catch (const InputError&) {
        ++errors;
      }
    }
  }
  EXPECT_EQ(meshes + errors, 450);
  std::printf("fuzz: %d meshes, %d input errors\n", meshes, errors);
}

// The YADE facets reference silo (shared/reference/yade/facets): mesh.stl holds 48 triangles in
// one solid "silo"; every corner equals mesh.csv's to the bit; the vertex count is that of the
// distinct corners of mesh.csv; the file's facet normals equal triangle_normal to 1e-15; the
// areas equal YADE's (out/facets_yade.csv) to 1e-15 relative.
TEST(TriangleMesh, YadeFacetsReferenceMesh) {
  const fs::path ref = fs::path(GS_SOURCE_DIR) / ".." / "shared" / "reference" / "yade" / "facets";
  if (!fs::exists(ref / "mesh.stl") || !fs::exists(ref / "mesh.csv"))
    GTEST_SKIP() << "reference mesh absent: " << (ref / "mesh.stl").string();
  const TriangleMesh m = read_stl(ref / "mesh.stl");
  ASSERT_EQ(m.triangles.size(), 48u);
  ASSERT_EQ(m.group_names, std::vector<std::string>{"silo"});

  std::ifstream csv(ref / "mesh.csv");
  std::string line;
  std::getline(csv, line);  // header
  std::set<std::array<std::uint64_t, 3>> distinct;
  std::size_t t = 0;
  while (std::getline(csv, line)) {
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) f.push_back(c);
    ASSERT_EQ(f.size(), 11u);
    ASSERT_LT(t, m.triangles.size());
    for (int k = 0; k < 3; ++k) {
      std::array<std::uint64_t, 3> key{};
      for (int d = 0; d < 3; ++d) {
        const double want = std::strtod(f[2 + 3 * k + d].c_str(), nullptr);
        const double got = m.vertices[m.triangles[t][k]][d];
        EXPECT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(want))
            << "facet " << t << " vertex " << k;
        key[d] = std::bit_cast<std::uint64_t>(want + 0.0);
      }
      distinct.insert(key);
    }
    ++t;
  }
  EXPECT_EQ(t, 48u);
  EXPECT_EQ(m.vertices.size(), distinct.size());

  std::ifstream stl(ref / "mesh.stl");
  t = 0;
  double worst_normal = 0;
  while (std::getline(stl, line)) {
    std::istringstream ls(line);
    std::string w1, w2;
    double x, y, z;
    if (!(ls >> w1 >> w2) || w1 != "facet") continue;
    ls >> x >> y >> z;
    worst_normal =
        std::max(worst_normal, (triangle_normal(m, t++) - Eigen::Vector3d(x, y, z)).norm());
  }
  EXPECT_EQ(t, 48u);
  EXPECT_LE(worst_normal, 1e-15);

  std::ifstream yade(ref / "out" / "facets_yade.csv");
  std::getline(yade, line);
  t = 0;
  double worst_area = 0;
  while (std::getline(yade, line)) {
    if (line.empty()) continue;
    const double area = std::strtod(line.substr(line.rfind(',') + 1).c_str(), nullptr);
    worst_area = std::max(worst_area, std::abs(triangle_area(m, t++) - area) / area);
  }
  EXPECT_EQ(t, 48u);
  EXPECT_LE(worst_area, 1e-15);
  std::printf(
      "reference mesh: %zu vertices, worst normal difference %.3g, worst relative area "
      "difference %.3g\n",
      m.vertices.size(), worst_normal, worst_area);
}
