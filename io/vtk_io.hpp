// ParaView output (XML VTK) and reading it back, plus YADE's VTK outputs.
//  - particles: .vtu, one vertex cell per sphere; point arrays id, radius, velocity,
//    angular_velocity, orientation (w,x,y,z), rotation, mass, clump_id, material_id; field data
//    TimeValue, step, dt, two_d, domain_lo, domain_hi, periodic, cell. Doubles stored exactly.
//  - contacts: .vtp, one line per contact from the centre of id1 to the centre of id2 (to the
//    contact point for a wall or unknown body); cell arrays id1, id2, point, normal,
//    normal_force, shear_force, fn_magnitude, bending_moment, twisting_moment, overlap.
//  - clump bodies: `<stem>_clumps.vtu` beside the particles (written when the frame has bodies),
//    one vertex cell per clump at its centre of mass; point arrays id, template (index into the
//    field-data string array template_names), velocity, angular_velocity, orientation (w,x,y,z),
//    mass, principal_inertia, axis_1..axis_3 (the principal axes in the lab frame = columns of
//    the orientation's rotation matrix, unit, for glyphs); field data TimeValue, template_names.
//    The members are the particles with clump_id = id, in the particles file.
//  - series: .pvd (ParaView collection) pointing at one .vtu (and one .vtp) per frame, and
//    `<stem>_clumps.pvd` over one clumps .vtu per frame when any frame has clump bodies.
#pragma once

#include <filesystem>
#include <vector>

#include "snapshot.hpp"

namespace gs {

void write_vtu_particles(const std::filesystem::path& path, const Frame& frame);
void write_vtp_contacts(const std::filesystem::path& path, const Frame& frame);
/// The clump bodies of the frame (none: a file with no points).
void write_vtu_clumps(const std::filesystem::path& path, const Frame& frame);
/// `<dir>/<stem>_clumps<ext>`: where the clump bodies of a particles .vtu / series .pvd go.
std::filesystem::path clumps_sibling(const std::filesystem::path& path);

/// Writes `<stem>.pvd` (particles) and `<stem>_contacts.pvd` (and `<stem>_clumps.pvd` when any
/// frame has clump bodies; a stale one is removed otherwise), with the per-frame files in the
/// directory `<stem>_files/`. All-or-nothing: everything is written under temporary names first.
void write_pvd_series(const std::filesystem::path& pvd_path, const Trajectory& trajectory);

/// Reads a particle .vtu: ours, or YADE VTKRecorder's 'spheres' output (radii, id, linVelVec,
/// angVelVec, clumpId, materialId; YADE writes positions as Float32).
Frame read_vtu_particles(const std::filesystem::path& path);
/// Reads our contact .vtp into frame.contacts.
void read_vtp_contacts(const std::filesystem::path& path, Frame& frame);
/// Reads our clumps .vtu into frame.clumps (and validates the frame: members and bodies agree).
void read_vtu_clumps(const std::filesystem::path& path, Frame& frame);
/// Reads a .pvd series written by write_pvd_series (contacts and clump bodies too when
/// `<stem>_contacts.pvd`, `<stem>_clumps.pvd` exist next to it).
Trajectory read_pvd_series(const std::filesystem::path& pvd_path);

/// YADE export.VTKExporter legacy ASCII files: spheres (point data radius, and id, linVel,
/// angVel when exported) and, optionally, interactions (cell data id1, id2 required; forceN,
/// forceT, normal, contactPoint, penetrationDepth used when present). When `intrs` is empty and
/// the spheres file is named `X-spheres-N.vtk`, `X-intrs-N.vtk` beside it is read if it exists.
Frame read_yade_legacy(const std::filesystem::path& spheres,
                       const std::filesystem::path& intrs = {});

}  // namespace gs
