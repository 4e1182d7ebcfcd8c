#!/bin/bash
# track_bench_ab.sh A_BENCH B_BENCH [CLIP...]: two builds' track_bench run interleaved, A then B,
# twice per clip (the shared real clips by default), each `--repeats 5`; one line per run:
# clip, which build, the decode + track / decode alone wall ratio (median of 5 pairs), tracking
# alone and tracking inside decode + track (us a frame), and the busy-core floor.
# Why interleaved: a single before/after pair swings 0.05-0.1 on this shared machine, more than
# most changes to the tracker move the ratio (docs/PERFORMANCE.md).
# A build of the base commit: git worktree add /tmp/base COMMIT; cmake -S /tmp/base -B
# /tmp/base/build; cmake --build /tmp/base/build --target track_bench.
set -u
usage() { sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; }
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then usage; exit 0; fi
if [ $# -lt 2 ]; then usage >&2; exit 2; fi
A=$1; B=$2; shift 2
for bin in "$A" "$B"; do
  [ -x "$bin" ] || { echo "track_bench_ab: no executable $bin" >&2; exit 2; }
done
clips=("$@")
if [ ${#clips[@]} -eq 0 ]; then
  dir=$(dirname "$(readlink -f "$0")")/../../shared/real-clips
  clips=("$dir"/*.avi "$dir"/*.mp4 "$dir"/*.mov)
fi
for clip in "${clips[@]}"; do
  [ -f "$clip" ] || { echo "track_bench_ab: no clip $clip" >&2; exit 2; }
  for round in 1 2; do
    for side in A B; do
      bin=$A; [ $side = B ] && bin=$B
      out=$("$bin" --clip "$clip" --repeats 5 2>&1) || { echo "track_bench_ab: $bin failed on $clip" >&2; exit 1; }
      ratio=$(echo "$out" | sed -n 's/^decode+track \/ decode alone: .* CPU time, \([0-9.]*\) wall time, median.*/\1/p')
      alone=$(echo "$out" | sed -n 's/^tracking alone, BGR .*( *\([0-9.]*\) us\/frame).*/\1/p')
      inside=$(echo "$out" | sed -n 's/^pass .*tracking within it \([0-9.]*\) us\/frame.*/\1/p' | sort -n | sed -n 3p)
      floor=$(echo "$out" | sed -n 's/^decode alone beside busy cores .* decode alone: \([0-9.]*\) wall time.*/\1/p')
      printf '%-42s %s round %d  ratio %-6s  tracking alone %-7s inside %-7s us/frame  busy-core floor %s\n' \
        "$(basename "$clip")" "$side" "$round" "${ratio:--}" "${alone:--}" "${inside:--}" "${floor:--}"
    done
  done
done
