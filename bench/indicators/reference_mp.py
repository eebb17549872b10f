#!/usr/bin/env python3
"""The truth for docs/dynamics.md's accuracy tables of Lyapunov exponents and MEGNO: paper2d (coupling COUPLING, 0.2 by
default) on the
chaotic orbit q = (0.5, 0), p = (0, 2.5), its variational equations derived by hand (independent of nonsep's
plugins and automatic differentiation), integrated
by an s-stage Gauss-Legendre method (order 2s) in mpmath at `dps` digits, stage equations solved by fixed-point
iteration to 10^-(dps-3). Prints lambda_1(10), lambda_1(20), continuous Y and <Y> at 10, 20, and the discrete MEGNO of
REBOUND's right-endpoint sums (first order in dt) on the grid dt_grid (= h * integer), and FLI and OFLI (suprema over
the steps of h of ln |w| and of ln(|w_perp| / |w_perp(0)|), w_perp the vector's component across the flow).
usage: reference_mp.py H STAGES DPS [COUPLING]"""
import sys, mpmath as mp
h_s, s, dps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
mp.mp.dps = dps
h = mp.mpf(h_s)
c = mp.mpf(sys.argv[4] if len(sys.argv) > 4 else '0.2'); k = mp.mpf(2)/3 + 4*c; two3 = mp.mpf(2)/3
P = lambda x: mp.legendre(s, 2*x - 1)
coef = mp.taylor(lambda x: mp.legendre(s, x), 0, s)[::-1]
cs = sorted((1 + mp.re(r))/2 for r in mp.polyroots(coef, maxsteps=200, extraprec=2*dps))
V = mp.matrix([[cj**m for cj in cs] for m in range(s)])
b = mp.lu_solve(V, mp.matrix([mp.mpf(1)/(m + 1) for m in range(s)]))
a = [mp.lu_solve(V, mp.matrix([ci**(m + 1)/(m + 1) for m in range(s)])) for ci in cs]
def rhs(t, u):
    x, y, p0, p1, dx, dy, dp0, dp1, W, Z = u
    r = 1 + (x*x + y*y)/3
    a11, a12, a22 = r + two3*x*x + 2*c*y*y, k*x*y, r + two3*y*y + 2*c*x*x
    g0, g1 = 1 + p0*p0/2, 1 + p1*p1/2
    Ag0, Ag1 = a11*g0 + a12*g1, a12*g0 + a22*g1
    Ax = (2*x, k*y, (two3 + 4*c)*x); Ay = ((two3 + 4*c)*y, k*x, 2*y)
    Hx = Ax[0]*g0*g0 + 2*Ax[1]*g0*g1 + Ax[2]*g1*g1
    Hy = Ay[0]*g0*g0 + 2*Ay[1]*g0*g1 + Ay[2]*g1*g1
    Hpp00 = 2*Ag0 + 2*p0*a11*p0; Hpp01 = 2*p0*a12*p1; Hpp11 = 2*Ag1 + 2*p1*a22*p1
    Hp0x = 2*p0*(Ax[0]*g0 + Ax[1]*g1); Hp1x = 2*p1*(Ax[1]*g0 + Ax[2]*g1)
    Hp0y = 2*p0*(Ay[0]*g0 + Ay[1]*g1); Hp1y = 2*p1*(Ay[1]*g0 + Ay[2]*g1)
    Hxx = 2*g0*g0 + k*g1*g1; Hxy = 2*k*g0*g1; Hyy = k*g0*g0 + 2*g1*g1
    ddx = Hp0x*dx + Hp0y*dy + Hpp00*dp0 + Hpp01*dp1
    ddy = Hp1x*dx + Hp1y*dy + Hpp01*dp0 + Hpp11*dp1
    ddp0 = -(Hxx*dx + Hxy*dy + Hp0x*dp0 + Hp1x*dp1)
    ddp1 = -(Hxy*dx + Hyy*dy + Hp0y*dp0 + Hp1y*dp1)
    n2 = dx*dx + dy*dy + dp0*dp0 + dp1*dp1
    return [2*p0*Ag0, 2*p1*Ag1, -Hx, -Hy, ddx, ddy, ddp0, ddp1, t*(dx*ddx + dy*ddy + dp0*ddp0 + dp1*ddp1)/n2, 2*W/t]
w = [mp.mpf(1), mp.mpf(1)/2, mp.mpf(1)/3, mp.mpf(1)/4]; nw = mp.sqrt(sum(v*v for v in w))
u = [mp.mpf('0.5'), mp.mpf(0), mp.mpf(0), mp.mpf('2.5')] + [v/nw for v in w] + [mp.mpf(0), mp.mpf(0)]
N = int(mp.nint(20/h)); tol = mp.mpf(10)**(-(dps - 3))
def across(t, u):  # ln(|w_perp| / |w|), w_perp = w - (w.f / f.f) f, f the flow (the first four of rhs)
    f = rhs(t, u)[:4]; w = u[4:8]; c = sum(x*y for x, y in zip(w, f))/sum(x*x for x in f)
    return mp.log(mp.sqrt(sum((x - c*y)**2 for x, y in zip(w, f)))/mp.sqrt(sum(x*x for x in w)))
a0 = across(mp.mpf(1), u); fli = ofli = mp.mpf(0)
logn = mp.mpf(0); lns = [logn]; out = {}; K = None
for n in range(N):
    t0 = n*h
    if K is None: K = [rhs(t0 + ci*h, u) for ci in cs]
    for it in range(200):
        Kn = [rhs(t0 + cs[i]*h, [u[j] + h*sum(a[i][m]*K[m][j] for m in range(s)) for j in range(10)]) for i in range(s)]
        d = max(abs(Kn[i][j] - K[i][j])/(1 + abs(Kn[i][j])) for i in range(s) for j in range(8))
        K = Kn
        if d < tol: break
    else: raise SystemExit("no convergence")
    u = [u[j] + h*sum(b[i]*K[i][j] for i in range(s)) for j in range(10)]
    nn = mp.sqrt(sum(v*v for v in u[4:8])); logn += mp.log(nn); u[4:8] = [v/nn for v in u[4:8]]; lns.append(logn)
    t = (n + 1)*h
    fli = max(fli, logn); ofli = max(ofli, logn + across(t, u) - a0)
    if abs(t - 10) < h/2 or n == N - 1:
        T = int(mp.nint(t)); out[f"lambda1_{T}"] = logn/T; out[f"Y_cont_{T}"] = 2*u[8]/T; out[f"meanY_cont_{T}"] = u[9]/T
        print(T, mp.nstr(out[f"lambda1_{T}"], 15), mp.nstr(out[f"Y_cont_{T}"], 15), mp.nstr(out[f"meanY_cont_{T}"], 15),
              "FLI", mp.nstr(fli, 15), "OFLI", mp.nstr(ofli, 15), flush=True)
for g in ('0.005', '0.0025', '0.00125', '0.000625', '0.0003125', '0.00025'):
    e = int(mp.nint(mp.mpf(g)/h))
    if e == 0 or abs(e*h - mp.mpf(g)) > h/1000: continue
    dt = e*h; wg = iy = mp.mpf(0)
    for kk in range(1, int(mp.nint(20/dt)) + 1):
        T = kk*dt; wg += T*(lns[kk*e] - lns[(kk - 1)*e]); Y = 2*wg/T; iy += Y*dt
        if abs(T - 10) < dt/2 or abs(T - 20) < dt/2:
            print(f"disc dt={g} t={mp.nstr(T, 3)} Y={mp.nstr(Y, 15)} meanY={mp.nstr(iy/T, 15)}", flush=True)
