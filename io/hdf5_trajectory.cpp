// HDF5 trajectory reader/writer (C API). Layout and guarantees: docs/format.md.
#include "hdf5_trajectory.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <system_error>
#include <vector>

#include "atomic_file.hpp"
#include "errors.hpp"

namespace gs {

namespace {

// ---------------------------------------------------------------- handles and helpers

class Hid {
 public:
  Hid() = default;
  Hid(hid_t id, herr_t (*closer)(hid_t)) : id_(id), closer_(closer) {}
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  Hid(Hid&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = -1; }
  Hid& operator=(Hid&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      closer_ = o.closer_;
      o.id_ = -1;
    }
    return *this;
  }
  ~Hid() { reset(); }
  void reset() {
    if (id_ >= 0 && closer_) closer_(id_);
    id_ = -1;
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = -1;
  herr_t (*closer_)(hid_t) = nullptr;
};

void quiet_hdf5() {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

struct Column {
  const char* group;
  const char* name;
  hid_t (*mem_type)();  // native type getter (H5T_NATIVE_* are runtime values)
  std::vector<hsize_t> tail;
  hsize_t chunk_rows;
  int since = 1;  // first schema version that has this dataset
};

hid_t t_f64() {
  return H5T_NATIVE_DOUBLE;
}
hid_t t_i64() {
  return H5T_NATIVE_INT64;
}
hid_t t_i32() {
  return H5T_NATIVE_INT32;
}
hid_t t_i8() {
  return H5T_NATIVE_INT8;
}
// Fixed-length, NUL-padded ASCII strings of kTemplateBytes (clump template names): fixed length
// keeps them in the chunks (filters and checksums apply; no global heap under SWMR).
hid_t t_str() {
  static const hid_t t = [] {
    const hid_t s = H5Tcopy(H5T_C_S1);
    H5Tset_size(s, kClumpTemplateBytes);
    H5Tset_strpad(s, H5T_STR_NULLPAD);
    return s;
  }();
  return t;
}

// Rows per chunk of the per-particle and per-contact datasets. The chunk that a frame ends in is
// compressed and written again when the next frame is appended: with 4096 rows the 883-sphere
// oedometer (a frame every 1000 steps) ran 6 % slower and its file was 1.7x larger than with
// 1024. 1024 rows of three doubles (24 KiB) still fill most of deflate's 32 KiB window.
constexpr hsize_t kRowChunk = 1024;
constexpr hsize_t kFrameChunk = 64;

// Column order matters for the writer: /frames/end must stay last (commit marker).
enum Col : int {
  P_ID,
  P_POS,
  P_RAD,
  P_VEL,
  P_ANGVEL,
  P_ORI,
  P_ROT,
  P_MASS,
  P_CLUMP,
  P_MAT,
  C_ID1,
  C_ID2,
  C_POINT,
  C_NORMAL,
  C_FN,
  C_FS,
  C_MB,
  C_MT,
  C_OVERLAP,
  W_ID,
  W_KIND,
  W_A,
  W_B,
  W_FORCE,
  W_TORQUE,
  K_ID,
  K_TEMPLATE,
  K_POS,
  K_ORI,
  K_VEL,
  K_ANGVEL,
  K_MASS,
  K_INERTIA,
  L_WALL,
  L_FACET,
  L_CENTROID,
  L_FORCE,
  F_TIME,
  F_STEP,
  F_DT,
  F_TWOD,
  F_LO,
  F_HI,
  F_PERIODIC,
  F_CELL,
  F_CELL_VELGRAD,
  F_CLUMP_END,
  F_FACET_END,
  F_END,
  N_COLS
};

const std::vector<Column>& columns() {
  static const std::vector<Column> cols = {
      {"particles", "id", t_i64, {}, kRowChunk},
      {"particles", "position", t_f64, {3}, kRowChunk},
      {"particles", "radius", t_f64, {}, kRowChunk},
      {"particles", "velocity", t_f64, {3}, kRowChunk},
      {"particles", "angular_velocity", t_f64, {3}, kRowChunk},
      {"particles", "orientation", t_f64, {4}, kRowChunk},
      {"particles", "rotation", t_f64, {3}, kRowChunk},
      {"particles", "mass", t_f64, {}, kRowChunk},
      {"particles", "clump_id", t_i64, {}, kRowChunk},
      {"particles", "material_id", t_i32, {}, kRowChunk},
      {"contacts", "id1", t_i64, {}, kRowChunk},
      {"contacts", "id2", t_i64, {}, kRowChunk},
      {"contacts", "point", t_f64, {3}, kRowChunk},
      {"contacts", "normal", t_f64, {3}, kRowChunk},
      {"contacts", "normal_force", t_f64, {3}, kRowChunk},
      {"contacts", "shear_force", t_f64, {3}, kRowChunk},
      {"contacts", "bending_moment", t_f64, {3}, kRowChunk},
      {"contacts", "twisting_moment", t_f64, {3}, kRowChunk},
      {"contacts", "overlap", t_f64, {}, kRowChunk},
      {"walls", "id", t_i64, {}, kFrameChunk},
      {"walls", "kind", t_i32, {}, kFrameChunk},
      {"walls", "a", t_f64, {3}, kFrameChunk},
      {"walls", "b", t_f64, {3}, kFrameChunk},
      {"walls", "force", t_f64, {3}, kFrameChunk},
      {"walls", "torque", t_f64, {3}, kFrameChunk},
      {"clumps", "id", t_i64, {}, kRowChunk, 2},
      {"clumps", "template", t_str, {}, kRowChunk, 2},
      {"clumps", "position", t_f64, {3}, kRowChunk, 2},
      {"clumps", "orientation", t_f64, {4}, kRowChunk, 2},
      {"clumps", "velocity", t_f64, {3}, kRowChunk, 2},
      {"clumps", "angular_velocity", t_f64, {3}, kRowChunk, 2},
      {"clumps", "mass", t_f64, {}, kRowChunk, 2},
      {"clumps", "principal_inertia", t_f64, {3}, kRowChunk, 2},
      {"facet_loads", "wall_id", t_i64, {}, kRowChunk, 2},
      {"facet_loads", "facet", t_i32, {}, kRowChunk, 2},
      {"facet_loads", "centroid", t_f64, {3}, kRowChunk, 2},
      {"facet_loads", "force", t_f64, {3}, kRowChunk, 2},
      {"frames", "time", t_f64, {}, kFrameChunk},
      {"frames", "step", t_i64, {}, kFrameChunk},
      {"frames", "dt", t_f64, {}, kFrameChunk},
      {"frames", "two_d", t_i8, {}, kFrameChunk},
      {"frames", "domain_lo", t_f64, {3}, kFrameChunk},
      {"frames", "domain_hi", t_f64, {3}, kFrameChunk},
      {"frames", "periodic", t_i8, {}, kFrameChunk},
      {"frames", "cell", t_f64, {3, 3}, kFrameChunk},
      {"frames", "cell_velocity_gradient", t_f64, {3, 3}, kFrameChunk, 3},
      {"frames", "clump_end", t_i64, {}, kFrameChunk, 2},
      {"frames", "facet_end", t_i64, {}, kFrameChunk, 2},
      {"frames", "end", t_i64, {3}, kFrameChunk},
  };
  return cols;
}

std::string col_path(const Column& c) {
  return std::string("/") + c.group + "/" + c.name;
}

hsize_t row_width(const Column& c) {
  hsize_t w = 1;
  for (auto t : c.tail) w *= t;
  return w;
}

bool is_string(const Column& c) {
  return c.mem_type == t_str;
}

/// The file type of a column: little-endian numbers, or the fixed-length string type.
hid_t file_type(const Column& c) {
  if (is_string(c)) return t_str();
  return c.mem_type() == H5T_NATIVE_DOUBLE  ? H5T_IEEE_F64LE
         : c.mem_type() == H5T_NATIVE_INT64 ? H5T_STD_I64LE
         : c.mem_type() == H5T_NATIVE_INT32 ? H5T_STD_I32LE
                                            : H5T_STD_I8LE;
}

/// An empty, extendable dataset for column `c`: chunked, shuffled and deflated (level > 0), and
/// Fletcher-32 checksummed.
void create_dataset(hid_t file, const Column& c, int deflate_level, const std::string& name) {
  std::vector<hsize_t> dims{0}, maxdims{H5S_UNLIMITED}, chunk{c.chunk_rows};
  for (auto t : c.tail) {
    dims.push_back(t);
    maxdims.push_back(t);
    chunk.push_back(t);
  }
  Hid space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), maxdims.data()), H5Sclose);
  Hid dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_chunk(dcpl.get(), static_cast<int>(chunk.size()), chunk.data());
  if (deflate_level > 0) {
    H5Pset_shuffle(dcpl.get());
    H5Pset_deflate(dcpl.get(), static_cast<unsigned>(deflate_level));
  }
  H5Pset_fletcher32(dcpl.get());
  Hid d(H5Dcreate2(file, col_path(c).c_str(), file_type(c), space.get(), H5P_DEFAULT, dcpl.get(),
                   H5P_DEFAULT),
        H5Dclose);
  if (!d.valid()) throw InputError(name, "cannot create dataset", col_path(c));
}

/// Reads the schema_version root attribute (-1 when missing or unreadable).
long long read_schema_version(hid_t file) {
  Hid a(H5Aopen(file, "schema_version", H5P_DEFAULT), H5Aclose);
  long long v = -1;
  if (!a.valid() || H5Aread(a.get(), H5T_NATIVE_LLONG, &v) < 0) return -1;
  return v;
}

Hid latest_fapl() {
  Hid fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST);
  return fapl;
}

void write_string_attr(hid_t obj, const std::string& name, const std::string& value,
                       const std::string& file) {
  Hid type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<size_t>(1, value.size()));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  Hid space(H5Screate(H5S_SCALAR), H5Sclose);
  Hid attr(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
           H5Aclose);
  if (!attr.valid()) throw InputError(file, "cannot create attribute", name);
  std::string buf = value.empty() ? std::string(1, '\0') : value;
  if (H5Awrite(attr.get(), type.get(), buf.data()) < 0)
    throw InputError(file, "cannot write attribute", name);
}

void write_int_attr(hid_t obj, const std::string& name, long long value, const std::string& file) {
  Hid space(H5Screate(H5S_SCALAR), H5Sclose);
  Hid attr(H5Acreate2(obj, name.c_str(), H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
           H5Aclose);
  if (!attr.valid() || H5Awrite(attr.get(), H5T_NATIVE_LLONG, &value) < 0)
    throw InputError(file, "cannot write attribute", name);
}

std::string read_string_attr(hid_t attr, const std::string& file, const std::string& name) {
  Hid ftype(H5Aget_type(attr), H5Tclose);
  if (!ftype.valid() || H5Tget_class(ftype.get()) != H5T_STRING)
    throw InputError(file, "attribute is not a string", name);
  Hid space(H5Aget_space(attr), H5Sclose);
  if (!space.valid() || H5Sget_simple_extent_npoints(space.get()) != 1)
    throw InputError(file, "attribute is not a scalar string", name);
  if (H5Tis_variable_str(ftype.get()) > 0) {
    Hid mtype(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mtype.get(), H5T_VARIABLE);
    char* p = nullptr;
    if (H5Aread(attr, mtype.get(), &p) < 0) throw InputError(file, "cannot read attribute", name);
    std::string s = p ? p : "";
    H5free_memory(p);
    return s;
  }
  const size_t n = H5Tget_size(ftype.get());
  if (n == 0 || n > (1u << 24)) throw InputError(file, "attribute has a bad size", name);
  std::string s(n + 1, '\0');  // room for the terminator of the NULLTERM memory type
  Hid mtype(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(mtype.get(), n + 1);
  if (H5Aread(attr, mtype.get(), s.data()) < 0)
    throw InputError(file, "cannot read attribute", name);
  s.resize(std::strlen(s.c_str()));
  return s;
}

// ---------------------------------------------------------------- what a reader refuses

/// The object at `path` (absolute, "/a/b") is reached through hard links only: an external link
/// (into another file), a soft or user-defined link is refused before anything follows it.
void require_hard_links(hid_t file, const std::string& path, const std::string& name) {
  std::size_t at = 1;
  while (at <= path.size()) {
    const auto slash = path.find('/', at);
    const std::string prefix = path.substr(0, slash);
    H5L_info_t info;
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) return;  // (reported by the caller)
    if (H5Lget_info(file, prefix.c_str(), &info, H5P_DEFAULT) < 0)
      throw InputError(name, "cannot read link", prefix);
    if (info.type == H5L_TYPE_EXTERNAL)
      throw InputError(name, "external link not followed", prefix);
    if (info.type != H5L_TYPE_HARD)
      throw InputError(name, "soft or user-defined link not followed", prefix);
    if (slash == std::string::npos) break;
    at = slash + 1;
  }
}

/// The dataset's raw data lies in this file, in chunks filtered only by shuffle, deflate and
/// Fletcher-32 (what the writer uses; deflate compresses at most 1032:1), and the rows it
/// declares fit in the bytes it stores: a few kilobytes never claim 10^8 particles.
void check_dataset_storage(hid_t ds, hsize_t rows, hsize_t row_bytes, const std::string& path,
                           const std::string& name) {
  Hid dcpl(H5Dget_create_plist(ds), H5Pclose);
  if (!dcpl.valid()) throw InputError(name, "cannot read dataset properties", path);
  const H5D_layout_t layout = H5Pget_layout(dcpl.get());
  if (layout == H5D_VIRTUAL) throw InputError(name, "virtual dataset not followed", path);
  if (H5Pget_external_count(dcpl.get()) > 0)
    throw InputError(name, "dataset with external raw data not followed", path);
  const int nfilters = H5Pget_nfilters(dcpl.get());
  for (int k = 0; k < nfilters; ++k) {
    unsigned flags = 0;
    std::size_t nelem = 0;
    const H5Z_filter_t f = H5Pget_filter2(dcpl.get(), static_cast<unsigned>(k), &flags, &nelem,
                                          nullptr, 0, nullptr, nullptr);
    if (f != H5Z_FILTER_DEFLATE && f != H5Z_FILTER_SHUFFLE && f != H5Z_FILTER_FLETCHER32)
      throw InputError(name, "dataset uses an unsupported filter",
                       path + " filter " + std::to_string(f));
  }
  const hsize_t stored = H5Dget_storage_size(ds);
  const long double logical = static_cast<long double>(rows) * static_cast<long double>(row_bytes);
  if (logical > 1100.0L * static_cast<long double>(stored) + 1048576.0L)
    throw InputError(
        name, "dataset declares more rows than the file stores",
        path + ": " + std::to_string(rows) + " rows in " + std::to_string(stored) + " bytes");
}

// ---------------------------------------------------------------- appendable dataset

struct Appendable {
  Hid ds;
  hsize_t rows = 0;
  const Column* col = nullptr;

  void append(const void* data, hsize_t n, const std::string& file) {
    if (n == 0) return;
    std::vector<hsize_t> dims{rows + n};
    dims.insert(dims.end(), col->tail.begin(), col->tail.end());
    if (H5Dset_extent(ds.get(), dims.data()) < 0)
      throw InputError(file, "cannot extend dataset", col_path(*col));
    Hid fspace(H5Dget_space(ds.get()), H5Sclose);
    std::vector<hsize_t> start(dims.size(), 0), count = dims;
    start[0] = rows;
    count[0] = n;
    H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
    Hid mspace(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr), H5Sclose);
    if (H5Dwrite(ds.get(), col->mem_type(), mspace.get(), fspace.get(), H5P_DEFAULT, data) < 0)
      throw InputError(file, "cannot write dataset", col_path(*col));
    rows += n;
  }
};

/// `width` values of T per row, over the rows `rows_of(frame)` of `nf` frames in order.
template <class T, class Rows, class F>
std::vector<T> gather_rows(const Frame* fr, std::size_t nf, std::size_t width, Rows rows_of,
                           F fill) {
  std::size_t total = 0;
  for (std::size_t j = 0; j < nf; ++j) total += rows_of(fr[j]).size();
  std::vector<T> v(total * width);
  std::size_t at = 0;
  for (std::size_t j = 0; j < nf; ++j)
    for (const auto& r : rows_of(fr[j])) fill(r, &v[width * at++]);
  return v;
}

void put3(double* out, const Eigen::Vector3d& v) {
  out[0] = v.x();
  out[1] = v.y();
  out[2] = v.z();
}

Eigen::Vector3d get3(const double* in) {
  return {in[0], in[1], in[2]};
}

// Quaternions as (w, x, y, z).
void put_quat(double* out, const Eigen::Quaterniond& q) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

Eigen::Quaterniond get_quat(const double* in) {
  return {in[0], in[1], in[2], in[3]};
}

}  // namespace

std::filesystem::path partial_path(const std::filesystem::path& final_path) {
  auto p = final_path;
  p += ".partial";
  return p;
}

bool is_hdf5_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char sig[8] = {};
  in.read(sig, 8);
  return in.gcount() == 8 && std::memcmp(sig, "\x89HDF\r\n\x1a\n", 8) == 0;
}

// ==================================================================== writer

struct TrajectoryWriter::Impl {
  std::filesystem::path final_path;
  std::filesystem::path file_path;
  Options options;
  Hid file;
  std::vector<Appendable> ds;
  std::size_t frames = 0;
  bool finished = false;

  std::string name() const { return file_path.string(); }

  void open_datasets() {
    ds.clear();
    ds.resize(N_COLS);
    for (int i = 0; i < N_COLS; ++i) {
      const auto& c = columns()[i];
      ds[i].col = &c;
      ds[i].ds = Hid(H5Dopen2(file.get(), col_path(c).c_str(), H5P_DEFAULT), H5Dclose);
      if (!ds[i].ds.valid()) throw InputError(name(), "missing dataset", col_path(c));
      Hid space(H5Dget_space(ds[i].ds.get()), H5Sclose);
      hsize_t dims[4] = {};
      if (H5Sget_simple_extent_ndims(space.get()) != static_cast<int>(1 + c.tail.size()))
        throw InputError(name(), "dataset has wrong rank", col_path(c));
      H5Sget_simple_extent_dims(space.get(), dims, nullptr);
      ds[i].rows = dims[0];
    }
  }

  void create(const RunMetadata& meta) {
    quiet_hdf5();
    std::error_code ec;
    std::filesystem::remove(file_path, ec);
    auto fapl = latest_fapl();
    file = Hid(H5Fcreate(file_path.string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()),
               H5Fclose);
    if (!file.valid()) throw InputError(name(), "cannot create HDF5 file");
    write_string_attr(file.get(), "format", kTrajectoryFormatName, name());
    write_int_attr(file.get(), "schema_version", kTrajectorySchemaVersion, name());
    write_string_attr(file.get(), "code_version",
                      meta.code_version.empty() ? code_version() : meta.code_version, name());
    write_string_attr(file.get(), "provenance", meta.provenance, name());
    {
      Hid gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
      H5Pset_attr_creation_order(gcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
      Hid g(H5Gcreate2(file.get(), "metadata", H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose);
      if (!g.valid()) throw InputError(name(), "cannot create group", "metadata");
      for (const auto& [k, v] : meta.parameters) {
        if (k.empty()) throw InputError(name(), "empty metadata key");
        write_string_attr(g.get(), k, v, name());
      }
    }
    for (const char* g : {"particles", "contacts", "walls", "clumps", "facet_loads", "frames"}) {
      Hid grp(H5Gcreate2(file.get(), g, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
      if (!grp.valid()) throw InputError(name(), "cannot create group", g);
    }
    for (const auto& c : columns()) create_dataset(file.get(), c, options.deflate_level, name());
    open_datasets();
    start_swmr();
  }

  void start_swmr() {
    if (H5Fstart_swmr_write(file.get()) < 0)
      throw InputError(name(), "cannot start single-writer mode");
  }

  void flush() {
    if (H5Fflush(file.get(), H5F_SCOPE_LOCAL) < 0) throw InputError(name(), "cannot flush");
  }

  /// Schema 1 or 2 -> current, before resuming: the datasets added since (empty clump rows,
  /// and frame-table columns of zeros for the frames already written: clump_end, facet_end,
  /// the cell velocity gradient), then the version attribute.
  void upgrade_from(long long version) {
    if (version < 2)
      for (const char* g : {"clumps", "facet_loads"}) {
        Hid grp(H5Gcreate2(file.get(), g, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
        if (!grp.valid()) throw InputError(name(), "cannot create group", g);
      }
    for (const auto& c : columns())
      if (c.since > version) create_dataset(file.get(), c, options.deflate_level, name());
    open_datasets();
    const std::size_t nf = ds[F_END].rows;
    if (version < 2) {
      const std::vector<std::int64_t> zeros(nf, 0);
      ds[F_CLUMP_END].append(zeros.data(), zeros.size(), name());
      ds[F_FACET_END].append(zeros.data(), zeros.size(), name());
    }
    const std::vector<double> zeros9(9 * nf, 0.0);
    ds[F_CELL_VELGRAD].append(zeros9.data(), nf, name());
    Hid a(H5Aopen(file.get(), "schema_version", H5P_DEFAULT), H5Aclose);
    const long long v = kTrajectorySchemaVersion;
    if (!a.valid() || H5Awrite(a.get(), H5T_NATIVE_LLONG, &v) < 0)
      throw InputError(name(), "cannot write attribute", "schema_version");
  }

  /// Appends `nf` frames: each dataset is extended and written once for the whole batch (10^6
  /// frames convert in linear time), the commit marker /frames/end last.
  void append(const Frame* fr, std::size_t nf) {
    if (nf == 0) return;
    write_particles_and_contacts(fr, nf);
    write_rest(fr, nf);
  }

  /// The particle and contact rows of `nf` frames.
  void write_particles_and_contacts(const Frame* fr, std::size_t nf) {
    const std::string n = name();
    const auto P = [](const Frame& f) -> const auto& {
      return f.particles;
    };
    const auto C = [](const Frame& f) -> const auto& {
      return f.contacts;
    };
    auto wr = [&](int col, const auto& vec, std::size_t width) {
      ds[col].append(vec.data(), vec.size() / width, n);
    };
    wr(P_ID, gather_rows<std::int64_t>(fr, nf, 1, P, [](const auto& r, auto* o) { *o = r.id; }), 1);
    wr(P_POS,
       gather_rows<double>(fr, nf, 3, P, [](const auto& r, auto* o) { put3(o, r.position); }), 3);
    wr(P_RAD, gather_rows<double>(fr, nf, 1, P, [](const auto& r, auto* o) { *o = r.radius; }), 1);
    wr(P_VEL,
       gather_rows<double>(fr, nf, 3, P, [](const auto& r, auto* o) { put3(o, r.velocity); }), 3);
    wr(P_ANGVEL,
       gather_rows<double>(fr, nf, 3, P,
                           [](const auto& r, auto* o) { put3(o, r.angular_velocity); }),
       3);
    wr(P_ORI,
       gather_rows<double>(fr, nf, 4, P,
                           [](const auto& r, auto* o) { put_quat(o, r.orientation); }),
       4);
    wr(P_ROT,
       gather_rows<double>(fr, nf, 3, P, [](const auto& r, auto* o) { put3(o, r.rotation); }), 3);
    wr(P_MASS, gather_rows<double>(fr, nf, 1, P, [](const auto& r, auto* o) { *o = r.mass; }), 1);
    wr(P_CLUMP,
       gather_rows<std::int64_t>(fr, nf, 1, P, [](const auto& r, auto* o) { *o = r.clump_id; }), 1);
    wr(P_MAT,
       gather_rows<std::int32_t>(fr, nf, 1, P, [](const auto& r, auto* o) { *o = r.material_id; }),
       1);

    wr(C_ID1, gather_rows<std::int64_t>(fr, nf, 1, C, [](const auto& r, auto* o) { *o = r.id1; }),
       1);
    wr(C_ID2, gather_rows<std::int64_t>(fr, nf, 1, C, [](const auto& r, auto* o) { *o = r.id2; }),
       1);
    wr(C_POINT, gather_rows<double>(fr, nf, 3, C, [](const auto& r, auto* o) { put3(o, r.point); }),
       3);
    wr(C_NORMAL,
       gather_rows<double>(fr, nf, 3, C, [](const auto& r, auto* o) { put3(o, r.normal); }), 3);
    wr(C_FN,
       gather_rows<double>(fr, nf, 3, C, [](const auto& r, auto* o) { put3(o, r.normal_force); }),
       3);
    wr(C_FS,
       gather_rows<double>(fr, nf, 3, C, [](const auto& r, auto* o) { put3(o, r.shear_force); }),
       3);
    wr(C_MB,
       gather_rows<double>(fr, nf, 3, C, [](const auto& r, auto* o) { put3(o, r.bending_moment); }),
       3);
    wr(C_MT,
       gather_rows<double>(fr, nf, 3, C,
                           [](const auto& r, auto* o) { put3(o, r.twisting_moment); }),
       3);
    wr(C_OVERLAP, gather_rows<double>(fr, nf, 1, C, [](const auto& r, auto* o) { *o = r.overlap; }),
       1);
  }

  /// The wall, clump and facet-load rows of `nf` frames, then their entries in the frame table
  /// (whose row ends are the datasets' totals, so the particles and contacts go first).
  void write_rest(const Frame* fr, std::size_t nf) {
    const std::string n = name();
    const auto W = [](const Frame& f) -> const auto& {
      return f.walls;
    };
    const auto K = [](const Frame& f) -> const auto& {
      return f.clumps;
    };
    const auto L = [](const Frame& f) -> const auto& {
      return f.facet_loads;
    };
    auto wr = [&](int col, const auto& vec, std::size_t width) {
      ds[col].append(vec.data(), vec.size() / width, n);
    };
    wr(W_ID, gather_rows<std::int64_t>(fr, nf, 1, W, [](const auto& r, auto* o) { *o = r.id; }), 1);
    wr(W_KIND,
       gather_rows<std::int32_t>(
           fr, nf, 1, W, [](const auto& r, auto* o) { *o = static_cast<std::int32_t>(r.kind); }),
       1);
    wr(W_A, gather_rows<double>(fr, nf, 3, W, [](const auto& r, auto* o) { put3(o, r.a); }), 3);
    wr(W_B, gather_rows<double>(fr, nf, 3, W, [](const auto& r, auto* o) { put3(o, r.b); }), 3);
    wr(W_FORCE, gather_rows<double>(fr, nf, 3, W, [](const auto& r, auto* o) { put3(o, r.force); }),
       3);
    wr(W_TORQUE,
       gather_rows<double>(fr, nf, 3, W, [](const auto& r, auto* o) { put3(o, r.torque); }), 3);

    wr(K_ID, gather_rows<std::int64_t>(fr, nf, 1, K, [](const auto& r, auto* o) { *o = r.id; }), 1);
    wr(K_TEMPLATE,
       gather_rows<char>(fr, nf, kClumpTemplateBytes, K,
                         [](const auto& r, auto* o) {
                           std::memcpy(o, r.template_name.data(), r.template_name.size());
                         }),
       kClumpTemplateBytes);
    wr(K_POS,
       gather_rows<double>(fr, nf, 3, K, [](const auto& r, auto* o) { put3(o, r.position); }), 3);
    wr(K_ORI,
       gather_rows<double>(fr, nf, 4, K,
                           [](const auto& r, auto* o) { put_quat(o, r.orientation); }),
       4);
    wr(K_VEL,
       gather_rows<double>(fr, nf, 3, K, [](const auto& r, auto* o) { put3(o, r.velocity); }), 3);
    wr(K_ANGVEL,
       gather_rows<double>(fr, nf, 3, K,
                           [](const auto& r, auto* o) { put3(o, r.angular_velocity); }),
       3);
    wr(K_MASS, gather_rows<double>(fr, nf, 1, K, [](const auto& r, auto* o) { *o = r.mass; }), 1);
    wr(K_INERTIA,
       gather_rows<double>(fr, nf, 3, K,
                           [](const auto& r, auto* o) { put3(o, r.principal_inertia); }),
       3);

    wr(L_WALL,
       gather_rows<std::int64_t>(fr, nf, 1, L, [](const auto& r, auto* o) { *o = r.wall_id; }), 1);
    wr(L_FACET,
       gather_rows<std::int32_t>(fr, nf, 1, L, [](const auto& r, auto* o) { *o = r.facet; }), 1);
    wr(L_CENTROID,
       gather_rows<double>(fr, nf, 3, L, [](const auto& r, auto* o) { put3(o, r.centroid); }), 3);
    wr(L_FORCE, gather_rows<double>(fr, nf, 3, L, [](const auto& r, auto* o) { put3(o, r.force); }),
       3);

    std::vector<double> time(nf), dt(nf), lo(3 * nf), hi(3 * nf), cell(9 * nf), velgrad(9 * nf);
    std::vector<std::int64_t> step(nf), clump_end(nf), facet_end(nf), end(3 * nf);
    std::vector<std::int8_t> two_d(nf), periodic(nf);
    // The row counts before this batch were taken from the datasets just written.
    std::int64_t rows[5] = {
        static_cast<std::int64_t>(ds[P_ID].rows), static_cast<std::int64_t>(ds[C_ID1].rows),
        static_cast<std::int64_t>(ds[W_ID].rows), static_cast<std::int64_t>(ds[K_ID].rows),
        static_cast<std::int64_t>(ds[L_WALL].rows)};
    for (std::size_t j = nf; j-- > 0;) {  // back from the totals
      const Frame& f = fr[j];
      time[j] = f.time;
      step[j] = f.step;
      dt[j] = f.dt;
      two_d[j] = f.two_d ? 1 : 0;
      periodic[j] = f.domain.periodic ? 1 : 0;
      put3(&lo[3 * j], f.domain.lo);
      put3(&hi[3 * j], f.domain.hi);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          cell[9 * j + r * 3 + c] = f.domain.cell(r, c);
          velgrad[9 * j + r * 3 + c] = f.domain.velocity_gradient(r, c);
        }
      end[3 * j] = rows[0];
      end[3 * j + 1] = rows[1];
      end[3 * j + 2] = rows[2];
      clump_end[j] = rows[3];
      facet_end[j] = rows[4];
      rows[0] -= static_cast<std::int64_t>(f.particles.size());
      rows[1] -= static_cast<std::int64_t>(f.contacts.size());
      rows[2] -= static_cast<std::int64_t>(f.walls.size());
      rows[3] -= static_cast<std::int64_t>(f.clumps.size());
      rows[4] -= static_cast<std::int64_t>(f.facet_loads.size());
    }
    ds[F_TIME].append(time.data(), nf, n);
    ds[F_STEP].append(step.data(), nf, n);
    ds[F_DT].append(dt.data(), nf, n);
    ds[F_TWOD].append(two_d.data(), nf, n);
    ds[F_LO].append(lo.data(), nf, n);
    ds[F_HI].append(hi.data(), nf, n);
    ds[F_PERIODIC].append(periodic.data(), nf, n);
    ds[F_CELL].append(cell.data(), nf, n);
    ds[F_CELL_VELGRAD].append(velgrad.data(), nf, n);
    ds[F_CLUMP_END].append(clump_end.data(), nf, n);
    ds[F_FACET_END].append(facet_end.data(), nf, n);
    flush();
    // Commit marker: the frames exist for readers once their end offsets are on disk.
    ds[F_END].append(end.data(), nf, n);
    flush();
    frames += nf;
  }

  void close() {
    ds.clear();
    file.reset();
  }
};

TrajectoryWriter::TrajectoryWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

TrajectoryWriter::TrajectoryWriter(std::filesystem::path path, const RunMetadata& metadata)
    : TrajectoryWriter(std::move(path), metadata, Options{}) {}

TrajectoryWriter::TrajectoryWriter(std::filesystem::path path, const RunMetadata& metadata,
                                   Options options)
    : impl_(std::make_unique<Impl>()) {
  impl_->final_path = std::move(path);
  check_not_an_input(impl_->final_path);
  impl_->file_path = partial_path(impl_->final_path);
  impl_->options = options;
  try {
    impl_->create(metadata);
  } catch (...) {
    impl_->close();
    std::error_code ec;
    std::filesystem::remove(impl_->file_path, ec);
    throw;
  }
}

TrajectoryWriter TrajectoryWriter::resume(std::filesystem::path path, std::size_t keep_frames,
                                          Options options) {
  quiet_hdf5();
  auto impl = std::make_unique<Impl>();
  impl->final_path = std::move(path);
  impl->file_path = partial_path(impl->final_path);
  impl->options = options;
  auto fapl = latest_fapl();
  impl->file = Hid(H5Fopen(impl->file_path.string().c_str(), H5F_ACC_RDWR, fapl.get()), H5Fclose);
  if (!impl->file.valid()) {
    // A writer killed in single-writer mode leaves the superblock marked as open; clear that
    // mark (what the h5clear tool does) and open again.
    hbool_t clear = 1;
    if (H5Pset(fapl.get(), "clear_status_flags", &clear) >= 0)
      impl->file =
          Hid(H5Fopen(impl->file_path.string().c_str(), H5F_ACC_RDWR, fapl.get()), H5Fclose);
  }
  if (!impl->file.valid()) throw InputError(impl->name(), "cannot reopen trajectory to resume");
  const long long version = read_schema_version(impl->file.get());
  if (version == 1 || version == 2) {
    impl->upgrade_from(version);
  } else if (version != kTrajectorySchemaVersion) {
    throw InputError(impl->name(), "cannot resume, unsupported schema_version",
                     std::to_string(version));
  }
  impl->open_datasets();
  const std::size_t have = impl->ds[F_END].rows;
  const std::size_t keep = std::min(have, keep_frames);
  std::array<std::int64_t, 5> end{0, 0, 0, 0, 0};  // particles, contacts, walls, clumps, facets
  if (keep > 0) {
    auto read_row = [&](int col, std::int64_t* out) {
      const hsize_t w = row_width(columns()[col]);
      Hid fspace(H5Dget_space(impl->ds[col].ds.get()), H5Sclose);
      const int rank = w == 1 ? 1 : 2;
      hsize_t start[2] = {keep - 1, 0}, count[2] = {1, w};
      H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start, nullptr, count, nullptr);
      Hid mspace(H5Screate_simple(rank, count, nullptr), H5Sclose);
      if (H5Dread(impl->ds[col].ds.get(), H5T_NATIVE_INT64, mspace.get(), fspace.get(), H5P_DEFAULT,
                  out) < 0)
        throw InputError(impl->name(), "cannot read frame index", col_path(columns()[col]));
    };
    read_row(F_END, end.data());
    read_row(F_CLUMP_END, end.data() + 3);
    read_row(F_FACET_END, end.data() + 4);
  }
  for (int i = 0; i < N_COLS; ++i) {
    const auto& c = columns()[i];
    const std::string g = c.group;
    const hsize_t rows = g == "particles"     ? end[0]
                         : g == "contacts"    ? end[1]
                         : g == "walls"       ? end[2]
                         : g == "clumps"      ? end[3]
                         : g == "facet_loads" ? end[4]
                                              : keep;
    if (rows == impl->ds[i].rows) continue;
    std::vector<hsize_t> dims{rows};
    dims.insert(dims.end(), c.tail.begin(), c.tail.end());
    if (H5Dset_extent(impl->ds[i].ds.get(), dims.data()) < 0)
      throw InputError(impl->name(), "cannot truncate dataset", col_path(c));
    impl->ds[i].rows = rows;
  }
  impl->frames = keep;
  if (H5Fget_intent(impl->file.get(), nullptr) >= 0) {
    unsigned intent = 0;
    H5Fget_intent(impl->file.get(), &intent);
    if (!(intent & H5F_ACC_SWMR_WRITE)) impl->start_swmr();
  }
  impl->flush();
  return TrajectoryWriter(std::move(impl));
}

TrajectoryWriter::TrajectoryWriter(TrajectoryWriter&&) noexcept = default;
TrajectoryWriter& TrajectoryWriter::operator=(TrajectoryWriter&&) noexcept = default;

TrajectoryWriter::~TrajectoryWriter() {
  if (!impl_ || impl_->finished) return;
  impl_->close();
  if (impl_->options.discard_unfinished) {
    std::error_code ec;
    std::filesystem::remove(impl_->file_path, ec);
  }
}

namespace {
// What append() refuses before any row is written.
void check_template_names(const Frame& frame, const std::string& name) {
  for (const auto& k : frame.clumps)
    if (k.template_name.size() > kClumpTemplateBytes)
      throw InputError(
          name, "clump template name longer than " + std::to_string(kClumpTemplateBytes) + " bytes",
          k.template_name);
}

void check_appendable(const Frame& frame, const std::string& name) {
  validate_frame(frame, name);
  check_template_names(frame, name);
}
}  // namespace

void TrajectoryWriter::append(const Frame& frame) {
  check_appendable(frame, impl_->final_path.string());
  impl_->append(&frame, 1);
}

void TrajectoryWriter::append(const std::vector<Frame>& frames) {
  for (const auto& f : frames) check_appendable(f, impl_->final_path.string());
  constexpr std::size_t kBatch = 4096;  // frames per write: bounded memory, one flush per batch
  for (std::size_t b = 0; b < frames.size(); b += kBatch)
    impl_->append(frames.data() + b, std::min(kBatch, frames.size() - b));
}

void TrajectoryWriter::append(const Frame& head, const FramePieces& pieces) {
  // Every piece is checked before any is written (a frame that fails leaves the file as it
  // was), so each piece is asked for twice.
  const std::string file = impl_->final_path.string();
  if (!head.particles.empty() || !head.contacts.empty())
    throw std::invalid_argument("append in pieces: the head carries no particles or contacts");
  FrameCheck check(head, file);
  check_template_names(head, file);
  Frame piece;
  for (std::size_t i = 0;; ++i) {
    piece.particles.clear();
    piece.contacts.clear();
    const bool more = pieces(i, piece);
    check.add(piece);
    if (!more) break;
  }
  check.finish(head);
  for (std::size_t i = 0;; ++i) {
    piece.particles.clear();
    piece.contacts.clear();
    const bool more = pieces(i, piece);
    impl_->write_particles_and_contacts(&piece, 1);
    if (!more) break;
  }
  impl_->write_rest(&head, 1);
}

std::size_t TrajectoryWriter::frames_written() const {
  return impl_->frames;
}

void TrajectoryWriter::finish() {
  impl_->close();
  rename_durably(impl_->file_path, impl_->final_path);
  impl_->finished = true;
}

// ==================================================================== reader

struct TrajectoryReader::Impl {
  std::string file_name;
  Hid file;
  RunMetadata meta;
  std::vector<Hid> ds;
  std::vector<hsize_t> rows;
  std::size_t n = 0;
  long long version = 0;
  // Per-frame tables, read once (clump_end: zeros for a version 1 file).
  std::vector<double> time, dt, lo, hi, cell, cell_velgrad;
  std::vector<std::int64_t> step, end, clump_end, facet_end;
  std::vector<std::int8_t> two_d, periodic;

  bool has(int col) const { return columns()[col].since <= version; }

  template <class T>
  std::vector<T> read_rows(int col, hsize_t first, hsize_t count) const {
    const auto& c = columns()[col];
    const hsize_t w = row_width(c) * (is_string(c) ? kClumpTemplateBytes : 1);
    std::vector<T> out(count * w);
    if (count == 0 || !has(col)) return out;
    Hid fspace(H5Dget_space(ds[col].get()), H5Sclose);
    std::vector<hsize_t> start(1 + c.tail.size(), 0), cnt{count};
    cnt.insert(cnt.end(), c.tail.begin(), c.tail.end());
    start[0] = first;
    if (H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start.data(), nullptr, cnt.data(),
                            nullptr) < 0)
      throw InputError(file_name, "bad selection in dataset", col_path(c));
    Hid mspace(H5Screate_simple(static_cast<int>(cnt.size()), cnt.data(), nullptr), H5Sclose);
    if (H5Dread(ds[col].get(), c.mem_type(), mspace.get(), fspace.get(), H5P_DEFAULT, out.data()) <
        0)
      throw InputError(file_name, "cannot read dataset (corrupt or truncated)", col_path(c));
    return out;
  }

  void open(const std::filesystem::path& path) {
    quiet_hdf5();
    file_name = path.string();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(file_name, "no such file");
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(file_name, "not a file");
    if (!is_hdf5_file(path)) throw InputError(file_name, "not an HDF5 file (bad signature)");
    file = Hid(H5Fopen(file_name.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (!file.valid()) {  // a file still open by (or left behind by a killed) single writer
      // SWMR readers retry a metadata read whose checksum fails, sleeping 1 ns, 2 ns, 4 ns, …
      // between tries; HDF5's default of 100 tries turns a corrupt file into a hang of 2^100 ns.
      // 24 tries (16 ms of sleep in all) still ride out a read torn by the live writer.
      Hid fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
      H5Pset_metadata_read_attempts(fapl.get(), 24);
      file =
          Hid(H5Fopen(file_name.c_str(), H5F_ACC_RDONLY | H5F_ACC_SWMR_READ, fapl.get()), H5Fclose);
    }
    if (!file.valid()) throw InputError(file_name, "cannot open HDF5 file (corrupt or truncated)");
    note_input(path);

    // Root attributes.
    auto attr_string = [&](const char* nm) {
      Hid a(H5Aopen(file.get(), nm, H5P_DEFAULT), H5Aclose);
      if (!a.valid()) throw InputError(file_name, "missing root attribute", nm);
      return read_string_attr(a.get(), file_name, nm);
    };
    const std::string fmt = attr_string("format");
    if (fmt != kTrajectoryFormatName)
      throw InputError(file_name, "not a granoscope trajectory, format", fmt);
    version = read_schema_version(file.get());
    if (version == -1) throw InputError(file_name, "missing root attribute", "schema_version");
    if (version < 1 || version > kTrajectorySchemaVersion)
      throw InputError(file_name, "unsupported schema_version", std::to_string(version));
    meta.code_version = attr_string("code_version");
    meta.provenance = attr_string("provenance");
    {
      require_hard_links(file.get(), "/metadata", file_name);
      Hid g(H5Gopen2(file.get(), "metadata", H5P_DEFAULT), H5Gclose);
      if (!g.valid()) throw InputError(file_name, "missing group", "/metadata");
      H5O_info_t info;
      if (H5Oget_info2(g.get(), &info, H5O_INFO_NUM_ATTRS) < 0)
        throw InputError(file_name, "cannot read group", "/metadata");
      for (hsize_t i = 0; i < info.num_attrs; ++i) {
        Hid a(H5Aopen_by_idx(g.get(), ".", H5_INDEX_CRT_ORDER, H5_ITER_INC, i, H5P_DEFAULT,
                             H5P_DEFAULT),
              H5Aclose);
        if (!a.valid())
          a = Hid(
              H5Aopen_by_idx(g.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
        if (!a.valid())
          throw InputError(file_name, "cannot read metadata attribute", std::to_string(i));
        const ssize_t len = H5Aget_name(a.get(), 0, nullptr);
        if (len <= 0 || len > 65536) throw InputError(file_name, "bad metadata attribute name");
        std::string key(static_cast<size_t>(len) + 1, '\0');
        H5Aget_name(a.get(), key.size(), key.data());
        key.resize(static_cast<size_t>(len));
        meta.parameters.emplace_back(key, read_string_attr(a.get(), file_name, key));
      }
    }

    // Datasets: shape checks.
    ds.resize(N_COLS);
    rows.assign(N_COLS, 0);
    for (int i = 0; i < N_COLS; ++i) {
      const auto& c = columns()[i];
      if (!has(i)) continue;  // added after this file's schema_version: no rows
      require_hard_links(file.get(), col_path(c), file_name);
      ds[i] = Hid(H5Dopen2(file.get(), col_path(c).c_str(), H5P_DEFAULT), H5Dclose);
      if (!ds[i].valid()) throw InputError(file_name, "missing dataset", col_path(c));
      Hid space(H5Dget_space(ds[i].get()), H5Sclose);
      const int rank = H5Sget_simple_extent_ndims(space.get());
      if (rank != static_cast<int>(1 + c.tail.size()))
        throw InputError(file_name, "dataset has wrong rank",
                         col_path(c) + " rank " + std::to_string(rank));
      hsize_t dims[8] = {};
      H5Sget_simple_extent_dims(space.get(), dims, nullptr);
      for (size_t k = 0; k < c.tail.size(); ++k)
        if (dims[k + 1] != c.tail[k])
          throw InputError(file_name, "dataset has wrong shape", col_path(c));
      Hid type(H5Dget_type(ds[i].get()), H5Tclose);
      const auto cls = H5Tget_class(type.get());
      const bool want_float = c.mem_type() == H5T_NATIVE_DOUBLE;
      const H5T_class_t want = is_string(c) ? H5T_STRING : want_float ? H5T_FLOAT : H5T_INTEGER;
      if (cls != want || (is_string(c) && H5Tis_variable_str(type.get()) > 0))
        throw InputError(file_name, "dataset has wrong type", col_path(c));
      check_dataset_storage(ds[i].get(), dims[0], row_width(c) * H5Tget_size(c.mem_type()),
                            col_path(c), file_name);
      rows[i] = dims[0];
    }
    n = rows[F_END];
    for (int i = F_TIME; i < N_COLS; ++i)
      if (has(i) && rows[i] < n)
        throw InputError(file_name, "frame table shorter than frame index", col_path(columns()[i]));
    time = read_rows<double>(F_TIME, 0, n);
    step = read_rows<std::int64_t>(F_STEP, 0, n);
    dt = read_rows<double>(F_DT, 0, n);
    two_d = read_rows<std::int8_t>(F_TWOD, 0, n);
    lo = read_rows<double>(F_LO, 0, n);
    hi = read_rows<double>(F_HI, 0, n);
    periodic = read_rows<std::int8_t>(F_PERIODIC, 0, n);
    cell = read_rows<double>(F_CELL, 0, n);
    cell_velgrad = read_rows<double>(F_CELL_VELGRAD, 0, n);  // (zeros before version 3)
    end = read_rows<std::int64_t>(F_END, 0, n);
    clump_end = read_rows<std::int64_t>(F_CLUMP_END, 0, n);
    facet_end = read_rows<std::int64_t>(F_FACET_END, 0, n);
    // Row groups k = particles, contacts, walls (columns of /frames/end), clumps (clump_end),
    // facet loads (facet_end).
    const hsize_t limits[5] = {rows[P_ID], rows[C_ID1], rows[W_ID], rows[K_ID], rows[L_WALL]};
    const int first_col[5] = {P_ID, C_ID1, W_ID, K_ID, L_WALL};
    const int last_col[5] = {P_MAT, C_OVERLAP, W_TORQUE, K_INERTIA, L_FORCE};
    for (int k = 0; k < 5; ++k) {
      for (int c = first_col[k]; c <= last_col[k]; ++c)
        if (rows[c] != limits[k])
          throw InputError(file_name, "datasets of one group differ in length",
                           col_path(columns()[c]));
      std::int64_t prev = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const std::int64_t e = end_of(i, k);
        if (e < prev || static_cast<hsize_t>(e) > limits[k])
          throw InputError(file_name,
                           std::string("corrupt frame index ") +
                               (k < 3    ? "/frames/end"
                                : k == 3 ? "/frames/clump_end"
                                         : "/frames/facet_end") +
                               " at frame " + std::to_string(i),
                           std::to_string(e));
        prev = e;
      }
    }
  }

  std::int64_t end_of(std::size_t i, int k) const {
    return k < 3 ? end[i * 3 + k] : k == 3 ? clump_end[i] : facet_end[i];
  }

  std::pair<hsize_t, hsize_t> range(std::size_t i, int k) const {
    const hsize_t b = i == 0 ? 0 : static_cast<hsize_t>(end_of(i - 1, k));
    return {b, static_cast<hsize_t>(end_of(i, k)) - b};
  }
};

TrajectoryReader::TrajectoryReader(const std::filesystem::path& path)
    : impl_(std::make_unique<Impl>()) {
  impl_->open(path);
}
TrajectoryReader::TrajectoryReader(TrajectoryReader&&) noexcept = default;
TrajectoryReader::~TrajectoryReader() = default;

std::size_t TrajectoryReader::frame_count() const {
  return impl_->n;
}
const RunMetadata& TrajectoryReader::metadata() const {
  return impl_->meta;
}
double TrajectoryReader::time(std::size_t i) const {
  return impl_->time.at(i);
}
std::size_t TrajectoryReader::particle_count(std::size_t i) const {
  if (i >= impl_->n) throw std::out_of_range("frame index");
  return impl_->range(i, 0).second;
}
std::size_t TrajectoryReader::contact_count(std::size_t i) const {
  if (i >= impl_->n) throw std::out_of_range("frame index");
  return impl_->range(i, 1).second;
}
std::size_t TrajectoryReader::clump_count(std::size_t i) const {
  if (i >= impl_->n) throw std::out_of_range("frame index");
  return impl_->range(i, 3).second;
}
int TrajectoryReader::schema_version() const {
  return static_cast<int>(impl_->version);
}

Frame TrajectoryReader::frame(std::size_t i) const {
  const Impl& m = *impl_;
  if (i >= m.n)
    throw InputError(m.file_name, "no such frame",
                     std::to_string(i) + " of " + std::to_string(m.n));
  Frame f;
  f.time = m.time[i];
  f.step = m.step[i];
  f.dt = m.dt[i];
  f.two_d = m.two_d[i] != 0;
  f.domain.lo = get3(&m.lo[i * 3]);
  f.domain.hi = get3(&m.hi[i * 3]);
  f.domain.periodic = m.periodic[i] != 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      f.domain.cell(r, c) = m.cell[i * 9 + r * 3 + c];
      f.domain.velocity_gradient(r, c) = m.cell_velgrad[i * 9 + r * 3 + c];
    }

  {
    const auto [b, cnt] = m.range(i, 0);
    const auto id = m.read_rows<std::int64_t>(P_ID, b, cnt);
    const auto pos = m.read_rows<double>(P_POS, b, cnt);
    const auto rad = m.read_rows<double>(P_RAD, b, cnt);
    const auto vel = m.read_rows<double>(P_VEL, b, cnt);
    const auto av = m.read_rows<double>(P_ANGVEL, b, cnt);
    const auto ori = m.read_rows<double>(P_ORI, b, cnt);
    const auto rot = m.read_rows<double>(P_ROT, b, cnt);
    const auto mass = m.read_rows<double>(P_MASS, b, cnt);
    const auto clump = m.read_rows<std::int64_t>(P_CLUMP, b, cnt);
    const auto mat = m.read_rows<std::int32_t>(P_MAT, b, cnt);
    f.particles.resize(cnt);
    for (hsize_t k = 0; k < cnt; ++k) {
      auto& p = f.particles[k];
      p.id = id[k];
      p.position = get3(&pos[k * 3]);
      p.radius = rad[k];
      p.velocity = get3(&vel[k * 3]);
      p.angular_velocity = get3(&av[k * 3]);
      p.orientation = get_quat(&ori[k * 4]);
      p.rotation = get3(&rot[k * 3]);
      p.mass = mass[k];
      p.clump_id = clump[k];
      p.material_id = mat[k];
    }
  }
  {
    const auto [b, cnt] = m.range(i, 1);
    const auto id1 = m.read_rows<std::int64_t>(C_ID1, b, cnt);
    const auto id2 = m.read_rows<std::int64_t>(C_ID2, b, cnt);
    const auto pt = m.read_rows<double>(C_POINT, b, cnt);
    const auto nn = m.read_rows<double>(C_NORMAL, b, cnt);
    const auto fn = m.read_rows<double>(C_FN, b, cnt);
    const auto fs = m.read_rows<double>(C_FS, b, cnt);
    const auto mb = m.read_rows<double>(C_MB, b, cnt);
    const auto mt = m.read_rows<double>(C_MT, b, cnt);
    const auto ov = m.read_rows<double>(C_OVERLAP, b, cnt);
    f.contacts.resize(cnt);
    for (hsize_t k = 0; k < cnt; ++k) {
      auto& c = f.contacts[k];
      c.id1 = id1[k];
      c.id2 = id2[k];
      c.point = get3(&pt[k * 3]);
      c.normal = get3(&nn[k * 3]);
      c.normal_force = get3(&fn[k * 3]);
      c.shear_force = get3(&fs[k * 3]);
      c.bending_moment = get3(&mb[k * 3]);
      c.twisting_moment = get3(&mt[k * 3]);
      c.overlap = ov[k];
    }
  }
  {
    const auto [b, cnt] = m.range(i, 2);
    const auto id = m.read_rows<std::int64_t>(W_ID, b, cnt);
    const auto kind = m.read_rows<std::int32_t>(W_KIND, b, cnt);
    const auto a = m.read_rows<double>(W_A, b, cnt);
    const auto bb = m.read_rows<double>(W_B, b, cnt);
    const auto force = m.read_rows<double>(W_FORCE, b, cnt);
    const auto torque = m.read_rows<double>(W_TORQUE, b, cnt);
    f.walls.resize(cnt);
    for (hsize_t k = 0; k < cnt; ++k) {
      auto& w = f.walls[k];
      w.id = id[k];
      w.kind = static_cast<WallKind>(kind[k]);
      w.a = get3(&a[k * 3]);
      w.b = get3(&bb[k * 3]);
      w.force = get3(&force[k * 3]);
      w.torque = get3(&torque[k * 3]);
    }
  }
  {
    const auto [b, cnt] = m.range(i, 3);
    const auto id = m.read_rows<std::int64_t>(K_ID, b, cnt);
    const auto tpl = m.read_rows<char>(K_TEMPLATE, b, cnt);
    const auto pos = m.read_rows<double>(K_POS, b, cnt);
    const auto ori = m.read_rows<double>(K_ORI, b, cnt);
    const auto vel = m.read_rows<double>(K_VEL, b, cnt);
    const auto av = m.read_rows<double>(K_ANGVEL, b, cnt);
    const auto mass = m.read_rows<double>(K_MASS, b, cnt);
    const auto inertia = m.read_rows<double>(K_INERTIA, b, cnt);
    f.clumps.resize(cnt);
    for (hsize_t k = 0; k < cnt; ++k) {
      auto& c = f.clumps[k];
      c.id = id[k];
      const char* name = &tpl[k * kClumpTemplateBytes];
      c.template_name.assign(name, strnlen(name, kClumpTemplateBytes));
      c.position = get3(&pos[k * 3]);
      c.orientation = get_quat(&ori[k * 4]);
      c.velocity = get3(&vel[k * 3]);
      c.angular_velocity = get3(&av[k * 3]);
      c.mass = mass[k];
      c.principal_inertia = get3(&inertia[k * 3]);
    }
  }
  {
    const auto [b, cnt] = m.range(i, 4);
    const auto wall = m.read_rows<std::int64_t>(L_WALL, b, cnt);
    const auto facet = m.read_rows<std::int32_t>(L_FACET, b, cnt);
    const auto centroid = m.read_rows<double>(L_CENTROID, b, cnt);
    const auto force = m.read_rows<double>(L_FORCE, b, cnt);
    f.facet_loads.resize(cnt);
    for (hsize_t k = 0; k < cnt; ++k) {
      auto& l = f.facet_loads[k];
      l.wall_id = wall[k];
      l.facet = facet[k];
      l.centroid = get3(&centroid[k * 3]);
      l.force = get3(&force[k * 3]);
    }
  }
  validate_frame(f, m.file_name + " frame " + std::to_string(i));
  return f;
}

Trajectory read_hdf5_trajectory(const std::filesystem::path& path) {
  TrajectoryReader r(path);
  Trajectory t;
  t.metadata = r.metadata();
  t.frames.reserve(r.frame_count());
  for (std::size_t i = 0; i < r.frame_count(); ++i) t.frames.push_back(r.frame(i));
  return t;
}

void write_hdf5_trajectory(const std::filesystem::path& path, const Trajectory& trajectory) {
  TrajectoryWriter w(path, trajectory.metadata, TrajectoryWriter::Options{});
  w.append(trajectory.frames);
  w.finish();
}

}  // namespace gs
