#!/bin/bash
# Runs the shipped cases (and a few variants) for a short time with two wgsph binaries and says
# whether their probe and particle files are byte-identical: the check that a refactor changed
# no result. Usage: tools/compare_outputs.sh OLD_BINARY NEW_BINARY [OUT_DIR]
set -u
OLD=$1 NEW=$2 OUT=${3:-/tmp/wgsph_compare}
cd "$(dirname "$0")/.."
rm -rf "$OUT"; mkdir -p "$OUT"
sed '/^alpha/d' cases/dam_break_2d.toml > "$OUT/laminar.toml"
status=0
run() { # name case-file end-time extra --set arguments...
  local name=$1 case=$2 end=$3; shift 3
  for v in old new; do
    local bin=$OLD; [ $v = new ] && bin=$NEW
    "$bin" run "$case" --out "$OUT/$v/$name" --quiet --checkpoint-every never \
      --set time.end_s=$end --set time.output_every_s=$end "$@" > "$OUT/$v-$name.log" 2>&1
  done
  local a b
  a=$(cd "$OUT/old/$name" 2>/dev/null && find probes particles -type f | sort | xargs md5sum | md5sum)
  b=$(cd "$OUT/new/$name" 2>/dev/null && find probes particles -type f | sort | xargs md5sum | md5sum)
  if [ -n "$a" ] && [ "$a" = "$b" ]; then echo "SAME $name"; else echo "DIFF $name (logs in $OUT)"; status=1; fi
}
for f in dam_break_2d hydrostatic_2d floating_box_2d water_entry_cylinder_2d oscillating_plate_2d \
         oscillating_plate_tl_2d water_injection_2d sloshing_2d dam_break_lobovsky_2d \
         free_overfall_2d broad_crested_weir_2d; do
  run $f cases/$f.toml 0.02
done
run elastic_gate_2d cases/elastic_gate_2d.toml 0.005
run energy cases/dam_break_2d.toml 0.05 --set physics.energy=true
run laminar "$OUT/laminar.toml" 0.05 --set physics.viscosity=laminar --set physics.nu_m2_s=1e-6
run mirror cases/dam_break_2d.toml 0.05 --set tank.wall=mirror
for f in dam_break_3d street_flood_3d street_flood_mesh_3d; do
  run $f cases/$f.toml 0.02 --set particles.dx_m=0.04
done
exit $status
