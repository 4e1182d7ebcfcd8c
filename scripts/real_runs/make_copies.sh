#!/bin/bash
# make_copies.sh [DIR]: copies of every shared real clip as another camera, encoder or hand
# would give them (the harness's copies: docs/ACCURACY.md "Real clips"), into DIR (default
# $REAL_RUNS_DIR or /tmp/bouncefit-real-runs/copies):
#   shake0_  cropped 5 px each side, crf 18         crop8_  cropped 8 px each side
#   s80_     scaled to 0.8                          eq_     brighter, less contrast and colour
#   gam_     gamma 1.4, crf 23
#   shake2_, shake5_  hand-held: a jitter of A = 2 / 5 px a frame and a sway of S = 3 / 7 px
#            (a clip that stores each picture twice, 30 fps on a 60 fps timeline, loses its
#            repeats first: a hand moves the camera between pictures, not between two copies
#            of one; the copy keeps the frames' times)
# libx264 veryfast, frame times and sound kept. Needs ffmpeg (scripts/setup installs it).
# Existing copies are kept; the same ffmpeg on the same machine makes the same bytes.
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
set -u
HERE=$(cd "$(dirname "$0")" && pwd)
SHARED=${SHARED:-$HERE/../../../shared/real-clips}
OUT=${1:-${REAL_RUNS_DIR:-/tmp/bouncefit-real-runs}/copies}
command -v ffmpeg > /dev/null || { echo "make_copies: ffmpeg not found (bash scripts/setup installs it)" >&2; exit 2; }
[ -d "$SHARED" ] || { echo "make_copies: no $SHARED" >&2; exit 2; }
mkdir -p "$OUT"
common=(-c:v libx264 -preset veryfast -fps_mode passthrough -c:a copy -y -loglevel error)
copy() {  # name crf filter
  [ -s "$OUT/$1" ] || nice -n 10 ffmpeg -i "$clip" -vf "$3" -crf "$2" "${common[@]}" "$OUT/$1" ||
    echo "make_copies: ffmpeg failed on $1" >&2
}
# The clips that store most pictures twice (bouncefit run reports them as repeated frames).
REPEATS="pingpong_ruler_60fps.mov"
for clip in "$SHARED"/*.mp4 "$SHARED"/*.mov "$SHARED"/*.avi; do
  [ -f "$clip" ] || continue
  b=$(basename "$clip"); n=${b%.*}
  dedup=""; [[ " $REPEATS " == *" $b "* ]] && dedup="mpdecimate=hi=64*4:lo=64*2:frac=0.33,"
  copy "shake0_$n.mp4" 18 "crop=iw-10:ih-10:5:5"
  copy "crop8_$n.mp4" 20 "crop=iw-16:ih-16:8:8"
  copy "s80_$n.mp4" 20 "scale=trunc(iw*0.8/2)*2:trunc(ih*0.8/2)*2"
  copy "eq_$n.mp4" 20 "eq=brightness=0.06:contrast=0.85:saturation=0.8"
  copy "gam_$n.mp4" 23 "eq=gamma=1.4"
  for AS in "2 3" "5 7"; do
    set -- $AS; A=$1; S=$2; M=$((2 * (A + S) + 4))
    copy "shake${A}_$n.mp4" 20 "${dedup}crop=iw-$M:ih-$M:x='$M/2+$A*2*(random(0)-0.5)+$S*sin(2*PI*t*0.7)':y='$M/2+$A*2*(random(1)-0.5)+$S*cos(2*PI*t*0.7)'"
  done
  echo "copies of $n in $OUT"
done
