#!/usr/bin/env python3
"""score.py LIST OUTDIR: how run.sh's runs compare with what a person counts and with flight times.

Per run with a count in LIST (the shared clips and their copies): the rows real-clips-check
counts (bounce 1 and on) against the person's range. Over all runs: the refitted and the live
heights against the flight-time heights g dt^2/8 (rows that have one): mean |h / flight - 1|,
and rows of 10 cm or more that are more than 5% off.
"""
import csv
import sys


def main(list_path, out):
    within = total = 0
    off = []
    refit, live = [], []
    for line in open(list_path):
        if not line.strip() or line.startswith('#'):
            continue
        name, _, _, count = (line.rstrip('\n').split('\t') + ['-'] * 4)[:4]
        try:
            rows = list(csv.DictReader(open(f'{out}/{name}/peaks.csv')))
        except OSError:
            rows = []
        if count != '-':
            lo, hi = (map(int, count.split('-')) if '-' in count else (int(count), int(count)))
            n = sum(1 for r in rows if int(r['bounce']) >= 1)
            total += 1
            if lo <= n <= hi:
                within += 1
            else:
                off.append(f'{name} {n} (counted {count})')
        for r in rows:
            if r.get('flight_height_m') and r.get('refit_height_m') and float(r['flight_height_m']) > 0:
                fl = float(r['flight_height_m'])
                refit.append((abs(float(r['refit_height_m']) / fl - 1), fl))
                live.append((abs(float(r['height_m']) / fl - 1), fl))
    print(f'within the counted bounces: {within} of {total}')
    for o in off:
        print(f'  outside: {o}')
    for what, v in (('refitted', refit), ('live', live)):
        if v:
            mean = 100 * sum(e for e, _ in v) / len(v)
            bad = sum(1 for e, fl in v if fl >= 0.10 and e > 0.05)
            print(f'{what} heights against flight time: mean {mean:.2f}% over {len(v)} rows; '
                  f'rows of 10 cm or more past 5%: {bad}')


if __name__ == '__main__':
    if len(sys.argv) != 3:
        sys.exit('usage: score.py LIST OUTDIR')
    main(sys.argv[1], sys.argv[2])
