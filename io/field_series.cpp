#include "field_series.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>

#include "errors.hpp"
#include "field_output.hpp"

namespace gs {
namespace {

// One HDF5 handle, closed with its owner.
class Hid {
 public:
  Hid(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  ~Hid() {
    if (id_ >= 0) close_(id_);
  }
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

/// What a part holds: its datasets (path → numeric or not) and attributes (object → names).
struct Listing {
  std::vector<std::string> datasets;
  std::vector<std::string> objects;  // "/" and every group and dataset, in visiting order
};

herr_t visit(hid_t, const char* name, const H5O_info_t* info, void* data) {
  auto& l = *static_cast<Listing*>(data);
  const std::string path = std::string(name) == "." ? "/" : "/" + std::string(name);
  l.objects.push_back(path);
  if (info->type == H5O_TYPE_DATASET) l.datasets.push_back(path);
  return 0;
}

Listing list(hid_t file) {
  Listing l;
  H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_INC, visit, &l, H5O_INFO_BASIC);
  return l;
}

struct Array {
  std::vector<hsize_t> dims;
  bool integer = false;
  std::vector<double> real;
  std::vector<std::int64_t> whole;
};

/// A numeric dataset as double or int64; false for other types (strings, compounds).
bool read_array(hid_t file, const std::string& path, const std::string& part, Array& a) {
  const Hid d(H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!d.ok()) throw InputError(part, "dataset missing from this frame's output", path);
  const Hid type(H5Dget_type(d.get()), H5Tclose);
  const H5T_class_t cls = H5Tget_class(type.get());
  if (cls != H5T_FLOAT && cls != H5T_INTEGER) return false;
  const Hid space(H5Dget_space(d.get()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  a.dims.assign(static_cast<std::size_t>(std::max(rank, 0)), 0);
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), a.dims.data(), nullptr);
  hsize_t n = 1;
  for (const hsize_t k : a.dims) n *= k;
  a.integer = cls == H5T_INTEGER;
  herr_t status = 0;
  if (a.integer) {
    a.whole.resize(n);
    if (n)
      status = H5Dread(d.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.whole.data());
  } else {
    a.real.resize(n);
    if (n)
      status = H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a.real.data());
  }
  if (status < 0) throw InputError(part, "cannot read dataset", path);
  return true;
}

struct Attribute {
  bool text = false;
  double number = 0;
  std::string string;
};

herr_t read_attribute(hid_t obj, const char* name, const H5A_info_t*, void* data) {
  auto& out = *static_cast<std::map<std::string, Attribute>*>(data);
  const Hid a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  const Hid type(H5Aget_type(a.get()), H5Tclose);
  const Hid space(H5Aget_space(a.get()), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) return 0;  // (arrays: not written by us)
  Attribute v;
  switch (H5Tget_class(type.get())) {
    case H5T_STRING: {
      v.text = true;
      if (H5Tis_variable_str(type.get()) > 0) {
        char* s = nullptr;
        const Hid mem(H5Tcopy(H5T_C_S1), H5Tclose);
        H5Tset_size(mem.get(), H5T_VARIABLE);
        if (H5Aread(a.get(), mem.get(), &s) >= 0 && s) {
          v.string = s;
          H5free_memory(s);
        }
      } else {
        std::string s(H5Tget_size(type.get()), '\0');
        if (H5Aread(a.get(), type.get(), s.data()) >= 0) v.string = s.c_str();
      }
      break;
    }
    case H5T_FLOAT:
    case H5T_INTEGER:
      H5Aread(a.get(), H5T_NATIVE_DOUBLE, &v.number);
      break;
    default:
      return 0;
  }
  out[name] = v;
  return 0;
}

std::map<std::string, Attribute> attributes(hid_t file, const std::string& object) {
  std::map<std::string, Attribute> out;
  const Hid obj(H5Oopen(file, object.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.ok()) return out;
  hsize_t at = 0;
  H5Aiterate2(obj.get(), H5_INDEX_NAME, H5_ITER_INC, &at, read_attribute, &out);
  return out;
}

}  // namespace

void merge_field_series(const std::vector<std::filesystem::path>& parts,
                        const std::vector<long>& frames, const std::filesystem::path& out) {
  if (parts.empty() || parts.size() != frames.size())
    throw InputError(out.string(), "a frame series needs one output per frame");
  std::vector<std::unique_ptr<Hid>> files;
  for (const auto& p : parts) {
    files.push_back(
        std::make_unique<Hid>(H5Fopen(p.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose));
    if (!files.back()->ok()) throw InputError(p.string(), "cannot open a frame's output");
  }
  const std::size_t nf = parts.size();
  const Listing first = list(files[0]->get());
  // Attributes of every object in every frame.
  std::vector<std::vector<std::map<std::string, Attribute>>> attrs(first.objects.size());
  for (std::size_t o = 0; o < first.objects.size(); ++o)
    for (std::size_t f = 0; f < nf; ++f)
      attrs[o].push_back(attributes(files[f]->get(), first.objects[o]));
  const auto& root = attrs[0];  // (the first object visited is "/")
  const auto fmt = root[0].find("format");
  H5FieldFile h(out, "granoscope-series");
  h.attr("of", fmt != root[0].end() ? fmt->second.string : std::string("unknown"));
  h.attr("frames", static_cast<long long>(nf));
  std::vector<std::int64_t> index(frames.begin(), frames.end());
  h.write("/frame", index);
  for (const std::string& path : first.datasets) {
    std::vector<Array> a(nf);
    bool numeric = true;
    for (std::size_t f = 0; f < nf && numeric; ++f)
      numeric = read_array(files[f]->get(), path, parts[f].string(), a[f]);
    if (!numeric || path == "/frame") continue;
    bool same = true;
    for (std::size_t f = 1; f < nf; ++f) {
      if (a[f].integer != a[0].integer || a[f].dims.size() != a[0].dims.size())
        throw InputError(
            parts[f].string(),
            "a dataset differs in type or rank from frame " + std::to_string(frames[0]) + "'s",
            path);
      same = same && a[f].dims == a[0].dims;
    }
    std::vector<std::size_t> dims;
    std::vector<std::int64_t> offsets{0};
    if (same) {
      dims.push_back(nf);
      for (const hsize_t k : a[0].dims) dims.push_back(static_cast<std::size_t>(k));
    } else {
      std::size_t rows = 0;
      for (const Array& x : a) {
        rows += x.dims.empty() ? 1 : static_cast<std::size_t>(x.dims[0]);
        offsets.push_back(static_cast<std::int64_t>(rows));
      }
      dims.push_back(rows);
      for (std::size_t k = 1; k < a[0].dims.size(); ++k)
        dims.push_back(static_cast<std::size_t>(a[0].dims[k]));
    }
    if (a[0].integer) {
      std::vector<std::int64_t> v;
      for (const Array& x : a) v.insert(v.end(), x.whole.begin(), x.whole.end());
      h.write(path, v, dims);
    } else {
      std::vector<double> v;
      for (const Array& x : a) v.insert(v.end(), x.real.begin(), x.real.end());
      h.write(path, v, dims);
    }
    if (!same) h.write(path + "_offsets", offsets);
  }
  // Attributes: numbers per frame as datasets, strings once.
  for (std::size_t o = 0; o < first.objects.size(); ++o) {
    const std::string& obj = first.objects[o];
    for (const auto& [name, v0] : attrs[o][0]) {
      if (obj == "/" && (name == "format" || name == "code_version")) continue;
      if (v0.text) {
        bool varies = false;
        for (std::size_t f = 1; f < nf; ++f) {
          const auto it = attrs[o][f].find(name);
          varies = varies || it == attrs[o][f].end() || it->second.string != v0.string;
        }
        if (obj != "/") continue;  // (a group's or dataset's text: its name says enough)
        h.attr(name, v0.string);
        if (varies) h.attr(name + "_varies", 1LL);
        continue;
      }
      std::vector<double> v(nf, 0.0);
      for (std::size_t f = 0; f < nf; ++f) {
        const auto it = attrs[o][f].find(name);
        if (it == attrs[o][f].end() || it->second.text)
          throw InputError(parts[f].string(), "attribute missing from this frame's output",
                           obj + ":" + name);
        v[f] = it->second.number;
      }
      h.write("/attributes" + (obj == "/" ? std::string() : obj) + "/" + name, v);
    }
  }
  h.commit();
}

}  // namespace gs
