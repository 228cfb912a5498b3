#!/usr/bin/env python3
"""Bias of the paper's eq. 1 (straight lines between positions at one instant) on exact,
noise-free ToFs of the rotor geometry (docs/results/blade-crossing.md): two bursts T = 420 us apart,
symmetric about the instant whose sound travels vertically or one-sided (T/4 and 5T/4 after it), R = 4.244 m, r = 0.85 R, c = 340.
Flight times by bisection on |RX(t_e + tau) - TX(t_e)| = c tau (independent of the C++ solver)."""
import math

C, R = 340.0, 4.244


def tof(te, h, wu, wl, r):
    tx = (r * math.cos(wu * te), r * math.sin(wu * te), h)
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        a = -wl * (te + mid)  # the crossing at t = 0, azimuth 0
        f = math.dist((r * math.cos(a), r * math.sin(a), 0.0), tx) - C * mid
        lo, hi = (mid, hi) if f > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def heron(a, b, s):
    p = (a + b + s) / 2
    q = p * (p - a) * (p - b) * (p - s)
    return 2 * math.sqrt(q) / s if q >= 0 else float("nan")


print("| RPM | h m | pair | d1 mm | d2 mm | paper eq. 1 h - true, mm |")
print("|---|---|---|---|---|---|")
for rpm in (60, 150, 450):
    w = rpm * 2 * math.pi / 60
    r = 0.85 * R
    for T in (420e-6,):
        for h in (0.1, 0.3, 0.5, 1.0):
            # symmetric pair around the vertical ray: emission centred at -tau0/2
            tau0 = h / C
            for name, (t1, t2) in (("symmetric", (-tau0 / 2 - T / 2, -tau0 / 2 + T / 2)),
                                   ("one-sided", (-tau0 / 2 + T / 4, -tau0 / 2 + 5 * T / 4))):
                d1, d2 = C * tof(t1, h, w, w, r), C * tof(t2, h, w, w, r)
                s = 2 * w * r * (t2 - t1)
                e = (heron(d1, d2, s) - h) * 1e3
                print("| %d | %.1f | %s | %.2f | %.2f | %s |" % (rpm, h, name, d1 * 1e3, d2 * 1e3,
                                                                 "%.3f" % e if e == e else "no triangle (|d1 - d2| > s)"))
