#!/bin/bash
# compare.sh OUTA OUTB: for every run in either directory (run.sh's output), whether track.csv
# and peaks.csv are byte-identical; the peaks.csv diff of those that are not. Exit 1 if any differ.
set -u
[ $# -eq 2 ] || { echo "usage: $0 OUTA OUTB" >&2; exit 2; }
A=$1; B=$2
names=$( { (cd "$A" && ls -1 *.log 2>/dev/null); (cd "$B" && ls -1 *.log 2>/dev/null); } | sed 's/\.log$//' | sort -u)
same=0; differ=0; diffs=()
state() {
  if [ ! -f "$1" ] && [ ! -f "$2" ]; then echo absent
  elif [ ! -f "$1" ]; then echo only-B
  elif [ ! -f "$2" ]; then echo only-A
  elif cmp -s "$1" "$2"; then echo same
  else echo DIFF; fi
}
for n in $names; do
  t=$(state "$A/$n/track.csv" "$B/$n/track.csv"); p=$(state "$A/$n/peaks.csv" "$B/$n/peaks.csv")
  printf '%-48s track %-7s peaks %s\n' "$n" "$t" "$p"
  if [ "$t" = same ] && [ "$p" = same ]; then same=$((same + 1)); else differ=$((differ + 1)); fi
  [ "$p" = same ] || diffs+=("$n")
done
echo "identical (track and peaks): $same; different: $differ"
for n in "${diffs[@]}"; do
  echo; echo "=== $n: peaks.csv"
  diff -u --label "A/$n" --label "B/$n" "$A/$n/peaks.csv" "$B/$n/peaks.csv" 2>&1
done
exit $(( differ > 0 ? 1 : 0 ))
