# Sourced by the mesh benchmarks: writes the shared facet silo (../shared/reference/yade/facets,
# the parameters of its README) as a granoscope scene.
#   facet_silo_scene OUT.toml REF_DIR CONTACT STEPS HISTORY_EVERY [OUTLET_Z_M]
# CONTACT is "yade" or "merged"; with OUTLET_Z_M, spheres below it are removed.
facet_silo_scene() {
  local out=$1 ref=$2 contact=$3 steps=$4 every=$5 zlo=${6:-}
  cat > "$out" <<TOML
[scene]
name = "silo"
packing = "$ref/packing.csv"
[material]
young_Pa = 2.0e6
stiffness_ratio = 0.3
friction_deg = 18.0
density_kg_m3 = 2550.0
rolling_stiffness = 0.5
rolling_limit = 0.2
[solver]
dt_s = 1.43e-5
damping = 0.1
gravity_m_s2 = [0.0, 0.0, -9.81]
steps = $steps
max_overlap_ratio = 1.0
[output]
every = 100000000
history_every = $every
checkpoint_every = 100000000
[[mesh]]
file = "$ref/mesh.stl"
contact = "$contact"
TOML
  if [ -n "$zlo" ]; then
    printf '[outlet]\nkeep_lo_m = [-1.0, -1.0, %s]\nkeep_hi_m = [1.0, 1.0, 1.0]\n' "$zlo" >> "$out"
  fi
}
