#!/usr/bin/env bash
# bench_accel.sh — whole renders on the kd-tree against Embree 3 (docs/performance.md §1):
# the same `valo render` with `--accel kdtree` and `--accel embree`, alternated over R
# rounds, best of each; prints per scene the build and render seconds of both and the
# speed ratios kd/Embree (Embree's time over the kd-tree's) of the build, the render and
# the whole run (load + build + render).
#   bench/bench_accel.sh [BUILD_DIR] [SCENE ...]
# Default scenes: bench/cornell-bunny.json, bench/cornell-dragon.json, bench/sponza-sun.json
# (they read ../shared). Environment: ROUNDS (3), THREADS (2), SPP (32), RES (256x256).
set -euo pipefail
build=${1:-build}
shift $(( $# > 0 ? 1 : 0 )) || true
here=$(cd "$(dirname "$0")" && pwd)
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=("$here/cornell-bunny.json" "$here/cornell-dragon.json" "$here/sponza-sun.json")
rounds=${ROUNDS:-3}
threads=${THREADS:-2}
spp=${SPP:-32}
res=${RES:-256x256}
valo="$(cd "$build" && pwd)/valo"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
field() { sed -n "s/.*\"$1\": \([0-9.e+-]*\).*/\1/p" "$2"; }
echo "bench_accel: $res, $spp spp, $threads threads, $rounds rounds, $(nproc) cores, $(date -u +%F)"
echo
echo "| scene | triangles | kd build s | Embree build s | kd render s | Embree render s | kd/Embree build | kd/Embree render | kd/Embree whole run |"
echo "|---|---|---|---|---|---|---|---|---|"
for scene in "${scenes[@]}"; do
  declare -A best=()
  for round in $(seq "$rounds"); do
    for accel in kdtree embree; do
      "$valo" render "$scene" --accel "$accel" --res "$res" --spp "$spp" --threads "$threads" -q -o "$tmp/$accel.exr" \
        --stats-json "$tmp/$accel.json" 2>"$tmp/err" || { cat "$tmp/err" >&2; exit 1; }
      for f in load_seconds build_seconds render_seconds; do
        v=$(field "$f" "$tmp/$accel.json")
        k="$accel.$f"
        if [ -z "${best[$k]:-}" ] || [ "$(echo "$v < ${best[$k]}" | bc -l)" = 1 ]; then best[$k]=$v; fi
      done
      tris=$(field triangles "$tmp/$accel.json")
    done
  done
  kb=${best[kdtree.build_seconds]}; eb=${best[embree.build_seconds]}
  kr=${best[kdtree.render_seconds]}; er=${best[embree.render_seconds]}
  kw=$(echo "${best[kdtree.load_seconds]} + $kb + $kr" | bc -l); ew=$(echo "${best[embree.load_seconds]} + $eb + $er" | bc -l)
  printf "| %s | %s | %.3f | %.3f | %.2f | %.2f | %.2f | %.2f | %.2f |\n" "$(basename "$scene" .json)" "$tris" "$kb" "$eb" "$kr" "$er" \
    "$(echo "$eb / $kb" | bc -l)" "$(echo "$er / $kr" | bc -l)" "$(echo "$ew / $kw" | bc -l)"
  unset best
done
