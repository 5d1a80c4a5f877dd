#!/bin/sh
# Writes tests/data/trajectory_v1.h5 with the schema_version 1 writer (commit ade4e67, before the
# clump bodies): two frames, three spheres (two of them members of clump 7, as imported data
# carry clump_id without bodies), one contact, one plane wall. Run from the repository root.
set -e
tmp=$(mktemp -d)
for f in hdf5_trajectory.hpp hdf5_trajectory.cpp snapshot.hpp snapshot.cpp errors.hpp; do
  git show ade4e67:io/$f >"$tmp/$f"
done
cat >"$tmp/main.cpp" <<'CPP'
#include "hdf5_trajectory.hpp"
int main(int, char** argv) {
  gs::Trajectory t;
  t.metadata.code_version = "granoscope 0.1.0";
  t.metadata.provenance = "schema_version 1 fixture";
  t.metadata.parameters = {{"scene", "v1"}};
  for (int k = 0; k < 2; ++k) {
    gs::Frame f;
    f.time = 0.5 * k;
    f.step = 1000 * k;
    f.dt = 1e-6;
    f.domain.hi = {0.01, 0.01, 0.01};
    for (int i = 0; i < 3; ++i) {
      gs::Particle p;
      p.id = i;
      p.position = {0.002 * i, 0.001 * k, 0.003};
      p.radius = 0.001;
      p.mass = 1e-5;
      p.clump_id = i < 2 ? 7 : -1;
      f.particles.push_back(p);
    }
    gs::Contact c;
    c.id1 = 1;
    c.id2 = 2;
    c.point = {0.003, 0.001 * k, 0.003};
    c.normal = {1, 0, 0};
    c.normal_force = {0.25, 0, 0};
    f.contacts.push_back(c);
    gs::Wall w;
    w.id = 3;
    f.walls.push_back(w);
    t.frames.push_back(f);
  }
  gs::write_hdf5_trajectory(argv[1], t);
}
CPP
g++ -std=c++20 -O1 -I"$tmp" -I/usr/include/eigen3 -I/usr/include/hdf5/serial \
  "$tmp"/main.cpp "$tmp"/hdf5_trajectory.cpp "$tmp"/snapshot.cpp -o "$tmp"/gen \
  -L/usr/lib/x86_64-linux-gnu/hdf5/serial -lhdf5
"$tmp"/gen tests/data/trajectory_v1.h5
rm -rf "$tmp"
