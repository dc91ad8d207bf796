#!/usr/bin/env bash
# Runs the benchmarks of a Release build directory (default build-bench) on one core.
set -euo pipefail
dir=${1:-build-bench}
cpu=$(lscpu 2>/dev/null | sed -n 's/^Model name:[[:space:]]*//p' | head -n1)
echo "machine: ${cpu:-unknown}, $(nproc) cores; $(date -u +%Y-%m-%d)"
taskset -c 0 "$dir/bench/bench_attribution" --benchmark_min_time=1
