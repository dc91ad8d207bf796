#!/usr/bin/env bash
# Peak memory and CPU of `geardiag analyze` (the whole command) on long recordings: 10 s of the
# two-stage box simulated at 20 kHz, 8 of its vibration channels and its input tacho tiled by
# bench/make_long_recording.py (block by block) into recordings of 0.25 GB and 1 GB of vibration
# samples, each analysed with /usr/bin/time -v. analyze examines every sample, frame by frame,
# each frame read by blocks (detect/analysis/analyze_file.hpp): peak RSS must be < 256 MB and the
# same at both lengths (flat in length), and `batch` of the 1 GB recording twice on two workers under
# the same bound; then a 1 GB CSV log of the same channels, read row by row
# (bench/make_long_csv.py). The frames note is printed.
# Not a CI test: it needs ~2.5 GB of disk and a few minutes. The files are deleted on exit, also
# on failure or Ctrl-C.
#
# Usage: bench/analyze_memory.sh [BUILD_DIR]   (default build)
set -euo pipefail
dir=${1:-build}
exe="$dir/geardiag"
[[ -x "$exe" ]] || { echo "analyze_memory: $exe not built" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
tmpdir=$(mktemp -d "${TMPDIR:-/tmp}/geardiag_analyze_memory.XXXXXX")
trap 'rm -rf "$tmpdir"' EXIT INT TERM
free_kb=$(df -Pk "$tmpdir" | awk 'NR == 2 { print $4 }')
if (( free_kb < 2 * 1024 * 1024 )); then
  echo "analyze_memory: $tmpdir has $(( free_kb / 1024 )) MiB free, need 2048 MiB" >&2
  exit 2
fi
peak() { sed -n 's/^[[:space:]]*Maximum resident set size (kbytes): //p' "$1"; }
field() { sed -n "s/^[[:space:]]*$2: //p" "$1"; }
# 1800 rpm: 10 s hold 300 whole input revolutions, so the tiled tacho runs on without a jump and
# the speed is steady in every frame.
"$exe" simulate --gearbox "$here/../testdata/gearbox/two_stage_17_44_21_50.json" --duration 10 \
  --fs 20000 --rpm 1800 -o "$tmpdir/short.h5" > /dev/null
log="$tmpdir/time.log"
status=0
# Runs `analyze` with the given arguments under /usr/bin/time -v; prints its peak RSS, CPU and
# frames (labelled $1) and sets status=1 over the 256 MB target.
measure() {
  local label=$1
  shift
  /usr/bin/time -v "$exe" analyze "$@" --json "$tmpdir/r.json" > /dev/null 2> "$log"
  local rss_kb
  rss_kb=$(peak "$log")
  echo "$label: peak RSS $(( rss_kb / 1024 )) MiB, user $(field "$log" 'User time (seconds)') s," \
       "sys $(field "$log" 'System time (seconds)') s;" \
       "$(grep -o 'long recording analysed in [0-9]* frames of [^)]*)' "$tmpdir/r.json")"
  if (( rss_kb * 1024 >= 256000000 )); then
    echo "analyze_memory: peak RSS $(( rss_kb * 1024 / 1000000 )) MB is over the 256 MB target" >&2
    status=1
  fi
}
for bytes in 2.5e8 1e9; do
  file="$tmpdir/long.h5"
  /usr/bin/python3 "$here/make_long_recording.py" "$tmpdir/short.h5" "$file" "$bytes"
  measure analyze "$file"
  if [[ $bytes == 1e9 ]]; then
    # `batch` of the 1 GB recording given twice, two workers: each reads its file frame by frame.
    /usr/bin/time -v "$exe" batch "$file" "$file" --jobs 2 -o "$tmpdir/table.csv" 2> "$log"
    rss_kb=$(peak "$log")
    echo "batch (2 x 1 GB, 2 workers): peak RSS $(( rss_kb / 1024 )) MiB," \
         "user $(field "$log" 'User time (seconds)') s, sys $(field "$log" 'System time (seconds)') s"
    if (( rss_kb * 1024 >= 256000000 )); then
      echo "analyze_memory: batch peak RSS $(( rss_kb * 1024 / 1000000 )) MB is over 256 MB" >&2
      status=1
    fi
  fi
  rm -f "$file"
done
# A 1 GB CSV log of the same channels (a time column, 7 significant digits, no tacho): read row
# by row, frame by frame (diag::open_recording_frames), not whole.
csv="$tmpdir/long.csv"
/usr/bin/python3 "$here/make_long_csv.py" "$tmpdir/short.h5" "$csv" 1e9
measure "analyze (CSV)" "$csv" --gearbox "$here/../testdata/gearbox/two_stage_17_44_21_50.json" \
  --rpm 1800
rm -f "$csv"
exit $status
