#!/usr/bin/env bash
# Time and peak memory of the million-point runs of issue 36
# (docs/performance.md, "Peak memory of a million points"): each command run
# once under `/usr/bin/time -v`, its output thrown away, its elapsed time and
# maximum resident set size printed as a table. Run it on a quiet machine
# (no build, no other job); it builds the `ci` binary first.
#
#   scripts/peak_memory.sh            # every run
#   scripts/peak_memory.sh map        # only the runs whose name contains `map`
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --profile ci --bin chain >&2
chain=target/ci/chain
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

# 10^6 instants of the gantry grinder along a raster path (x fastest).
python3 - "$scratch/gantry_1e6.csv" <<'EOF'
import sys
with open(sys.argv[1], "w") as f:
    f.write("t,x,y,z\n")
    k = 0
    for i in range(100):
        z = 600 + 800 * i / 99
        for j in range(100):
            y = -1500 + 3000 * j / 99
            for m in range(100):
                x = 1000 * m / 99
                f.write(f"{k * 0.001:.3f},{x!r},{y!r},{z!r}\n")
                k += 1
EOF

gantry=examples/machines/gantry_grinder.yaml
grid=(--grid x=0:1000:100 --grid y=-1500:1500:100 --grid z=600:1400:100)
runs=(
  "map-gantry-csv|$chain map $gantry --values examples/values/gantry_grinder.yaml ${grid[*]} --format csv"
  "map-gantry-json|$chain map $gantry --values examples/values/gantry_grinder.yaml ${grid[*]} --format json"
  "map-vmc3-csv|$chain map examples/machines/vmc3.yaml --values examples/values/vmc3.yaml --grid x=0:800:100 --grid y=0:500:100 --grid z=0:500:100 --format csv"
  "reliability-gantry-table|$chain reliability $gantry ${grid[*]}"
  "reliability-gantry-csv|$chain reliability $gantry ${grid[*]} --format csv"
  "reliability-gantry-json|$chain reliability $gantry ${grid[*]} --format json"
  "path-gantry-csv|$chain path $gantry --axes $scratch/gantry_1e6.csv --format csv"
  "path-gantry-json|$chain path $gantry --axes $scratch/gantry_1e6.csv --format json"
)

printf '%-26s %10s %14s\n' run seconds "peak (MB)"
for run in "${runs[@]}"; do
  name=${run%%|*}
  command=${run#*|}
  if [[ $# -gt 0 && $name != *"$1"* ]]; then
    continue
  fi
  # shellcheck disable=SC2086
  /usr/bin/time -v -o "$scratch/time" $command > /dev/null 2> "$scratch/stderr" || {
    echo "$name failed:" >&2
    cat "$scratch/stderr" >&2
    exit 1
  }
  seconds=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, p, ":"); s = 0; for (i = 1; i <= n; i++) s = s * 60 + p[i]; print s}' "$scratch/time")
  peak=$(awk -F': ' '/Maximum resident set size/ {printf "%.0f", $2 / 1024}' "$scratch/time")
  printf '%-26s %10s %14s\n' "$name" "$seconds" "$peak"
done
