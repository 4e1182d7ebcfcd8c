#!/usr/bin/env python3
"""Where each run's fitted ball starts against the footage (docs/ACCURACY.md, "The fitted ball on
the clip's timeline"). For every run directory with a fit: each drop of coefficients.json's
"drops", simulated.csv's first time against peaks.csv's start apex, its first rebound apex (time
and height) against the recorded one, in frames of the clip (track.csv's median step) and mm,
and whether the report's bounce figure (report_plots/bounces_difference.dat, written by
`bouncefit report` when absent) holds coefficients.json's simulated - recorded per bounce.

Usage: scripts/real_runs/timeline.py [--bouncefit build/bouncefit] RUN_DIR...
(e.g. the directories ../shared/tools/real-clips-check leaves in /tmp/real-clips-check.*/)."""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def num(v):
    return float(v) if v not in (None, "") else float("nan")


def first_rebound(sim):
    """The highest sample between the simulated drop's first two impacts."""
    i = 1
    while i < len(sim) and sim[i][1] <= sim[i - 1][1]:
        i += 1
    best = None
    while i < len(sim) and (best is None or sim[i][1] >= sim[i - 1][1]):
        if best is None or sim[i][1] > best[1]:
            best = sim[i]
        i += 1
    return best


def check(run, bouncefit):
    c = json.load(open(os.path.join(run, "coefficients.json")))
    peaks = rows(os.path.join(run, "peaks.csv"))
    track = rows(os.path.join(run, "track.csv"))
    sim = rows(os.path.join(run, "simulated.csv"))
    steps = [num(b["t_s"]) - num(a["t_s"]) for a, b in zip(track, track[1:])]
    frame = statistics.median(steps)
    plots = os.path.join(run, "report_plots", "bounces_difference.dat")
    if not os.path.exists(plots):
        subprocess.run([bouncefit, "report", run], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    plotted = {}
    if os.path.exists(plots):
        for line in open(plots):
            if line.startswith("#") or not line.strip():
                continue
            f = line.split()
            plotted[(int(f[3]), int(f[4]))] = float(f[1])

    def row(drop, bounce):
        for p in peaks:
            if int(p["bounce"]) == bounce and int(p.get("drop") or 0) == drop:
                return p
        return None

    out = []
    for d in c.get("drops", []):
        drop, start = d["drop"], d["start_bounce"]
        s = [(num(r["t_s"]), num(r["height_m"])) for r in sim if int(r["drop"]) == drop]
        a, b = row(drop, start), row(drop, start + 1)
        apex = first_rebound(s) if s else None
        if not (s and a and b and apex):
            out.append((drop, start, None))
            continue
        rec_t, rec_h = num(b["t_s"]), num(b["fused_height_m"] or b["height_m"])
        pairs = all(abs(plotted.get((drop, n), float("nan")) - 1000 * (sm - r)) < 1e-3
                    for n, r, sm in zip(d["bounces"], d["recorded_m"], d["simulated_m"]) if sm is not None)
        out.append((drop, start, dict(
            frame_ms=1000 * frame, start_frames=(s[0][0] - num(a["t_s"])) / frame,
            apex_frames=(apex[0] - rec_t) / frame, apex_mm=1000 * (apex[1] - rec_h), rec_h=rec_h,
            pairs=pairs, time_scale=c.get("time_scale", 1))))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bouncefit", default="build/bouncefit")
    ap.add_argument("runs", nargs="+")
    a = ap.parse_args()
    print("| clip | drop:start bounce | frame (ms) | simulated start - start apex (frames) | "
          "first rebound: simulated - recorded (frames) | (mm) | within 2 frames and max(3 mm, 5%) | "
          "bounce figure = coefficients.json |")
    print("|---|---|---|---|---|---|---|---|")
    bad = 0
    for run in a.runs:
        if not os.path.exists(os.path.join(run, "coefficients.json")):
            continue
        name = os.path.basename(os.path.normpath(run))
        for drop, start, m in check(run, a.bouncefit):
            if m is None:
                print(f"| {name} | {drop}:{start} | | no simulated drop or rebound row | | | no | |")
                bad += 1
                continue
            ok = abs(m["start_frames"]) <= 1 and abs(m["apex_frames"]) <= 2 and \
                abs(m["apex_mm"]) <= max(3, 0.05 * 1000 * m["rec_h"])
            bad += (not ok) or (not m["pairs"])
            slow = "" if m["time_scale"] == 1 else f" (x{m['time_scale']:g} real)"
            print(f"| {name} | {drop}:{start} | {m['frame_ms']:.1f}{slow} | {m['start_frames']:+.2f} | "
                  f"{m['apex_frames']:+.2f} | {m['apex_mm']:+.1f} | {'yes' if ok else 'no'} | "
                  f"{'yes' if m['pairs'] else 'no'} |")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
