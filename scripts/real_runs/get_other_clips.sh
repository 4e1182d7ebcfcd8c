#!/bin/bash
# get_other_clips.sh [DIR]: the clips of other public repositories that docs/ACCURACY.md
# measures (others.tsv names them), taken from bare git snapshots of those repositories under
# $MIRROR (default /work/.mirror/OWNER+NAME/repo, as the tool library's `fetch` leaves them;
# this script downloads nothing). The clips carry no licence: measure with them, never commit them.
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
set -u
M=${MIRROR:-/work/.mirror}
OUT=${1:-${REAL_RUNS_DIR:-/tmp/bouncefit-real-runs}/others}
mkdir -p "$OUT"
take() {  # repository commit path name
  if git --git-dir="$M/$1/repo" show "$2:$3" > "$OUT/$4" 2>/dev/null; then echo "ok   $4"
  else echo "missing $1 @$2 $3 (fetch github:${1/+//} first)"; rm -f "$OUT/$4"; fi
}
take IzhanAlam+Object-Tracking-With-Kalman-Filter d72e1e9 ball.mp4 izhan_ball.mp4
take virajkc1+Particle-Trajectory-System dc9f7d4 RedBall.mp4 viraj_redball.mp4
take Adi-SRAM25+Trajectory 6aad717 ball.mp4 adi_red_toss.mp4
take dekvall+EL2320_proj 85eec8e resx/1-long.mp4 dekvall_long.mp4
take dekvall+EL2320_proj 85eec8e resources/small/ex6-one-small.mp4 dekvall_ex6one.mp4
take senihyildirim+ball_tracking 0fb8435 basketball.mp4 senih_basketball.mp4
A=andwel11+Particle-Tracking-Velocimetry-for-a-Bouncing-Ball  # height 1 came at 17280ae
take $A 17280ae "ping pong ball at height 1-1.mp4" ping_pong_ball_at_height_1-1.mp4
take $A 8007020 "ping pong ball at height 2-1.mp4" ping_pong_ball_at_height_2-1.mp4
take $A 8007020 "ping pong ball at height 3-1.mp4" ping_pong_ball_at_height_3-1.mp4
cp "$(dirname "$0")/others.tsv" "$OUT/others.tsv"
