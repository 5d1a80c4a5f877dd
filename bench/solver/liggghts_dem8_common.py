"""Shared by the LIGGGHTS inputs of the DEM8 benchmarks (liggghts_dem8_impact.py,
liggghts_dem8_silo.py): the benchmark's walls .txt (a header line, then 9 vertex coordinates per
triangle) as an ASCII STL, and the input up to the integrator: Hertz contacts with the
benchmark's steel (type 2) and grain material (type 1), the mesh as a granular wall, gravity."""
import os


def write_stl(walls_txt, path, name):
    """The triangles of the benchmark's walls .txt as an ASCII STL (normals left to LIGGGHTS)."""
    with open(walls_txt) as a, open(path, "w") as b:
        a.readline()
        b.write("solid %s\n" % name)
        for line in a:
            c = line.split()
            if len(c) != 9:
                continue
            b.write(" facet normal 0 0 0\n  outer loop\n")
            for k in range(3):
                b.write("   vertex %s %s %s\n" % tuple(c[3 * k:3 * k + 3]))
            b.write("  endloop\n endfacet\n")
        b.write("endsolid %s\n" % name)


def hertz_input_types(data_file, skin_m, dt_s, youngs_pa, restitution, friction, mesh_options=""):
    """The LIGGGHTS input up to `fix nve/sphere` for any number of atom types: the data file, the
    Verlet skin, the Hertz model with each type's Young's modulus (Poisson ratio 0.2 for all),
    the restitution and friction matrices (rows per type), the wall mesh walls.stl of the last
    type (steel; mesh_options appended to its `fix mesh/surface`), gravity along -z."""
    model = "model hertz tangential history"
    n = len(youngs_pa)
    row = lambda m: " ".join(str(x) for r in m for x in r)
    return f"""atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
hard_particles yes
read_data {data_file}
neighbor {skin_m} bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype {" ".join(str(y) for y in youngs_pa)}
fix m2 all property/global poissonsRatio peratomtype {" ".join(["0.2"] * n)}
fix m3 all property/global coefficientRestitution peratomtypepair {n} {row(restitution)}
fix m4 all property/global coefficientFriction peratomtypepair {n} {row(friction)}
pair_style gran {model}
pair_coeff * *
timestep {dt_s}
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix cad all mesh/surface file walls.stl type {n}{(" " + mesh_options) if mesh_options else ""}
fix walls all wall/gran {model} mesh n_meshes 1 meshes cad
"""


def hertz_input(data_file, skin_m, dt_s, young_grain_pa, en_grain, mu_grain, mesh_options=""):
    """hertz_input_types for the grains (type 1) and steel (type 2), and the integrator."""
    return hertz_input_types(data_file, skin_m, dt_s, [young_grain_pa, "2.1e11"],
                             [[en_grain, 0.4], [0.4, 0.4]], [[mu_grain, 0.2], [0.2, 0.2]],
                             mesh_options) + "fix integr all nve/sphere\n"
