#!/usr/bin/env bash
# bench_mpi.sh — MPI scaling (docs/performance.md §11): the same render on 1, 2 and 3
# ranks of `--threads T` each, alternated over R rounds; prints per rank count the wall
# time of mpirun (median), the render time rank 0 reports, each rank's rays/s while busy
# and its share of the tiles, and checks every image is byte-identical to the 1-rank one.
#   bench/bench_mpi.sh [BUILD_DIR] [SCENE] [extra valo render options...]
# Ranks are not bound to cores (--bind-to none; OpenMPI binds each to one core by default,
# which leaves a rank of several threads on one core).
# Environment: RANKS (default "1 2 3"), ROUNDS (3), THREADS (1), SPP (64), RES (320x240).
set -euo pipefail
build=${1:-build}
scene=${2:-scenes/default.json}
shift $(( $# > 2 ? 2 : $# )) || true
ranks=${RANKS:-1 2 3}
rounds=${ROUNDS:-3}
threads=${THREADS:-1}
spp=${SPP:-64}
res=${RES:-320x240}
valo="$(cd "$build" && pwd)/valo"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
echo "bench_mpi: $scene, $res, $spp spp, $threads thread(s) per rank, $rounds rounds, $(nproc) cores, $(date -u +%F)"
for round in $(seq "$rounds"); do
  for n in $ranks; do
    t0=$(date +%s.%N)
    mpirun --oversubscribe --bind-to none -n "$n" "$valo" render "$scene" --res "$res" --spp "$spp" --threads "$threads" -q "$@" \
      -o "$tmp/r$n.exr" --stats-json "$tmp/r$n-$round.json"
    t1=$(date +%s.%N)
    echo "$n $(echo "$t1 - $t0" | bc)" >> "$tmp/wall"
    if [ "$n" != "$(echo $ranks | cut -d' ' -f1)" ] && ! cmp -s "$tmp/r$n.exr" "$tmp/r$(echo $ranks | cut -d' ' -f1).exr"; then
      echo "bench_mpi: $n ranks gave another image" >&2
      exit 1
    fi
  done
done
printf "%-6s %-10s %-10s %-9s %s\n" ranks "wall s" "render s" speedup "per rank: Mrays/s busy, tiles"
base=""
for n in $ranks; do
  wall=$(awk -v n="$n" '$1 == n {print $2}' "$tmp/wall" | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
  render=$(for r in $(seq "$rounds"); do grep -o '"render_seconds": [0-9.]*' "$tmp/r$n-$r.json" | cut -d' ' -f2; done | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
  [ -z "$base" ] && base=$render
  per=$( (grep -o '"tiles": [0-9]*' "$tmp/r$n-$rounds.json" || true) | cut -d' ' -f2 | tr '\n' ' ')
  rps=$( (grep -o '"busy_seconds": [0-9.]*, "rays_per_second": [0-9.e+]*' "$tmp/r$n-$rounds.json" || true) | awk '{printf "%.2f ", $4 / 1e6}')
  [ -z "$rps" ] && rps=$(grep -o '"rays_per_second": [0-9.e+]*' "$tmp/r$n-$rounds.json" | head -1 | awk '{printf "%.2f ", $2 / 1e6}') && per="all"
  printf "%-6s %-10.2f %-10.2f %-9.2f Mrays/s: %s tiles: %s\n" "$n" "$wall" "$render" "$(echo "$base / $render" | bc -l)" "$rps" "$per"
done
echo "bench_mpi: every image byte-identical to the $(echo $ranks | cut -d' ' -f1)-rank one"
