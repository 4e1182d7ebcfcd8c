#!/bin/bash
# list.sh [COPIES_DIR] [OTHERS_TSV]: the runs' list (NAME<TAB>FILE<TAB>BALL<TAB>COUNT) on stdout:
# the shared clips (ball preset and the bounces a person counts, from their README), their
# copies in COPIES_DIR (same preset and count), and the lines of OTHERS_TSV (clips of other
# repositories, NAME<TAB>FILE<TAB>BALL, no count: see README.md here).
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
set -u
HERE=$(cd "$(dirname "$0")" && pwd)
SHARED=${SHARED:-$HERE/../../../shared/real-clips}
COPIES=${1:-${REAL_RUNS_DIR:-/tmp/bouncefit-real-runs}/copies}
OTHERS=${2:-}
[ -f "$SHARED/README.md" ] || { echo "list: no $SHARED/README.md" >&2; exit 2; }
grep '^| [a-z_0-9]*\.\(avi\|mp4\|mov\) ' "$SHARED/README.md" | while IFS='|' read -r _ file _ _ _ count ball _; do
  file=$(echo "$file" | tr -d ' '); count=$(echo "$count" | tr -d ' '); ball=$(echo "$ball" | awk '{print $1}')
  n=${file%.*}
  printf '%s\t%s\t%s\t%s\n' "$n" "$SHARED/$file" "$ball" "$count"
  for p in shake0 crop8 s80 eq gam shake2 shake5; do
    [ -f "$COPIES/${p}_$n.mp4" ] && printf '%s\t%s\t%s\t%s\n' "${p}_$n" "$COPIES/${p}_$n.mp4" "$ball" "$count"
  done
done
if [ -n "$OTHERS" ]; then
  odir=$(cd "$(dirname "$OTHERS")" && pwd)
  grep -v '^#' "$OTHERS" | while IFS=$'\t' read -r n f b _; do
    [ -n "${n// }" ] || continue
    [[ "$f" = /* ]] || f="$odir/$f"
    printf '%s\t%s\t%s\t-\n' "$n" "$f" "$b"
  done
fi
