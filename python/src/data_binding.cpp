// Frames and trajectories. A frame's per-particle, per-contact and per-wall fields are numpy
// views into the frame's own arrays of structs (strided, no copy, writable; each view keeps its
// frame alive); `Trajectory` reads HDF5 trajectories frame by frame and every other format at
// once (io/trajectory_io.hpp).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "snapshot.hpp"
#include "trajectory_io.hpp"

namespace py = pybind11;

namespace gs::py_bind {
namespace {

// Byte offset of a member within its struct, read off an instance (Eigen members make the
// structs non-standard-layout, where offsetof is not guaranteed).
template <class T, class M>
std::size_t offset_of(M T::*member) {
  const T probe{};
  return static_cast<std::size_t>(reinterpret_cast<const char*>(&(probe.*member)) -
                                  reinterpret_cast<const char*>(&probe));
}

// A numpy view of `components` consecutive scalars of type S at `member` of every element of
// `v`, owned by `owner` (the Python object that holds `v`). components == 0: a 1-D array.
template <class S, class T, class M>
py::array view(py::handle owner, std::vector<T>& v, M T::*member, py::ssize_t components) {
  const auto n = static_cast<py::ssize_t>(v.size());
  static T empty{};  // a valid address for zero-length views
  char* base = reinterpret_cast<char*>(v.empty() ? &empty : v.data()) + offset_of(member);
  const auto row = static_cast<py::ssize_t>(sizeof(T));
  if (components == 0) return py::array_t<S>({n}, {row}, reinterpret_cast<S*>(base), owner);
  return py::array_t<S>({n, components}, {row, static_cast<py::ssize_t>(sizeof(S))},
                        reinterpret_cast<S*>(base), owner);
}

// A view of one fixed-size Eigen member of a single struct (the domain's vectors and matrices).
template <class Derived>
py::array eigen_view(py::handle owner, Eigen::PlainObjectBase<Derived>& x) {
  constexpr auto r = static_cast<py::ssize_t>(Derived::RowsAtCompileTime);
  constexpr auto c = static_cast<py::ssize_t>(Derived::ColsAtCompileTime);
  constexpr auto d = static_cast<py::ssize_t>(sizeof(double));
  if (c == 1) return py::array_t<double>({r}, {d}, x.data(), owner);
  return py::array_t<double>({r, c}, {d, r * d}, x.data(), owner);  // column-major storage
}

// Rows of a float64 (n, k) array (k = 0: 1-D) as a contiguous copy, checking the shape.
template <class T = double>
py::array_t<T, py::array::c_style | py::array::forcecast> rows(py::handle a, const char* name,
                                                               py::ssize_t n, py::ssize_t k) {
  auto arr = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!arr) throw InputError("<arrays>", std::string(name) + " is not a numeric array");
  const bool ok = k == 0 ? (arr.ndim() == 1 && arr.shape(0) == n)
                         : (arr.ndim() == 2 && arr.shape(0) == n && arr.shape(1) == k);
  if (!ok) {
    std::ostringstream s;
    s << "shape (";
    for (py::ssize_t i = 0; i < arr.ndim(); ++i) s << (i ? ", " : "") << arr.shape(i);
    s << (arr.ndim() == 1 ? ",)" : ")") << ", expected (" << n
      << (k ? ", " + std::to_string(k) : ",") << ")";
    throw InputError("<arrays>", std::string(name) + " has the wrong shape", s.str());
  }
  return arr;
}

Frame frame_from_arrays(py::handle positions, py::handle radii, py::object velocities,
                        py::object angular_velocities, py::object ids, py::object masses,
                        py::object clump_ids, py::object material_ids, py::object contact_ids,
                        py::object contact_points, py::object contact_normals,
                        py::object normal_forces, py::object shear_forces, py::object overlaps,
                        double time, std::int64_t step, double dt, bool two_d) {
  auto pos = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(positions);
  if (!pos || pos.ndim() != 2 || pos.shape(1) != 3)
    throw InputError("<arrays>", "positions must be an (N, 3) array");
  const py::ssize_t n = pos.shape(0);
  Frame f;
  f.time = time;
  f.step = step;
  f.dt = dt;
  f.two_d = two_d;
  f.particles.resize(static_cast<std::size_t>(n));
  const auto r = rows(radii, "radii", n, 0);
  for (py::ssize_t i = 0; i < n; ++i) {
    Particle& p = f.particles[static_cast<std::size_t>(i)];
    p.id = i;
    p.position = Eigen::Vector3d(pos.at(i, 0), pos.at(i, 1), pos.at(i, 2));
    p.radius = r.at(i);
  }
  const auto vec3 = [&](py::object a, const char* name, auto set) {
    if (a.is_none()) return;
    const auto v = rows(a, name, n, 3);
    for (py::ssize_t i = 0; i < n; ++i)
      set(f.particles[static_cast<std::size_t>(i)],
          Eigen::Vector3d(v.at(i, 0), v.at(i, 1), v.at(i, 2)));
  };
  vec3(velocities, "velocities", [](Particle& p, const Eigen::Vector3d& x) { p.velocity = x; });
  vec3(angular_velocities, "angular_velocities",
       [](Particle& p, const Eigen::Vector3d& x) { p.angular_velocity = x; });
  const auto scalar = [&](py::object a, const char* name, auto set) {
    if (a.is_none()) return;
    const auto v = rows(a, name, n, 0);
    for (py::ssize_t i = 0; i < n; ++i) set(f.particles[static_cast<std::size_t>(i)], v.at(i));
  };
  scalar(masses, "masses", [](Particle& p, double x) { p.mass = x; });
  // Integer fields as int64, never through double (ids above 2^53 stay exact).
  const auto integer = [&](py::object a, const char* name, auto set) {
    if (a.is_none()) return;
    const auto v = rows<std::int64_t>(a, name, n, 0);
    for (py::ssize_t i = 0; i < n; ++i) set(f.particles[static_cast<std::size_t>(i)], v.at(i));
  };
  integer(ids, "ids", [](Particle& p, std::int64_t x) { p.id = x; });
  integer(clump_ids, "clump_ids", [](Particle& p, std::int64_t x) { p.clump_id = x; });
  integer(material_ids, "material_ids", [](Particle& p, std::int64_t x) {
    if (x < 0 || x > std::numeric_limits<std::int32_t>::max())
      throw InputError("<arrays>", "material_ids must be in 0..2^31-1", std::to_string(x));
    p.material_id = static_cast<std::int32_t>(x);
  });
  if (!contact_ids.is_none()) {
    auto c =
        py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(contact_ids);
    if (!c || c.ndim() != 2 || c.shape(1) != 2)
      throw InputError("<arrays>", "contact_ids must be an (M, 2) array");
    const py::ssize_t m = c.shape(0);
    f.contacts.resize(static_cast<std::size_t>(m));
    for (py::ssize_t k = 0; k < m; ++k) {
      f.contacts[static_cast<std::size_t>(k)].id1 = c.at(k, 0);
      f.contacts[static_cast<std::size_t>(k)].id2 = c.at(k, 1);
    }
    const auto cvec = [&](py::object a, const char* name, Eigen::Vector3d Contact::*member) {
      if (a.is_none()) return;
      const auto v = rows(a, name, m, 3);
      for (py::ssize_t k = 0; k < m; ++k)
        f.contacts[static_cast<std::size_t>(k)].*member =
            Eigen::Vector3d(v.at(k, 0), v.at(k, 1), v.at(k, 2));
    };
    cvec(contact_points, "contact_points", &Contact::point);
    cvec(contact_normals, "contact_normals", &Contact::normal);
    cvec(normal_forces, "normal_forces", &Contact::normal_force);
    cvec(shear_forces, "shear_forces", &Contact::shear_force);
    if (!overlaps.is_none()) {
      const auto v = rows(overlaps, "overlaps", m, 0);
      for (py::ssize_t k = 0; k < m; ++k) f.contacts[static_cast<std::size_t>(k)].overlap = v.at(k);
    }
  } else {
    for (py::object a : {contact_points, contact_normals, normal_forces, shear_forces, overlaps})
      if (!a.is_none()) throw InputError("<arrays>", "contact fields given without contact_ids");
  }
  if (!f.particles.empty()) {
    Eigen::Vector3d lo = f.particles[0].position, hi = lo;
    for (const auto& p : f.particles) {
      lo = lo.cwiseMin(p.position - Eigen::Vector3d::Constant(p.radius));
      hi = hi.cwiseMax(p.position + Eigen::Vector3d::Constant(p.radius));
    }
    f.domain.lo = lo;
    f.domain.hi = hi;
  }
  validate_frame(f, "<arrays>");
  return f;
}

// A trajectory file: HDF5 read frame by frame, every other format at once.
struct PyTrajectory {
  std::string source;
  std::string format;
  std::shared_ptr<TrajectoryReader> reader;  // HDF5
  Trajectory loaded;                         // the other formats, or frames built in Python

  std::size_t size() const { return reader ? reader->frame_count() : loaded.frames.size(); }
  Frame frame(long i) const {
    const auto n = static_cast<long>(size());
    if (i < 0) i += n;
    if (i < 0 || i >= n) throw py::index_error("frame index out of range");
    if (reader) {
      py::gil_scoped_release release;
      return reader->frame(static_cast<std::size_t>(i));
    }
    return loaded.frames[static_cast<std::size_t>(i)];
  }
  const RunMetadata& metadata() const { return reader ? reader->metadata() : loaded.metadata; }
  Trajectory all() const {
    if (!reader) return loaded;
    Trajectory t;
    t.metadata = reader->metadata();
    for (std::size_t i = 0; i < reader->frame_count(); ++i) t.frames.push_back(reader->frame(i));
    return t;
  }
};

PyTrajectory open_file(const std::filesystem::path& path,
                       std::optional<std::filesystem::path> contacts, double dt,
                       std::optional<std::vector<std::string>> pair_columns) {
  PyTrajectory t;
  t.source = path.string();
  py::gil_scoped_release release;
  const SnapshotFormat fmt = detect_format(path);
  t.format = format_name(fmt);
  if (fmt == SnapshotFormat::Hdf5) {
    t.reader = std::make_shared<TrajectoryReader>(path);
    return t;
  }
  ImportOptions o;
  o.contacts = contacts;
  o.liggghts.dt = dt;
  if (pair_columns) o.liggghts.pair_columns = *pair_columns;
  t.loaded = read_snapshots(path, o);
  return t;
}

}  // namespace

void bind_data(py::module_& m) {
  py::class_<Frame>(m, "Frame", "One snapshot: particles, contacts, walls, clumps, domain (SI).")
      .def(py::init<>())
      .def_readwrite("time", &Frame::time, "s")
      .def_readwrite("step", &Frame::step)
      .def_readwrite("dt", &Frame::dt, "time step, s")
      .def_readwrite("two_d", &Frame::two_d, "2D (disks in the xy plane)")
      .def_property_readonly("n_particles", [](const Frame& f) { return f.particles.size(); })
      .def_property_readonly("n_contacts", [](const Frame& f) { return f.contacts.size(); })
      .def_property_readonly("n_walls", [](const Frame& f) { return f.walls.size(); })
      .def_property_readonly("n_clumps", [](const Frame& f) { return f.clumps.size(); })
      // particles
      .def_property_readonly("ids",
                             [](py::object s) {
                               return view<std::int64_t>(s, s.cast<Frame&>().particles,
                                                         &Particle::id, 0);
                             })
      .def_property_readonly(
          "positions",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().particles, &Particle::position, 3);
          },
          "(N, 3) m, a view")
      .def_property_readonly(
          "radii",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().particles, &Particle::radius, 0);
          },
          "(N,) m")
      .def_property_readonly(
          "velocities",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().particles, &Particle::velocity, 3);
          },
          "(N, 3) m/s")
      .def_property_readonly(
          "angular_velocities",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().particles, &Particle::angular_velocity, 3);
          },
          "(N, 3) rad/s")
      .def_property_readonly(
          "orientations_xyzw",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().particles, &Particle::orientation, 4);
          },
          "(N, 4) unit quaternions body -> lab in (x, y, z, w) order (scipy's from_quat order)")
      .def_property_readonly(
          "rotations",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().particles, &Particle::rotation, 3);
          },
          "(N, 3) cumulative rotation vectors, rad")
      .def_property_readonly(
          "masses",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().particles, &Particle::mass, 0);
          },
          "(N,) kg, 0 = unknown")
      .def_property_readonly(
          "clump_ids",
          [](py::object s) {
            return view<std::int64_t>(s, s.cast<Frame&>().particles, &Particle::clump_id, 0);
          },
          "(N,) -1 = not in a clump")
      .def_property_readonly("material_ids",
                             [](py::object s) {
                               return view<std::int32_t>(s, s.cast<Frame&>().particles,
                                                         &Particle::material_id, 0);
                             })
      // contacts
      .def_property_readonly(
          "contact_ids",
          [](py::object s) {
            return view<std::int64_t>(s, s.cast<Frame&>().contacts, &Contact::id1, 2);
          },
          "(M, 2) id1, id2: the normal points from id1 to id2, forces are those of id1 on id2")
      .def_property_readonly(
          "contact_points",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().contacts, &Contact::point, 3);
          },
          "(M, 3) m")
      .def_property_readonly("contact_normals",
                             [](py::object s) {
                               return view<double>(s, s.cast<Frame&>().contacts, &Contact::normal,
                                                   3);
                             })
      .def_property_readonly(
          "normal_forces",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().contacts, &Contact::normal_force, 3);
          },
          "(M, 3) N")
      .def_property_readonly(
          "shear_forces",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().contacts, &Contact::shear_force, 3);
          },
          "(M, 3) N")
      .def_property_readonly(
          "bending_moments",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().contacts, &Contact::bending_moment, 3);
          },
          "(M, 3) N m")
      .def_property_readonly(
          "twisting_moments",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().contacts, &Contact::twisting_moment, 3);
          },
          "(M, 3) N m")
      .def_property_readonly(
          "overlaps",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().contacts, &Contact::overlap, 0);
          },
          "(M,) m, > 0 when penetrating")
      // walls
      .def_property_readonly(
          "wall_ids",
          [](py::object s) { return view<std::int64_t>(s, s.cast<Frame&>().walls, &Wall::id, 0); })
      .def_property_readonly(
          "wall_kinds",
          [](py::object s) {
            return view<std::int32_t>(s, s.cast<Frame&>().walls, &Wall::kind, 0);
          },
          "0 plane (a point, b normal), 1 box (a centre, b half-extents), 2 facet")
      .def_property_readonly(
          "wall_a",
          [](py::object s) { return view<double>(s, s.cast<Frame&>().walls, &Wall::a, 3); })
      .def_property_readonly(
          "wall_b",
          [](py::object s) { return view<double>(s, s.cast<Frame&>().walls, &Wall::b, 3); })
      .def_property_readonly(
          "wall_forces",
          [](py::object s) { return view<double>(s, s.cast<Frame&>().walls, &Wall::force, 3); },
          "N")
      .def_property_readonly(
          "wall_torques",
          [](py::object s) { return view<double>(s, s.cast<Frame&>().walls, &Wall::torque, 3); },
          "N m")
      // clump bodies
      .def_property_readonly("clump_body_ids",
                             [](py::object s) {
                               return view<std::int64_t>(s, s.cast<Frame&>().clumps, &Clump::id, 0);
                             })
      .def_property_readonly(
          "clump_positions",
          [](py::object s) {
            return view<double>(s, s.cast<Frame&>().clumps, &Clump::position, 3);
          },
          "(K, 3) centres of mass, m")
      .def_property_readonly("clump_orientations_xyzw",
                             [](py::object s) {
                               return view<double>(s, s.cast<Frame&>().clumps, &Clump::orientation,
                                                   4);
                             })
      .def_property_readonly(
          "clump_masses",
          [](py::object s) { return view<double>(s, s.cast<Frame&>().clumps, &Clump::mass, 0); },
          "kg")
      // domain
      .def_property_readonly("domain_lo",
                             [](py::object s) { return eigen_view(s, s.cast<Frame&>().domain.lo); })
      .def_property_readonly("domain_hi",
                             [](py::object s) { return eigen_view(s, s.cast<Frame&>().domain.hi); })
      .def_property_readonly("periodic", [](const Frame& f) { return f.domain.periodic; })
      .def_property_readonly(
          "cell", [](py::object s) { return eigen_view(s, s.cast<Frame&>().domain.cell); },
          "(3, 3) periodic cell, columns = cell vectors, m")
      .def_property_readonly(
          "velocity_gradient",
          [](py::object s) { return eigen_view(s, s.cast<Frame&>().domain.velocity_gradient); },
          "(3, 3) 1/s")
      .def(
          "copy", [](const Frame& f) { return Frame(f); }, "An independent copy.")
      .def("__repr__",
           [](const Frame& f) {
             std::ostringstream s;
             s << "<granoscope.Frame t=" << f.time << " s, step " << f.step << ": "
               << f.particles.size() << " particles, " << f.contacts.size() << " contacts, "
               << f.walls.size() << " walls"
               << (f.clumps.empty() ? "" : ", " + std::to_string(f.clumps.size()) + " clumps")
               << (f.two_d ? ", 2D" : "") << (f.domain.periodic ? ", periodic" : "") << ">";
             return s.str();
           })
      .def_static("from_arrays", &frame_from_arrays, py::arg("positions"), py::arg("radii"),
                  py::kw_only(), py::arg("velocities") = py::none(),
                  py::arg("angular_velocities") = py::none(), py::arg("ids") = py::none(),
                  py::arg("masses") = py::none(), py::arg("clump_ids") = py::none(),
                  py::arg("material_ids") = py::none(), py::arg("contact_ids") = py::none(),
                  py::arg("contact_points") = py::none(), py::arg("contact_normals") = py::none(),
                  py::arg("normal_forces") = py::none(), py::arg("shear_forces") = py::none(),
                  py::arg("overlaps") = py::none(), py::arg("time") = 0.0, py::arg("step") = 0,
                  py::arg("dt") = 0.0, py::arg("two_d") = false);

  py::class_<PyTrajectory>(m, "Trajectory",
                           "Frames of one run (a file, or frames built in Python).")
      .def(py::init([](std::vector<Frame> frames) {
             PyTrajectory t;
             t.source = "<frames>";
             t.format = "in memory";
             t.loaded.metadata.code_version = code_version();
             t.loaded.metadata.provenance = "Python";
             t.loaded.frames = std::move(frames);
             return t;
           }),
           py::arg("frames"))
      .def("__len__", &PyTrajectory::size)
      .def("__getitem__", &PyTrajectory::frame, py::arg("index"))
      .def_readonly("source", &PyTrajectory::source)
      .def_readonly("format", &PyTrajectory::format)
      .def_property_readonly("times",
                             [](const PyTrajectory& t) {
                               std::vector<double> out(t.size());
                               for (std::size_t i = 0; i < out.size(); ++i)
                                 out[i] = t.reader ? t.reader->time(i) : t.loaded.frames[i].time;
                               return out;
                             })
      .def_property_readonly("code_version",
                             [](const PyTrajectory& t) { return t.metadata().code_version; })
      .def_property_readonly("provenance",
                             [](const PyTrajectory& t) { return t.metadata().provenance; })
      .def_property_readonly("parameters",
                             [](const PyTrajectory& t) { return t.metadata().parameters; })
      .def(
          "save",
          [](const PyTrajectory& t, const std::filesystem::path& path, long frame) {
            const Trajectory all = t.all();
            py::gil_scoped_release release;
            write_snapshots(path, all, frame);
          },
          py::arg("path"), py::arg("frame") = -1,
          "Writes .h5/.pvd (all frames) or .vtu/.csv (one frame, default the last).")
      .def("__repr__", [](const PyTrajectory& t) {
        return "<granoscope.Trajectory " + t.source + " (" + t.format +
               "): " + std::to_string(t.size()) + " frames>";
      });

  m.def("_open", &open_file, py::arg("path"), py::arg("contacts") = py::none(), py::arg("dt") = 0.0,
        py::arg("pair_columns") = py::none());
  m.def(
      "_save_frames",
      [](const std::filesystem::path& path, std::vector<Frame> frames, long frame) {
        Trajectory t;
        t.metadata.code_version = code_version();
        t.metadata.provenance = "Python";
        t.frames = std::move(frames);
        py::gil_scoped_release release;
        write_snapshots(path, t, frame);
      },
      py::arg("path"), py::arg("frames"), py::arg("frame") = -1);
  m.def("code_version", &code_version);
}

}  // namespace gs::py_bind
