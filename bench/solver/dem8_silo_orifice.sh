# Sourced by the DEM8 Case 1 bench scripts: for ORIFICE (large, the default, or small) sets
# `scene` (the laptop scene under data/scenes), `z_orifice` (the orifice plane, m) and `walls`
# (the benchmark's wall mesh under $d8).
case ${ORIFICE:-large} in
  large) scene=dem8_silo_laptop; z_orifice=-0.0554222 ;;
  small) scene=dem8_silo_small_laptop; z_orifice=-0.0593008 ;;
  *) echo "ORIFICE: large or small"; exit 1 ;;
esac
walls=$d8/case1_silo/walls_${ORIFICE:-large}_orifice.txt
