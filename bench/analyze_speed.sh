#!/usr/bin/env bash
# Speed of `geardiag analyze` (the whole command; docs/performance.md): CPU time (user + sys,
# /usr/bin/time) of `analyze --threads 1 --timing` and M samples/s per core = the samples of the
# analysed channels / CPU seconds, on
#   - ts10: 10 s of the two-stage box simulated at 20 kHz, 39 channels (7.8 M samples), and
#   - the CWRU files (IR007_0, normal_0), imported with `geardiag import` from ../shared/data
#     (skipped when the data are absent), with a one-shaft SKF 6205 description at 1797 rpm.
# Each input is run RUNS times (default 3) and the smallest CPU time is kept (the machine may be
# shared: the minimum is the least disturbed run). Prints per input: CPU, user, sys, page faults,
# peak RSS, M samples/s per core, and the per-stage wall times of the JSON's timing_s.
#
# Usage: bench/analyze_speed.sh [BUILD_DIR] [RUNS]   (default build, 3)
set -euo pipefail
dir=${1:-build}
runs=${2:-3}
exe="$dir/geardiag"
[[ -x "$exe" ]] || { echo "analyze_speed: $exe not built" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
data="$here/../../shared/data/cwru-bearing"
py=/usr/bin/python3
tmpdir=$(mktemp -d "${TMPDIR:-/tmp}/geardiag_analyze_speed.XXXXXX")
trap 'rm -rf "$tmpdir"' EXIT INT TERM
echo "machine: $(nproc --all) cores; $(date -u '+%Y-%m-%d %H:%M UTC'); load average: $(cut -d' ' -f1-3 /proc/loadavg)"
"$exe" simulate --gearbox "$here/../testdata/gearbox/two_stage_17_44_21_50.json" --duration 10 \
  -o "$tmpdir/ts10.h5" > /dev/null
inputs=("ts10:$tmpdir/ts10.h5:")
cat > "$tmpdir/cwru.json" << 'EOF'
{"name": "cwru", "shafts": [{"name": "input"}], "input": {"shaft": "input", "speed_rpm": 1797},
 "bearings": [{"name": "drive_end", "shaft": "input", "rolling_elements": 9, "pitch_diameter_mm": 39.04, "element_diameter_mm": 7.94, "contact_angle_deg": 0.0}]}
EOF
for f_fs in IR007_0:12000 normal_0:48000; do  # the files' sampling rates (CWRU's README)
  f=${f_fs%:*}
  if [[ -f "$data/$f.mat" ]]; then
    "$exe" import "$data/$f.mat" --fs "${f_fs#*:}" -o "$tmpdir/$f.h5" > /dev/null
    inputs+=("$f:$tmpdir/$f.h5:--gearbox $tmpdir/cwru.json")
  else
    echo "$f: skipped ($data/$f.mat absent)"
  fi
done
for spec in "${inputs[@]}"; do
  IFS=: read -r name file extra <<< "$spec"
  best=""
  for ((r = 0; r < runs; ++r)); do
    # shellcheck disable=SC2086
    /usr/bin/time -f "%U %S %F %R %M" -o "$tmpdir/time" "$exe" analyze "$file" $extra \
      --threads 1 --timing --json "$tmpdir/$name.json" > /dev/null
    line=$(cat "$tmpdir/time")
    cpu=$(awk '{ print $1 + $2 }' <<< "$line")
    if [[ -z "$best" ]] || awk -v a="$cpu" -v b="$(awk '{ print $1 + $2 }' <<< "$best")" \
      'BEGIN { exit !(a < b) }'; then
      best=$line
    fi
  done
  "$py" - "$tmpdir/$name.json" "$name" $best << 'EOF'
import json, sys
report, name = json.load(open(sys.argv[1])), sys.argv[2]
user, sys_s, major, minor, rss_kb = map(float, sys.argv[3:8])
samples = sum(c.get("samples", 0) for c in report.get("channels", []))
cpu = user + sys_s
print(f"{name}: {samples / 1e6:.2f} M samples, CPU {cpu:.2f} s (user {user:.2f}, sys {sys_s:.2f}), "
      f"{int(major + minor)} page faults, peak RSS {rss_kb / 1024:.0f} MiB: "
      f"{samples / 1e6 / cpu:.2f} M samples/s per core")
timing = report.get("timing_s", {})
print("  timing_s: " + ", ".join(f"{k} {v:.3f}" for k, v in timing.items()))
EOF
done
