// ParaView output through VTK's XML writers (binary appended, zlib, Float64/Int64 arrays).
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCommand.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <unordered_map>

#include "atomic_file.hpp"
#include "errors.hpp"
#include "vtk_io.hpp"

namespace gs {

namespace {

vtkSmartPointer<vtkDoubleArray> vec_array(const char* name, int comps, vtkIdType n) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name);
  a->SetNumberOfComponents(comps);
  a->SetNumberOfTuples(n);
  return a;
}

void add_field(vtkFieldData* fd, const char* name, std::initializer_list<double> v) {
  auto a = vec_array(name, static_cast<int>(v.size()), 1);
  int k = 0;
  for (double x : v) a->SetComponent(0, k++, x);
  fd->AddArray(a);
}

// VTK's own error output (several lines through vtkOutputWindow and vtkLogger) is silenced; the
// first message becomes part of our one line.
struct WriterErrors {
  std::string first;
  static void on_error(vtkObject*, unsigned long, void* client, void* call) {
    auto* self = static_cast<WriterErrors*>(client);
    if (self->first.empty() && call) {
      std::string m = static_cast<const char*>(call);
      m = m.substr(0, m.find('\n'));
      self->first = m.substr(0, 160);
    }
  }
};

template <class Writer>
void write_xml(Writer* w, const std::filesystem::path& path) {
  vtkObject::GlobalWarningDisplayOff();
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  AtomicOutput out(path);
  WriterErrors sink;
  vtkNew<vtkCallbackCommand> cb;
  cb->SetCallback(&WriterErrors::on_error);
  cb->SetClientData(&sink);
  w->AddObserver(vtkCommand::ErrorEvent, cb);
  w->SetFileName(out.temp_path().c_str());
  w->SetDataModeToAppended();
  w->EncodeAppendedDataOff();
  w->SetCompressorTypeToZLib();
  const int ok = w->Write();
  if (ok != 1 || w->GetErrorCode() != 0 || !sink.first.empty())
    throw InputError(path.string(), "VTK writer failed",
                     w->GetErrorCode() != 0
                         ? std::string(vtkErrorCode::GetStringFromErrorCode(w->GetErrorCode()))
                         : (sink.first.empty() ? std::string("write error") : sink.first));
  out.commit();
}

}  // namespace

void write_vtu_particles(const std::filesystem::path& path, const Frame& f) {
  const auto n = static_cast<vtkIdType>(f.particles.size());
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(n);
  vtkNew<vtkTypeInt64Array> id, clump;
  id->SetName("id");
  id->SetNumberOfTuples(n);
  clump->SetName("clump_id");
  clump->SetNumberOfTuples(n);
  vtkNew<vtkIntArray> mat;
  mat->SetName("material_id");
  mat->SetNumberOfTuples(n);
  auto rad = vec_array("radius", 1, n), vel = vec_array("velocity", 3, n),
       av = vec_array("angular_velocity", 3, n), ori = vec_array("orientation", 4, n),
       rot = vec_array("rotation", 3, n), mass = vec_array("mass", 1, n);
  vtkNew<vtkCellArray> cells;
  for (vtkIdType i = 0; i < n; ++i) {
    const auto& p = f.particles[static_cast<std::size_t>(i)];
    pts->SetPoint(i, p.position.data());
    id->SetValue(i, p.id);
    clump->SetValue(i, p.clump_id);
    mat->SetValue(i, p.material_id);
    rad->SetValue(i, p.radius);
    vel->SetTuple(i, p.velocity.data());
    av->SetTuple(i, p.angular_velocity.data());
    const double q[4] = {p.orientation.w(), p.orientation.x(), p.orientation.y(),
                         p.orientation.z()};
    ori->SetTuple(i, q);
    rot->SetTuple(i, p.rotation.data());
    mass->SetValue(i, p.mass);
    cells->InsertNextCell(1, &i);
  }
  vtkNew<vtkUnstructuredGrid> g;
  g->SetPoints(pts);
  g->SetCells(VTK_VERTEX, cells);
  auto* pd = g->GetPointData();
  for (vtkAbstractArray* a :
       std::initializer_list<vtkAbstractArray*>{id, rad, vel, av, ori, rot, mass, clump, mat})
    pd->AddArray(a);
  pd->SetActiveScalars("radius");
  auto* fd = g->GetFieldData();
  add_field(fd, "TimeValue", {f.time});
  add_field(fd, "step", {static_cast<double>(f.step)});
  add_field(fd, "dt", {f.dt});
  add_field(fd, "two_d", {f.two_d ? 1.0 : 0.0});
  add_field(fd, "domain_lo", {f.domain.lo.x(), f.domain.lo.y(), f.domain.lo.z()});
  add_field(fd, "domain_hi", {f.domain.hi.x(), f.domain.hi.y(), f.domain.hi.z()});
  add_field(fd, "periodic", {f.domain.periodic ? 1.0 : 0.0});
  const auto& c = f.domain.cell;
  add_field(fd, "cell",
            {c(0, 0), c(0, 1), c(0, 2), c(1, 0), c(1, 1), c(1, 2), c(2, 0), c(2, 1), c(2, 2)});
  const auto& l = f.domain.velocity_gradient;
  add_field(fd, "cell_velocity_gradient",
            {l(0, 0), l(0, 1), l(0, 2), l(1, 0), l(1, 1), l(1, 2), l(2, 0), l(2, 1), l(2, 2)});
  vtkNew<vtkXMLUnstructuredGridWriter> w;
  w->SetInputData(g);
  write_xml(w.Get(), path);
}

void write_vtp_contacts(const std::filesystem::path& path, const Frame& f) {
  std::unordered_map<std::int64_t, const Particle*> byid;
  for (const auto& p : f.particles) byid[p.id] = &p;
  const auto n = static_cast<vtkIdType>(f.contacts.size());
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(2 * n);
  vtkNew<vtkCellArray> lines;
  vtkNew<vtkTypeInt64Array> id1, id2;
  id1->SetName("id1");
  id1->SetNumberOfTuples(n);
  id2->SetName("id2");
  id2->SetNumberOfTuples(n);
  auto pt = vec_array("point", 3, n), nn = vec_array("normal", 3, n),
       fn = vec_array("normal_force", 3, n), fs = vec_array("shear_force", 3, n),
       fnm = vec_array("fn_magnitude", 1, n), mb = vec_array("bending_moment", 3, n),
       mt = vec_array("twisting_moment", 3, n), ov = vec_array("overlap", 1, n);
  for (vtkIdType i = 0; i < n; ++i) {
    const auto& c = f.contacts[static_cast<std::size_t>(i)];
    const auto a = byid.find(c.id1), b = byid.find(c.id2);
    const Eigen::Vector3d xa = a != byid.end() ? a->second->position : c.point;
    const Eigen::Vector3d xb = b != byid.end() ? b->second->position : c.point;
    pts->SetPoint(2 * i, xa.data());
    pts->SetPoint(2 * i + 1, xb.data());
    const vtkIdType line[2] = {2 * i, 2 * i + 1};
    lines->InsertNextCell(2, line);
    id1->SetValue(i, c.id1);
    id2->SetValue(i, c.id2);
    pt->SetTuple(i, c.point.data());
    nn->SetTuple(i, c.normal.data());
    fn->SetTuple(i, c.normal_force.data());
    fs->SetTuple(i, c.shear_force.data());
    fnm->SetValue(i, c.normal_force.norm());
    mb->SetTuple(i, c.bending_moment.data());
    mt->SetTuple(i, c.twisting_moment.data());
    ov->SetValue(i, c.overlap);
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetLines(lines);
  auto* cd = pd->GetCellData();
  for (vtkAbstractArray* a :
       std::initializer_list<vtkAbstractArray*>{id1, id2, pt, nn, fn, fs, fnm, mb, mt, ov})
    cd->AddArray(a);
  cd->SetActiveScalars("fn_magnitude");
  add_field(pd->GetFieldData(), "TimeValue", {f.time});
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetInputData(pd);
  write_xml(w.Get(), path);
}

void write_vtu_clumps(const std::filesystem::path& path, const Frame& f) {
  const auto n = static_cast<vtkIdType>(f.clumps.size());
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(n);
  vtkNew<vtkTypeInt64Array> id;
  id->SetName("id");
  id->SetNumberOfTuples(n);
  vtkNew<vtkIntArray> tpl;
  tpl->SetName("template");
  tpl->SetNumberOfTuples(n);
  vtkNew<vtkStringArray> names;  // field data: template index k is template_names[k]
  names->SetName("template_names");
  std::map<std::string, int> index;
  auto vel = vec_array("velocity", 3, n), av = vec_array("angular_velocity", 3, n),
       ori = vec_array("orientation", 4, n), mass = vec_array("mass", 1, n),
       inertia = vec_array("principal_inertia", 3, n), a1 = vec_array("axis_1", 3, n),
       a2 = vec_array("axis_2", 3, n), a3 = vec_array("axis_3", 3, n);
  vtkDoubleArray* axes[3] = {a1, a2, a3};
  vtkNew<vtkCellArray> cells;
  for (vtkIdType i = 0; i < n; ++i) {
    const auto& c = f.clumps[static_cast<std::size_t>(i)];
    pts->SetPoint(i, c.position.data());
    id->SetValue(i, c.id);
    const auto [it, added] = index.emplace(c.template_name, static_cast<int>(index.size()));
    if (added) names->InsertNextValue(c.template_name);
    tpl->SetValue(i, it->second);
    vel->SetTuple(i, c.velocity.data());
    av->SetTuple(i, c.angular_velocity.data());
    const double q[4] = {c.orientation.w(), c.orientation.x(), c.orientation.y(),
                         c.orientation.z()};
    ori->SetTuple(i, q);
    mass->SetValue(i, c.mass);
    inertia->SetTuple(i, c.principal_inertia.data());
    const Eigen::Matrix3d r = c.orientation.normalized().toRotationMatrix();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d axis = r.col(k);  // principal axis k in the lab frame (unit)
      axes[k]->SetTuple(i, axis.data());
    }
    cells->InsertNextCell(1, &i);
  }
  vtkNew<vtkUnstructuredGrid> g;
  g->SetPoints(pts);
  g->SetCells(VTK_VERTEX, cells);
  auto* pd = g->GetPointData();
  for (vtkAbstractArray* a :
       std::initializer_list<vtkAbstractArray*>{id, tpl, vel, av, ori, mass, inertia, a1, a2, a3})
    pd->AddArray(a);
  pd->SetActiveScalars("mass");
  auto* fd = g->GetFieldData();
  add_field(fd, "TimeValue", {f.time});
  fd->AddArray(names);
  vtkNew<vtkXMLUnstructuredGridWriter> w;
  w->SetInputData(g);
  write_xml(w.Get(), path);
}

std::filesystem::path clumps_sibling(const std::filesystem::path& path) {
  auto p = path.parent_path() / (path.stem().string() + "_clumps");
  p += path.extension();
  return p;
}

namespace {

/// The collection under a temporary name; the caller commits it.
std::unique_ptr<AtomicOutput> write_pvd_file(
    const std::filesystem::path& path, const std::vector<std::pair<double, std::string>>& entries) {
  auto out = std::make_unique<AtomicOutput>(path);
  {
    std::ofstream o(out->temp_path());
    o << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
    char buf[64];
    for (const auto& [t, file] : entries) {
      std::snprintf(buf, sizeof buf, "%.17g", t);
      o << "    <DataSet timestep=\"" << buf << "\" part=\"0\" file=\"" << file << "\"/>\n";
    }
    o << "  </Collection>\n</VTKFile>\n";
    if (!o.flush()) throw InputError(path.string(), "write failed");
  }
  return out;
}

}  // namespace

void write_pvd_series(const std::filesystem::path& pvd_path, const Trajectory& t) {
  const auto dir_name = pvd_path.stem().string() + "_files";
  const auto dir = pvd_path.parent_path() / dir_name;
  auto contacts_pvd = pvd_path.parent_path() / (pvd_path.stem().string() + "_contacts.pvd");
  const auto clumps_pvd = clumps_sibling(pvd_path);
  bool any_clumps = false;
  for (const auto& f : t.frames) any_clumps = any_clumps || !f.clumps.empty();
  AtomicOutput tmp_dir(dir);
  std::error_code ec;
  std::filesystem::create_directory(tmp_dir.temp_path(), ec);
  if (ec) throw InputError(dir.string(), "cannot create directory", ec.message());
  struct Cleanup {
    std::filesystem::path p;
    bool armed = true;
    ~Cleanup() {
      std::error_code e;
      if (armed) std::filesystem::remove_all(p, e);
    }
  } cleanup{tmp_dir.temp_path()};
  std::vector<std::pair<double, std::string>> pe, ce, ke;
  char name[64];
  for (std::size_t i = 0; i < t.frames.size(); ++i) try {
      std::snprintf(name, sizeof name, "particles_%06zu.vtu", i);
      write_vtu_particles(tmp_dir.temp_path() / name, t.frames[i]);
      pe.emplace_back(t.frames[i].time, dir_name + "/" + name);
      std::snprintf(name, sizeof name, "contacts_%06zu.vtp", i);
      write_vtp_contacts(tmp_dir.temp_path() / name, t.frames[i]);
      ce.emplace_back(t.frames[i].time, dir_name + "/" + name);
      if (!any_clumps) continue;
      std::snprintf(name, sizeof name, "clumps_%06zu.vtu", i);
      write_vtu_clumps(tmp_dir.temp_path() / name, t.frames[i]);
      ke.emplace_back(t.frames[i].time, dir_name + "/" + name);
    } catch (const InputError& e) {
      throw with_dir_renamed(e, tmp_dir.temp_path(), dir);  // named as the directory it stands for
    }
  // Everything is written under temporary names before anything is renamed (a full disk leaves
  // no file under its final name).
  const auto contacts = write_pvd_file(contacts_pvd, ce);
  const auto clumps = any_clumps ? write_pvd_file(clumps_pvd, ke) : nullptr;
  const auto particles = write_pvd_file(pvd_path, pe);
  sync_to_disk(tmp_dir.temp_path());
  std::filesystem::remove_all(dir, ec);
  tmp_dir.commit();
  cleanup.armed = false;
  contacts->commit();
  if (clumps)
    clumps->commit();
  else
    std::filesystem::remove(clumps_pvd, ec);  // a stale series would name files just replaced
  particles->commit();
}

}  // namespace gs
