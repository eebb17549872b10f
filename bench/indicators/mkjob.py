#!/usr/bin/env python3
"""Writes a nonsep job of one paper2d orbit with tangent vectors into jobs/NAME.json (the folder this runs in):
mkjob.py NAME SCHEME ORDER_OR_STAGES DT T_END Q0 Q1 P0 P1 [--coupling C] [--vectors K]
[--renorm M] [--every-t TE] [--sali] [--gali K] [--megno] [--plugin P] [--omega W]"""
import argparse, json
a = argparse.ArgumentParser()
a.add_argument("name"); a.add_argument("scheme"); a.add_argument("order")
a.add_argument("dt", type=float); a.add_argument("t_end", type=float)
a.add_argument("state", type=float, nargs=4)
a.add_argument("--coupling", type=float, default=0.2)
a.add_argument("--vectors", type=int, default=4)
a.add_argument("--renorm", type=int, default=10)
a.add_argument("--every-t", type=float, default=10.0)
a.add_argument("--sali", action="store_true"); a.add_argument("--gali", type=int, default=0)
a.add_argument("--megno", action="store_true")
a.add_argument("--plugin", default="paper2d")
a.add_argument("--omega", type=float, default=None)
x = a.parse_args()
integ = {"scheme": x.scheme}
if x.scheme == "gauss": integ["stages"] = int(x.order)
elif x.scheme != "implicit_midpoint": integ["order"] = x.order
if x.omega is not None: integ["omega"] = x.omega
every = round(x.every_t / x.dt)
assert every % x.renorm == 0, "every must be a multiple of renormalize_every"
ly = {"vectors": x.vectors, "renormalize_every": x.renorm, "every": every}
an = {"lyapunov": ly}
if x.megno: an["megno"] = True
if x.sali: an["sali"] = True
if x.gali: an["gali"] = x.gali
job = {"model": {"plugin": x.plugin, "parameters": {"coupling": x.coupling}}, "integrator": integ,
       "initial": {"q": x.state[:2], "p": x.state[2:]},
       "time": {"dt": x.dt, "t_end": x.t_end}, "output": {"every": 0}, "analysis": an}
json.dump(job, open(f"jobs/{x.name}.json", "w"), indent=1)
