// Reading XML VTK (ours and YADE VTKRecorder's) through VTK's readers, with VTK's own error
// output silenced and turned into one InputError.
#include <vtkCallbackCommand.h>
#include <vtkCellData.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cmath>
#include <limits>
#include <regex>

#include "atomic_file.hpp"
#include "errors.hpp"
#include "text_parse.hpp"
#include "vtk_io.hpp"
#include "vtk_xml_check.hpp"

namespace gs {

namespace {

struct ErrorSink {
  std::string first;
  static void on_error(vtkObject*, unsigned long, void* client, void* call) {
    auto* self = static_cast<ErrorSink*>(client);
    if (self->first.empty() && call) {
      std::string m = static_cast<const char*>(call);
      const auto nl = m.find('\n');
      if (nl != std::string::npos) m = m.substr(0, nl);
      self->first = m.substr(0, 160);
    }
  }
};

template <class Reader>
void run_reader(Reader* r, const std::filesystem::path& path) {
  vtkObject::GlobalWarningDisplayOff();
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(name, "no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(name, "not a regular file");
  check_vtk_xml_structure(path);  // what VTK would trust: counts, sizes, nesting
  note_input(path);
  ErrorSink sink;
  vtkNew<vtkCallbackCommand> cb;
  cb->SetCallback(&ErrorSink::on_error);
  cb->SetClientData(&sink);
  r->AddObserver(vtkCommand::ErrorEvent, cb);
  r->AddObserver(vtkCommand::WarningEvent, cb);
  r->SetFileName(name.c_str());
  try {
    r->Update();
  } catch (const std::bad_alloc&) {
    throw InputError(name, "not enough memory to read the file");
  }
  if (!sink.first.empty() || r->GetErrorCode() != 0)
    throw InputError(name, "cannot read VTK XML file",
                     sink.first.empty() ? "reader error" : sink.first);
}

vtkDataArray* find_array(vtkFieldData* fd, std::initializer_list<const char*> names, int comps,
                         vtkIdType n, const std::string& file, bool required) {
  for (const char* nm : names) {
    vtkDataArray* a = fd->GetArray(nm);
    if (!a) continue;
    if (a->GetNumberOfComponents() != comps || a->GetNumberOfTuples() != n)
      throw InputError(file, std::string("array ") + nm + " has the wrong shape",
                       std::to_string(a->GetNumberOfTuples()) + "x" +
                           std::to_string(a->GetNumberOfComponents()));
    return a;
  }
  if (required) throw InputError(file, "missing array", *names.begin());
  return nullptr;
}

double field_scalar(vtkFieldData* fd, const char* name, int k, double fallback) {
  vtkDataArray* a = fd ? fd->GetArray(name) : nullptr;
  if (!a || a->GetNumberOfTuples() < 1 || a->GetNumberOfComponents() <= k) return fallback;
  return a->GetComponent(0, k);
}

// An id stored as a floating-point array value (YADE writes Float64 ids): integral and exact.
std::int64_t id_value(vtkDataArray* a, vtkIdType i, const std::string& file, const char* what) {
  const double v = a->GetComponent(i, 0);
  if (!(std::abs(v) <= 9e15) || v != std::round(v))
    throw InputError(file, std::string(what) + " is not an integer", value_str(v));
  return static_cast<std::int64_t>(v);
}

Eigen::Vector3d tuple3(vtkDataArray* a, vtkIdType i) {
  double v[3];
  a->GetTuple(i, v);
  return {v[0], v[1], v[2]};
}

}  // namespace

Frame read_vtu_particles(const std::filesystem::path& path) {
  const std::string name = path.string();
  vtkNew<vtkXMLUnstructuredGridReader> r;
  run_reader(r.Get(), path);
  vtkUnstructuredGrid* g = r->GetOutput();
  if (!g || !g->GetPoints()) throw InputError(name, "no points in file");
  const vtkIdType n = g->GetNumberOfPoints();
  auto* pd = g->GetPointData();
  vtkDataArray* rad = find_array(pd, {"radius", "radii"}, 1, n, name, true);
  vtkDataArray* id = find_array(pd, {"id", "ids"}, 1, n, name, false);
  vtkDataArray* vel = find_array(pd, {"velocity", "linVelVec"}, 3, n, name, false);
  vtkDataArray* av = find_array(pd, {"angular_velocity", "angVelVec"}, 3, n, name, false);
  vtkDataArray* ori = find_array(pd, {"orientation"}, 4, n, name, false);
  vtkDataArray* rot = find_array(pd, {"rotation"}, 3, n, name, false);
  vtkDataArray* mass = find_array(pd, {"mass"}, 1, n, name, false);
  vtkDataArray* clump = find_array(pd, {"clump_id", "clumpId"}, 1, n, name, false);
  vtkDataArray* mat = find_array(pd, {"material_id", "materialId"}, 1, n, name, false);
  Frame f;
  f.particles.resize(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i) {
    auto& p = f.particles[static_cast<std::size_t>(i)];
    double x[3];
    g->GetPoints()->GetPoint(i, x);
    p.position = {x[0], x[1], x[2]};
    p.radius = rad->GetComponent(i, 0);
    p.id = id ? id_value(id, i, name, "particle id") : i;
    if (vel) p.velocity = tuple3(vel, i);
    if (av) p.angular_velocity = tuple3(av, i);
    if (ori) {
      double q[4];
      ori->GetTuple(i, q);
      p.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    }
    if (rot) p.rotation = tuple3(rot, i);
    if (mass) p.mass = mass->GetComponent(i, 0);
    // YADE writes clumpId = -1 for standalone bodies, as we do.
    if (clump) p.clump_id = id_value(clump, i, name, "clump id");
    if (mat) {
      const std::int64_t m = id_value(mat, i, name, "material id");
      if (m < std::numeric_limits<std::int32_t>::min() ||
          m > std::numeric_limits<std::int32_t>::max())
        throw InputError(name, "material id out of range", value_str(m));
      p.material_id = static_cast<std::int32_t>(m);
    }
  }
  vtkFieldData* fd = g->GetFieldData();
  f.time = field_scalar(fd, "TimeValue", 0, 0.0);
  f.step = static_cast<std::int64_t>(std::llround(field_scalar(fd, "step", 0, 0.0)));
  f.dt = field_scalar(fd, "dt", 0, 0.0);
  f.two_d = field_scalar(fd, "two_d", 0, 0.0) != 0.0;
  f.domain.periodic = field_scalar(fd, "periodic", 0, 0.0) != 0.0;
  if (fd && fd->GetArray("domain_lo") && fd->GetArray("domain_hi")) {
    for (int d = 0; d < 3; ++d) {
      f.domain.lo[d] = field_scalar(fd, "domain_lo", d, 0.0);
      f.domain.hi[d] = field_scalar(fd, "domain_hi", d, 0.0);
    }
  } else {
    std::tie(f.domain.lo, f.domain.hi) = particle_bounds(f);
  }
  if (fd && fd->GetArray("cell"))
    for (int k = 0; k < 9; ++k) f.domain.cell(k / 3, k % 3) = field_scalar(fd, "cell", k, 0.0);
  if (fd && fd->GetArray("cell_velocity_gradient"))
    for (int k = 0; k < 9; ++k)
      f.domain.velocity_gradient(k / 3, k % 3) = field_scalar(fd, "cell_velocity_gradient", k, 0.0);
  validate_frame(f, name);
  return f;
}

void read_vtp_contacts(const std::filesystem::path& path, Frame& f) {
  const std::string name = path.string();
  vtkNew<vtkXMLPolyDataReader> r;
  run_reader(r.Get(), path);
  vtkPolyData* pd = r->GetOutput();
  if (!pd) throw InputError(name, "no poly data in file");
  const vtkIdType n = pd->GetNumberOfCells();
  auto* cd = pd->GetCellData();
  vtkDataArray* id1 = find_array(cd, {"id1"}, 1, n, name, true);
  vtkDataArray* id2 = find_array(cd, {"id2"}, 1, n, name, true);
  vtkDataArray* pt = find_array(cd, {"point"}, 3, n, name, true);
  vtkDataArray* nn = find_array(cd, {"normal"}, 3, n, name, true);
  vtkDataArray* fn = find_array(cd, {"normal_force"}, 3, n, name, true);
  vtkDataArray* fs = find_array(cd, {"shear_force"}, 3, n, name, true);
  vtkDataArray* mb = find_array(cd, {"bending_moment"}, 3, n, name, false);
  vtkDataArray* mt = find_array(cd, {"twisting_moment"}, 3, n, name, false);
  vtkDataArray* ov = find_array(cd, {"overlap"}, 1, n, name, false);
  f.contacts.resize(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i) {
    auto& c = f.contacts[static_cast<std::size_t>(i)];
    c.id1 = id_value(id1, i, name, "contact id1");
    c.id2 = id_value(id2, i, name, "contact id2");
    c.point = tuple3(pt, i);
    c.normal = tuple3(nn, i);
    c.normal_force = tuple3(fn, i);
    c.shear_force = tuple3(fs, i);
    if (mb) c.bending_moment = tuple3(mb, i);
    if (mt) c.twisting_moment = tuple3(mt, i);
    if (ov) c.overlap = ov->GetComponent(i, 0);
  }
  validate_frame(f, name);
}

void read_vtu_clumps(const std::filesystem::path& path, Frame& f) {
  const std::string name = path.string();
  vtkNew<vtkXMLUnstructuredGridReader> r;
  run_reader(r.Get(), path);
  vtkUnstructuredGrid* g = r->GetOutput();
  if (!g) throw InputError(name, "no unstructured grid in file");
  const vtkIdType n = g->GetNumberOfPoints();
  auto* pd = g->GetPointData();
  vtkDataArray* id = find_array(pd, {"id"}, 1, n, name, true);
  vtkDataArray* tpl = find_array(pd, {"template"}, 1, n, name, true);
  vtkDataArray* vel = find_array(pd, {"velocity"}, 3, n, name, true);
  vtkDataArray* av = find_array(pd, {"angular_velocity"}, 3, n, name, true);
  vtkDataArray* ori = find_array(pd, {"orientation"}, 4, n, name, true);
  vtkDataArray* mass = find_array(pd, {"mass"}, 1, n, name, true);
  vtkDataArray* inertia = find_array(pd, {"principal_inertia"}, 3, n, name, true);
  auto* names =
      g->GetFieldData()
          ? vtkStringArray::SafeDownCast(g->GetFieldData()->GetAbstractArray("template_names"))
          : nullptr;
  if (n > 0 && !names) throw InputError(name, "missing array", "template_names");
  f.clumps.resize(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i) {
    auto& c = f.clumps[static_cast<std::size_t>(i)];
    double x[3];
    g->GetPoints()->GetPoint(i, x);
    c.position = {x[0], x[1], x[2]};
    c.id = id_value(id, i, name, "clump id");
    const std::int64_t k = id_value(tpl, i, name, "clump template index");
    if (k < 0 || k >= names->GetNumberOfValues())
      throw InputError(name, "clump template index out of range", value_str(k));
    c.template_name = names->GetValue(static_cast<vtkIdType>(k));
    c.velocity = tuple3(vel, i);
    c.angular_velocity = tuple3(av, i);
    double q[4];
    ori->GetTuple(i, q);
    c.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    c.mass = mass->GetComponent(i, 0);
    c.principal_inertia = tuple3(inertia, i);
  }
  validate_frame(f, name);
}

Trajectory read_pvd_series(const std::filesystem::path& pvd_path) {
  const std::string name = pvd_path.string();
  auto entries = [&](const std::filesystem::path& p) {
    const std::string xml = text::read_text_file(p, 1u << 26);
    if (xml.find("<VTKFile") == std::string::npos || xml.find("Collection") == std::string::npos)
      throw InputError(p.string(), "not a ParaView collection (.pvd)");
    // A collection cut short lists only some of its frames: it must close.
    if (xml.find("</Collection>") == std::string::npos ||
        xml.find("</VTKFile>") == std::string::npos)
      throw InputError(p.string(),
                       "truncated collection (no closing </Collection> and </VTKFile>)");
    std::vector<std::pair<double, std::filesystem::path>> out;
    static const std::regex ds(R"(<DataSet\b([^>]*)>)");
    static const std::regex ts(R"(timestep\s*=\s*"([^"]*)\")"), fl(R"(file\s*=\s*"([^"]*)\")");
    for (auto it = std::sregex_iterator(xml.begin(), xml.end(), ds); it != std::sregex_iterator();
         ++it) {
      const std::string attrs = (*it)[1];
      std::smatch mt, mf;
      if (!std::regex_search(attrs, mf, fl))
        throw InputError(p.string(), "DataSet without file attribute");
      double t = 0;
      if (std::regex_search(attrs, mt, ts)) {
        t = text::to_double(mt[1].str(), p.string(), 0, "timestep");
        if (!std::isfinite(t))
          throw InputError(p.string(), "DataSet timestep is not finite", mt[1]);
      }
      out.emplace_back(t, p.parent_path() / mf[1].str());
    }
    if (out.empty()) throw InputError(p.string(), "collection lists no DataSet");
    return out;
  };
  const auto parts = entries(pvd_path);
  Trajectory t;
  t.metadata.code_version = code_version();
  t.metadata.provenance = "read from ParaView series " + name;
  for (const auto& [time, file] : parts) {
    Frame f = read_vtu_particles(file);
    f.time = time;
    t.frames.push_back(std::move(f));
  }
  const auto cpvd = pvd_path.parent_path() / (pvd_path.stem().string() + "_contacts.pvd");
  std::error_code ec;
  if (std::filesystem::exists(cpvd, ec)) {
    const auto cs = entries(cpvd);
    if (cs.size() != t.frames.size())
      throw InputError(cpvd.string(), "contact series length differs from particle series",
                       std::to_string(cs.size()));
    for (std::size_t i = 0; i < cs.size(); ++i) read_vtp_contacts(cs[i].second, t.frames[i]);
  }
  const auto kpvd = clumps_sibling(pvd_path);
  if (std::filesystem::exists(kpvd, ec)) {
    const auto ks = entries(kpvd);
    if (ks.size() != t.frames.size())
      throw InputError(kpvd.string(), "clump series length differs from particle series",
                       std::to_string(ks.size()));
    for (std::size_t i = 0; i < ks.size(); ++i) read_vtu_clumps(ks[i].second, t.frames[i]);
  }
  return t;
}

}  // namespace gs
