#!/usr/bin/env bash
# Dataset generation throughput (bench/RESULTS.md): bench/dataset/spec.json (12 recordings of 1 s at
# 20 kHz, three_shaft) on 1 and 2 threads and under mpirun -np 2, wall and CPU time and peak
# memory (GNU time); then peak memory for 2 and 8 recordings per class (flat in the count).
# Usage: bench/dataset/run.sh BUILD_DIR OUT_DIR
set -euo pipefail
bin="$(realpath "$1")/geardiag"; out="$2"; here="$(dirname "$(realpath "$0")")"
mkdir -p "$out"
root=(); [ "$(id -u)" -eq 0 ] && root=(--allow-run-as-root)
run() {  # name, command...
  local name=$1; shift
  rm -rf "$out/$name"
  /usr/bin/time -f "$name wall_s=%e user_s=%U sys_s=%S max_rss_kb=%M" "$@" -o "$out/$name" \
    > "$out/$name.log" 2>> "$out/times.txt"
  echo "$name load: $(cut -d" " -f1-3 /proc/loadavg)" >> "$out/times.txt"
}
: > "$out/times.txt"
run jobs1 "$bin" dataset "$here/spec.json" --jobs 1
run jobs2 "$bin" dataset "$here/spec.json" --jobs 2
run mpi2 mpirun "${root[@]}" --oversubscribe -np 2 "$bin" dataset "$here/spec.json" --jobs 1
for n in 2 8; do
  sed "s/\"recordings_per_class\": 4/\"recordings_per_class\": $n/" "$here/spec.json" \
    > "$out/spec_$n.json"
  sed -i "s|\"../../testdata|\"$(realpath "$here/../../testdata")|" "$out/spec_$n.json"
  run "mem$n" "$bin" dataset "$out/spec_$n.json" --jobs 1
done
for d in jobs2 mpi2; do
  diff -r -x .lock "$out/jobs1" "$out/$d" > /dev/null && echo "$d identical to jobs1" >> "$out/times.txt"
done
cat "$out/times.txt"
