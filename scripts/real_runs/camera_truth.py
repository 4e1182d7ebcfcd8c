#!/usr/bin/env python3
"""camera_truth.py TRUTH.csv TRACK.csv: the camera motion a run measured (track.csv's
camera_dx_px, camera_dy_px) against the truth make_held_copies.sh wrote, frame by frame
matched on t_s, from the first frame the run reported the camera moving. Prints how many
frames came before, the RMS and largest error per axis (px) and the share of frames within
0.5 px; exit 0."""
import csv
import math
import sys


def main():
    asked = len(sys.argv) > 1 and sys.argv[1] in ('--help', '-h')
    if asked or len(sys.argv) != 3:
        print(__doc__, file=sys.stdout if asked else sys.stderr)
        sys.exit(0 if asked else 2)
    truth = list(csv.DictReader(open(sys.argv[1])))
    track = list(csv.DictReader(open(sys.argv[2])))
    by_t = {round(float(r['t_s']), 3): r for r in truth}
    ex, ey = [], []
    before = 0
    for row in track:
        t = by_t.get(round(float(row['t_s']), 3))
        if t is None or row.get('camera_dx_px') in (None, ''):
            continue
        if not ex and float(row['camera_dx_px']) == 0 and float(row['camera_dy_px']) == 0:
            before += 1
            continue
        ex.append(float(row['camera_dx_px']) - float(t['camera_dx_px']))
        ey.append(float(row['camera_dy_px']) - float(t['camera_dy_px']))
    if not ex:
        print('no frame matched (no camera columns?)')
        return
    rms = lambda v: math.sqrt(sum(e * e for e in v) / len(v))
    within = sum(1 for a, b in zip(ex, ey) if abs(a) <= 0.5 and abs(b) <= 0.5) / len(ex)
    print('%4d frames (%d before)  x: rms %5.2f max %6.2f  y: rms %5.2f max %6.2f px  within 0.5 px: %3.0f%%' %
          (len(ex), before, rms(ex), max(map(abs, ex)), rms(ey), max(map(abs, ey)), 100 * within))


if __name__ == '__main__':
    main()
