#!/usr/bin/env bash
# The runs that wait for a GPU (docs/validation.md, "The GPU runs"): benchmarks of the 3D cases,
# `wgsph validate --full` case by case (the fluid–solid cases first), the 3D sloshing test and
# the street flood at their shipped dx. Each item runs under what is left of one time budget
# (and at most ITEM_CAP_S), so a short lease still returns every item that finished and the
# progress log of the one that did not; the summary marks each item's exit status (124: out of
# time), none is left out silently.
#
# Usage: tools/gpu_validation.sh WORK_DIR [BUDGET_S]
#   WGSPH             the engine (default target/release/wgsph; build it from this checkout)
#   VALIDATION_TESTS  the integration test binary, for the 3D sloshing test (built by
#                     `cargo test --release --test all --no-run`); skipped without it
#   ITEMS             the items to run, in order (default: all, as listed below)
#   ITEM_CAP_S        the most one item may take (default 300)
# Writes WORK_DIR/summary.txt (one line per item: name, exit status, seconds, then the
# validate report's judged rows), WORK_DIR/validate/report.md (every validate case that
# completed, judged together) and WORK_DIR/results.tar.gz (logs, reports, probe CSVs, plots,
# run files and every fifth snapshot of the 3D runs; no particle files). Unpacked elsewhere,
# `wgsph validate --full --reuse --out validate` judges those runs again without running them. Run from the repository root (the
# cases are read from cases/, the reference data from tests/data/).
set -uo pipefail

work=${1:?usage: tools/gpu_validation.sh WORK_DIR [BUDGET_S]}
budget=${2:-540}
wgsph=${WGSPH:-target/release/wgsph}
tests=${VALIDATION_TESTS:-}
cap=${ITEM_CAP_S:-300}
all="info validate:sfz_building_3d sfz_0.056 bench_spheric2 bench_spheric2_2h bench_spheric2_1M bench_spheric2_1M_2h bench_spheric2_4M bench_spheric2_13M bench_dam_break_3d bench_dam_break_3d_1M bench_street_flood_3d
validate:floating_box_2d validate:water_entry_cylinder_2d validate:water_entry_cylinder_2d_rho1000
validate:sloshing_2d validate:oscillating_plate_2d validate:oscillating_plate_tl_2d
validate:elastic_gate_2d sloshing_3d street_flood_3d street_flood_3d_open validate:dam_break_3d
spheric_0.04 spheric_0.0323529 spheric_0.025
validate:hydrostatic_2d validate:dam_break_2d validate:dam_break_lobovsky_2d mpi_np1 mpi_np2"
items=${ITEMS:-$all}

[ -x "$wgsph" ] || { echo "no engine at $wgsph: cargo build --release, or set WGSPH" >&2; exit 2; }
mkdir -p "$work"
summary="$work/summary.txt"
: >"$summary"
start=$(date +%s)

# The command of one item (run in $work/<item>/, log in $work/<item>.log).
command_of() {
    local item=$1 dir=$2
    case $item in
    info) echo "$wgsph info" ;;
    # DualSPHysics' performance case at its published sizes (docs/performance.md).
    bench_spheric2) echo "$wgsph bench cases/bench_spheric2.toml --steps 500 --stages" ;;
    bench_spheric2_1M) echo "$wgsph bench cases/bench_spheric2.toml --set particles.dx_m=0.0114 --steps 300" ;;
    # The same with cells of 2h, the default before 2026-12-05: what cells of h gain on a GPU.
    bench_spheric2_2h) echo "$wgsph bench cases/bench_spheric2.toml --set particles.cell=2h --steps 500 --stages" ;;
    bench_spheric2_1M_2h) echo "$wgsph bench cases/bench_spheric2.toml --set particles.dx_m=0.0114 --set particles.cell=2h --steps 300" ;;
    bench_spheric2_4M) echo "$wgsph bench cases/bench_spheric2.toml --set particles.dx_m=0.0072 --steps 200" ;;
    bench_spheric2_13M) echo "$wgsph bench cases/bench_spheric2.toml --set particles.dx_m=0.0042 --steps 100" ;;
    bench_dam_break_3d) echo "$wgsph bench cases/dam_break_3d.toml --steps 500 --stages" ;;
    # 1.05 M particles: bytes per particle and throughput at scale.
    bench_dam_break_3d_1M) echo "$wgsph bench cases/dam_break_3d.toml --set particles.dx_m=0.01 --steps 300" ;;
    bench_street_flood_3d) echo "$wgsph bench cases/street_flood_3d.toml --steps 500" ;;
    validate:*) echo "$wgsph validate --full --case ${item#validate:} --out $work/validate" ;;
    sloshing_3d)
        [ -n "$tests" ] || return 1
        echo "$tests --ignored --exact validation::sloshing::sloshing_3d_transducers_follow_the_experiment --nocapture"
        ;;
    # The street with and without its building to 10 s (docs/validation.md, "Street flood").
    street_flood_3d) echo "$wgsph run cases/street_flood_3d.toml --set time.end_s=10 --out $dir" ;;
    street_flood_3d_open) echo "$wgsph run cases/street_flood_3d.toml --set time.end_s=10 --set obstacle[3].enabled=false --set probe[5].enabled=false --out $dir" ;;
    # Soares-Frazão & Zech's building at a second dx (validate:sfz_building_3d runs dx = 0.04 m),
    # the flume cut as full mode cuts it (src/validation/sfz.rs), for the convergence of the
    # gauges' depths: `wgsph plot DIR --reference G1=tests/data/sfz_2007_building_G1_depth.csv …`.
    sfz_*) echo "$wgsph run cases/sfz_building_3d.toml --set particles.dx_m=${item#sfz_} --set time.end_s=13 --set time.probe_every_s=0.02 --set tank.max_m=[12.0,1.8,0.8] --set outlet[0].min_m=[11.7,-1.8,-0.1] --set outlet[0].max_m=[12.0,1.8,0.8] --out $dir" ;;
    # SPHERIC Test 2's 6 s at coarser dx, probes on the box's faces every 5 ms: with the
    # shipped dx (validate:dam_break_3d) the convergence study of docs/validation.md.
    spheric_*) echo "$wgsph run cases/dam_break_3d.toml --set particles.dx_m=${item#spheric_} --set time.probe_every_s=0.005 --set time.output_every_s=1 --out $dir" ;;
    # Issue 32: two ranks sharing the GPU against one rank, on the same 1 M particles
    # (docs/scaling.md); needs an engine built with --features mpi, and mpirun.
    mpi_np1 | mpi_np2)
        command -v mpirun >/dev/null && grep -q MPI_Init "$wgsph" || return 1
        echo "env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -np ${item#mpi_np} $wgsph bench cases/dam_break_3d.toml --set particles.dx_m=0.01 --steps 300"
        ;;
    *) return 1 ;;
    esac
}

for item in $items; do
    name=${item//:/_}
    dir="$work/$name"
    # validate's report.md holds the last case's rows: none left from the case before.
    [[ $item == validate:* ]] && dir="$work/validate" && rm -f "$dir/report.md"
    left=$((budget - ($(date +%s) - start)))
    if ! cmd=$(command_of "$item" "$dir"); then
        echo "$item: skipped (unknown item, or what it needs is missing: VALIDATION_TESTS, mpirun)" | tee -a "$summary"
        continue
    fi
    if [ "$left" -lt 20 ]; then
        echo "$item: not run (budget spent)" | tee -a "$summary"
        continue
    fi
    limit=$((left < cap ? left : cap))
    t0=$(date +%s)
    # SIGINT first: the engine stops at a step's end and keeps its outputs.
    timeout --signal=INT --kill-after=15 "$limit" $cmd >"$work/$name.log" 2>&1
    rc=$?
    echo "$item: exit $rc in $(($(date +%s) - t0)) s (limit $limit s)" | tee -a "$summary"
    # The report's rows (or, without a report, how far the run got), a bench's result.
    {
        if [ -f "$dir/report.md" ]; then
            grep -E '^- (adapter|result)|\| (PASS|FAIL|info) \|' "$dir/report.md"
        else
            grep -v XDG_RUNTIME_DIR "$work/$name.log" | tail -n 12
        fi
    } | sed 's/^/    /' >>"$summary"

done

# One report of every validate case whose run completed (evaluated again, not run: --reuse).
completed=()
for item in $items; do
    [[ $item == validate:* ]] &&
        grep -q '"status": "completed"' "$work/validate/${item#validate:}/run.json" 2>/dev/null &&
        completed+=(--case "${item#validate:}")
done
if [ ${#completed[@]} -gt 0 ]; then
    "$wgsph" validate --full --reuse --out "$work/validate" "${completed[@]}" >"$work/validate_all.log" 2>&1
    echo "validate, completed cases judged together: exit $? ($work/validate/report.md)" | tee -a "$summary"
fi

# Pictures of the 3D runs (the particle files stay here): every output drawn, every fifth in
# the archive (x–z slices through the middle, coloured by pressure).
for dir in "$work/validate/dam_break_3d" "$work/street_flood_3d"; do
    [ -f "$dir/run.json" ] && [ -d "$dir/particles" ] || continue
    "$wgsph" plot "$dir" --snapshots >>"$work/snapshots.log" 2>&1
    echo "snapshots of ${dir#"$work"/}: exit $?" | tee -a "$summary"
done

(cd "$work" && find . -name particles -prune -o -type f \( \
    \( -path '*/snapshots/*' -name '*[05].png' \) -o \( ! -path '*/snapshots/*' \( -name '*.log' \
    -o -name '*.md' -o -name '*.csv' -o -name '*.png' -o -name run.json -o -name summary.txt \) \) \
    \) -print | tar -czf results.tar.gz -T -)
echo "total $(($(date +%s) - start)) s; $work/summary.txt, $work/results.tar.gz ($(du -h "$work/results.tar.gz" | cut -f1))"
