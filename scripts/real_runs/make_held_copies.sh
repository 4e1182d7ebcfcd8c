#!/bin/bash
# make_held_copies.sh [DIR]: copies of the shared clips filmed by a still camera, moved as a
# hand would move it by a known amount every frame, with that amount beside each copy, to
# measure the tracker's camera motion (track/camera_motion.h) against the truth:
#   heldA_NAME.mp4        cropped by a window that jitters A px (A = 2, 5) and sways 3 / 7 px
#   heldA_NAME.truth.csv  t_s,camera_dx_px,camera_dy_px: how far the picture moved since the
#                         first frame (what the first frame showed at p is now at p + d)
# Unlike make_copies.sh's shake copies (ffmpeg's random(), even pixels), the window's place is
# a formula of the frame number, whole pixels (crop's exact=1): the truth is computed here.
# A clip that stores most pictures twice (30 fps on a 60 fps timeline) loses its repeats first
# (a hand moves the camera between pictures, not between two copies of one); the frames keep
# their times.
# Then: scripts/real_runs/camera_truth.py DIR/heldA_NAME.truth.csv OUT/heldA_NAME/track.csv
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
set -u
HERE=$(cd "$(dirname "$0")" && pwd)
SHARED=${SHARED:-$HERE/../../../shared/real-clips}
OUT=${1:-${REAL_RUNS_DIR:-/tmp/bouncefit-real-runs}/held}
command -v ffmpeg > /dev/null || { echo "make_held_copies: ffmpeg not found (bash scripts/setup installs it)" >&2; exit 2; }
mkdir -p "$OUT"
# The clips whose camera stands still (the others move on their own: their truth is unknown).
STILL="tennis_ruler_25fps.mp4 basketball_tile_ochre_24fps.mp4
       green_ball_poster_30fps.avi pingpong_ruler_60fps.mov"
REPEATS="pingpong_ruler_60fps.mov"  # bouncefit run reports their repeated frames
for b in $STILL; do
  clip="$SHARED/$b"; n=${b%.*}
  dedup=""; [[ " $REPEATS " == *" $b "* ]] && dedup="mpdecimate=hi=64*4:lo=64*2:frac=0.33,"
  [ -f "$clip" ] || { echo "make_held_copies: no $clip" >&2; continue; }
  for AS in "2 3" "5 7"; do
    set -- $AS; A=$1; S=$2; M=$((2 * (A + S) + 4))
    # x(n), y(n): the crop window's corner in frame n (whole pixels, rounded as crop does).
    X="$M/2+$A*sin(n*2.39996)+$S*sin(n*0.17593)"
    Y="$M/2+$A*sin(n*1.71+1)+$S*cos(n*0.17593)"
    name="held${A}_$n"
    [ -s "$OUT/$name.mp4" ] || nice -n 10 ffmpeg -i "$clip" -vf "${dedup}crop=iw-$M:ih-$M:x='$X':y='$Y':exact=1" \
      -c:v libx264 -preset veryfast -crf 20 -fps_mode passthrough -c:a copy -y -loglevel error "$OUT/$name.mp4" ||
      { echo "make_held_copies: ffmpeg failed on $name" >&2; continue; }
    ffprobe -v error -select_streams v:0 -show_entries frame=best_effort_timestamp_time -of csv=p=0 "$OUT/$name.mp4" |
      python3 -c "
import math, sys
M, A, S = $M, $A, $S
x = lambda n: round(M / 2 + A * math.sin(n * 2.39996) + S * math.sin(n * 0.17593))
y = lambda n: round(M / 2 + A * math.sin(n * 1.71 + 1) + S * math.cos(n * 0.17593))
ts = [float(l.strip().rstrip(',')) for l in sys.stdin if l.strip()]
print('t_s,camera_dx_px,camera_dy_px')
for n, t in enumerate(ts):
    # The window moved right by x(n) - x(0): the picture moved left by as much.
    print('%.6f,%d,%d' % (t - ts[0], -(x(n) - x(0)), -(y(n) - y(0))))
" > "$OUT/$name.truth.csv"
    echo "$name: $(($(wc -l < "$OUT/$name.truth.csv") - 1)) frames"
  done
done
