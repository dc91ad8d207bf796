#!/usr/bin/env bash
# Peak memory of the streaming analysis on a 4 GiB recording (2^29 float64 samples, one channel):
# bench_streaming writes it to a temporary file block by block, then analyze_streaming reads it
# back block by block (Welch PSD + moments). Peak resident set sizes come from /usr/bin/time -v.
# The target is < 256 MB for the analysis. Not a CI test: it needs ~4.1 GB of disk and a minute
# or more. The file is deleted on exit, also on failure or Ctrl-C.
#
# Usage: bench/streaming_memory.sh [BUILD_DIR] [SAMPLES]   (default build-bench, 536870912)
set -euo pipefail
dir=${1:-build-bench}
samples=${2:-536870912}
exe="$dir/bench/bench_streaming"
[[ -x "$exe" ]] || { echo "streaming_memory: $exe not built" >&2; exit 2; }
tmpdir=${TMPDIR:-/tmp}
need_kb=$(( samples * 8 / 1024 + 1024 * 1024 ))  # the file + 1 GiB to spare
free_kb=$(df -Pk "$tmpdir" | awk 'NR == 2 { print $4 }')
if (( free_kb < need_kb )); then
  echo "streaming_memory: $tmpdir has $(( free_kb / 1024 )) MiB free, need $(( need_kb / 1024 )) MiB" >&2
  exit 2
fi
file="$tmpdir/geardiag_streaming_$$.h5"
trap 'rm -f "$file"' EXIT INT TERM
peak() { sed -n 's/^[[:space:]]*Maximum resident set size (kbytes): //p' "$1"; }
field() { sed -n "s/^[[:space:]]*$2: //p" "$1"; }
log=$(mktemp)
taskset -c 0 /usr/bin/time -v "$exe" --write "$file" --samples "$samples" 2> "$log"
echo "write:   peak RSS $(( $(peak "$log") / 1024 )) MiB, user $(field "$log" 'User time (seconds)') s," \
     "sys $(field "$log" 'System time (seconds)') s, file $(( $(stat -c %s "$file") / 1048576 )) MiB"
taskset -c 0 /usr/bin/time -v "$exe" --analyze "$file" 2> "$log"
rss_kb=$(peak "$log")
echo "analyse: peak RSS $(( rss_kb / 1024 )) MiB, user $(field "$log" 'User time (seconds)') s," \
     "sys $(field "$log" 'System time (seconds)') s, wall $(field "$log" 'Elapsed (wall clock) time (h:mm:ss or m:ss)')"
rm -f "$log"
if (( rss_kb * 1024 >= 256000000 )); then
  echo "streaming_memory: peak RSS $(( rss_kb * 1024 / 1000000 )) MB is over the 256 MB target" >&2
  exit 1
fi
