#!/bin/bash
# run.sh BIN OUTDIR LIST: `BIN run CLIP --ball B --no-fit --no-audio --speed 0` on every line of
# LIST (list.sh's output), one after the other under nice, each into OUTDIR/NAME with its
# output in OUTDIR/NAME.log; then one line per run: name, rows of peaks.csv, bounce:height_m.
# Environment: LCM_URL (memq://: each run's bus stays in its process; another bouncefit on the
# machine would hear the default UDP multicast), ONLY (a regex on the names to run).
set -u
[ $# -eq 3 ] || { echo "usage: $0 BIN OUTDIR LIST" >&2; exit 2; }
BIN=$(readlink -f "$1"); OUT=$2; LIST=$3
LCM_URL=${LCM_URL:-memq://}; ONLY=${ONLY:-}
[ -x "$BIN" ] || { echo "run: no executable $BIN" >&2; exit 2; }
mkdir -p "$OUT"
: > "$OUT/times.tsv"
while IFS=$'\t' read -r name file ball _; do
  [[ -z "${name// }" || "$name" == \#* ]] && continue
  [[ -n "$ONLY" && ! "$name" =~ $ONLY ]] && continue
  rm -rf "${OUT:?}/$name"
  t0=$(date +%s.%N)
  nice -n 10 "$BIN" run "$file" --ball "$ball" --no-fit --no-audio --speed 0 --lcm-url "$LCM_URL" \
    --out "$OUT/$name" > "$OUT/$name.log" 2>&1 < /dev/null
  rc=$?
  printf '%s\t%s\t%s\t%.2f\n' "$name" "$ball" "$rc" "$(echo "$(date +%s.%N) - $t0" | bc)" >> "$OUT/times.tsv"
  p="$OUT/$name/peaks.csv"
  if [ -f "$p" ]; then
    hs=$(awk -F, 'NR==1 {for (i=1;i<=NF;i++) {if ($i=="height_m") h=i; if ($i=="bounce") b=i}; next}
                  {printf "%s%s:%.3f", (NR>2?" ":""), $b, $h}' "$p")
    printf '%-48s %3d  %s%s\n' "$name" "$(($(wc -l < "$p") - 1))" "$hs" "$([ "$rc" = 0 ] || echo "  (exit $rc)")"
  else
    printf '%-48s   -  (no peaks.csv, exit %s)\n' "$name" "$rc"
  fi
done < "$LIST" | tee "$OUT/summary.txt"
