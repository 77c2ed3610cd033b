#!/usr/bin/env bash
# bench_batch.sh — path's wavefront against one path at a time (docs/performance.md §14):
# the same `valo render` with `--batch 1` and each other batch size, alternated over R
# rounds, best render time of each; prints per scene the render seconds and the speed of
# each batch size over `--batch 1` (above 1: the batch is faster), and whether its image
# is byte for byte `--batch 1`'s.
#   bench/bench_batch.sh [BUILD_DIR] [SCENE ...]
# Default scenes: bench/cornell-bunny.json, bench/sponza-sun.json, Veach's MIS file, and
# four material scenes of tests/data/materials (they read ../shared). Environment: ROUNDS
# (3), THREADS (2), SPP (32), RES (256x256; a Mitsuba file keeps its own), BATCHES
# ("64 256 1024"), ACCEL (the default).
set -euo pipefail
build=${1:-build}
shift $(( $# > 0 ? 1 : 0 )) || true
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=("$here/cornell-bunny.json" "$here/sponza-sun.json" "$root/../shared/scenes/veach-mis/mitsuba-source/scene.xml"
  "$root/tests/data/mitsuba-xml/spot-falloff.xml" "$root/tests/data/materials/gold-rough.xml" "$root/tests/data/materials/glass-rough.xml"
  "$root/tests/data/materials/env-spheres.xml")
rounds=${ROUNDS:-3}
threads=${THREADS:-2}
spp=${SPP:-32}
res=${RES:-256x256}
read -r -a batches <<< "${BATCHES:-64 256 1024}"
accel=()
[ -z "${ACCEL:-}" ] || accel=(--accel "$ACCEL")
valo="$(cd "$build" && pwd)/valo"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
field() { sed -n "s/.*\"$1\": \"\{0,1\}\([0-9a-z.e+-]*\).*/\1/p" "$2"; }
echo "bench_batch: $spp spp, $threads threads, $rounds rounds, $(nproc) cores, $(date -u +%F)"
echo
head="| scene | accel | batch 1 render s |"; sep="|---|---|---|"
for b in "${batches[@]}"; do head="$head batch $b s | speed | same bytes |"; sep="$sep---|---|---|"; done
echo "$head"; echo "$sep"
for scene in "${scenes[@]}"; do
  extra=()
  case "$scene" in
    *.xml) extra=(-D integrator=path) ;;
    *) extra=(--res "$res") ;;
  esac
  declare -A best=()
  for round in $(seq "$rounds"); do
    for b in 1 "${batches[@]}"; do
      "$valo" render "$scene" "${extra[@]}" "${accel[@]}" --batch "$b" --spp "$spp" --threads "$threads" -q -o "$tmp/$b.exr" \
        --stats-json "$tmp/$b.json" 2>"$tmp/err" || { cat "$tmp/err" >&2; exit 1; }
      v=$(field render_seconds "$tmp/$b.json")
      if [ -z "${best[$b]:-}" ] || [ "$(echo "$v < ${best[$b]}" | bc -l)" = 1 ]; then best[$b]=$v; fi
    done
  done
  line="| $(basename "$(dirname "$scene")")/$(basename "$scene") | $(field accel "$tmp/1.json") | ${best[1]} |"
  for b in "${batches[@]}"; do
    same=no; cmp -s "$tmp/1.exr" "$tmp/$b.exr" && same=yes
    line="$line ${best[$b]} | $(printf %.2f "$(echo "${best[1]} / ${best[$b]}" | bc -l)") | $same |"
  done
  echo "$line"
  unset best
done
