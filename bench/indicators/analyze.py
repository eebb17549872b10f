#!/usr/bin/env python3
"""lambda_1 or MEGNO of the chaotic orbit from the runs runs/PREFIX_DT of ladder.sh, at time T:
errors against the truth given on the command line and observed orders log2(e(2dt)/e(dt)).
usage: analyze.py PREFIX T QUANTITY TRUTH   (PREFIX ch_g3, o_mpe4, ...; QUANTITY lyapunov0 | mean_megno | megno)"""
import csv, glob, math, sys
prefix, T, col, truth = sys.argv[1], float(sys.argv[2]), sys.argv[3], float(sys.argv[4])
res = []
for d in glob.glob(f'runs/{prefix}_*'):
    dt = float(d.rsplit('_', 1)[1])
    try: rows = list(csv.DictReader(open(d + '/lyapunov.csv')))
    except FileNotFoundError: continue
    v = next((float(r[col]) for r in rows if abs(float(r['t']) - T) < 1e-9), None)
    if v is not None: res.append((dt, v))
res.sort(reverse=True); prev = None
print(f"| dt | {col}({T:g}) | relative error | observed order |\n|---|---|---|---|")
for dt, v in res:
    e = abs(v - truth)/abs(truth); o = ''
    if prev and abs(prev[0]/dt - 2) < 1e-9 and e > 0: o = '%.2f' % math.log2(prev[1]/e)
    print(f"| {dt:g} | {v:.12g} | {e:.3g} | {o} |"); prev = (dt, e)
