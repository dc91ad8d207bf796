#!/usr/bin/env bash
# Face-gear bifurcation benchmark: 200 speeds x 200 mesh periods after 300 transient
# periods, the seed's light-load case (12 N m, 10x stiffness, analytic default tables),
# 100..20000 rpm, on all cores. Prints wall and CPU time (the target: < 1 min wall on 2 cores).
# Usage: bench/face_gear_bifurcation.sh [BUILD_DIR]   (default build)
set -euo pipefail
dir=${1:-build}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo '{"stiffness_scale": 10}' >"$tmp/sc.json"
cpu=$(lscpu 2>/dev/null | sed -n 's/^Model name:[[:space:]]*//p' | head -n1)
echo "machine: ${cpu:-unknown}, $(nproc --all) cores; $(date -u +%Y-%m-%dT%H:%MZ); load average: $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/time -f "wall %e s, user %U s, sys %S s" "$dir/geardiag" bifurcation \
  --gearbox "$here/../testdata/gearbox/seed002_face_gear.json" --scenario "$tmp/sc.json" \
  --torque 12 --from-rpm 100 --to-rpm 20000 --steps 200 --periods 200 --transient 300 \
  --json "$tmp/b.json"
