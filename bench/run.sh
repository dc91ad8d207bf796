#!/usr/bin/env bash
# Runs the benchmarks of a Release build directory (default build-bench) on one core, then the
# scipy peers on the same core, so C++/scipy figures compare as ratios measured in one run.
# Google Benchmark's items_per_second is computed from CPU time; the peers report CPU time too.
# Results (Google Benchmark JSON, peer output) go to $dir/bench-results/.
# Set GEARDIAG_BENCH_BIG=1 to add the 4 GiB streaming peak-memory check (needs ~5 GB of /tmp).
set -euo pipefail
dir=${1:-build-bench}
here=$(cd "$(dirname "$0")" && pwd)
py=/usr/bin/python3
out="$dir/bench-results"
mkdir -p "$out"
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
cpu=$(lscpu 2>/dev/null | sed -n 's/^Model name:[[:space:]]*//p' | head -n1)
echo "machine: ${cpu:-unknown}, $(nproc --all) cores; $(date -u +%Y-%m-%d); load average: $(cut -d' ' -f1-3 /proc/loadavg)"
gb() {  # name, extra args...
  local name=$1
  shift
  taskset -c 0 "$dir/bench/bench_$name" --benchmark_out="$out/$name.json" \
    --benchmark_out_format=json "$@"
}
gb attribution --benchmark_min_time=1
gb resample
gb welch
taskset -c 0 "$py" "$here/peer_welch.py"
gb analysis
taskset -c 0 "$py" "$here/peer_analysis.py" --cpp-json "$out/analysis.json"
gb dynamics
taskset -c 0 "$dir/bench/bench_dynamics" --export "$out/pair_model.json" --span 0.01
taskset -c 0 "$py" "$here/peer_dynamics.py" "$out/pair_model.json" --json "$out/peer_dynamics.json"
gb streaming
if [[ "${GEARDIAG_BENCH_BIG:-0}" == 1 ]]; then
  "$here/streaming_memory.sh" "$dir"
fi
