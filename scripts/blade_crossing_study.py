#!/usr/bin/env python3
"""The blade-crossing study of docs/results/blade-crossing.md.

Runs `ranging simulate` on variants of scenes/blade-crossing.yaml (14.5 degree beam) and
scenes/blade-crossing-wide.yaml (the paper's 320 mm window), and `ranging doppler`, then
writes the plots to docs/results/blade-crossing-*.png and prints the tables (markdown).

usage: scripts/blade_crossing_study.py --tool build/tool/ranging --work DIR [--crossings N]
"""
import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def variant(src, work, name, **keys):
    text = open(os.path.join(ROOT, "scenes", src)).read()
    text = re.sub(r"^name: .*$", "name: " + name, text, flags=re.M)
    for k, v in keys.items():
        text, n = re.subn(r"^(\s+%s:) [^#\n]*" % k, r"\g<1> %s" % v, text, count=1, flags=re.M)
        if n == 0:
            text = text.replace("  type: rotor\n", "  type: rotor\n  %s: %s\n" % (k, v))
    path = os.path.join(work, name + ".yaml")
    open(path, "w").write(text)
    return path


def simulate(tool, path, out):
    t = time.process_time()
    r = subprocess.run([tool, "simulate", path, "--out", out, "--quiet"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(r.stderr)
    cpu = time.process_time() - t
    s = json.load(open(os.path.join(out, "summary.json")))
    bursts = list(csv.DictReader(open(os.path.join(out, "bursts.csv"))))
    meas = list(csv.DictReader(open(os.path.join(out, "measurements.csv"))))
    return s, bursts, meas


def rms(xs):
    return math.sqrt(sum(x * x for x in xs) / len(xs)) if xs else float("nan")


def stats(s):
    cr = s["crossings"]
    em = [c["h_est_m"] - c["h_true_m"] for c in cr if c["h_est_m"] is not None]
    ep = [c["h_est_paper_m"] - c["h_true_m"] for c in cr if c["h_est_paper_m"] is not None]
    nmeas = [c["measurements"] for c in cr]
    return {
        "n": len(cr),
        "with2": sum(1 for m in nmeas if m >= 2),
        "mean_meas": sum(nmeas) / len(nmeas),
        "motion_n": len(em), "motion_rms_mm": rms(em) * 1e3,
        "paper_n": len(ep), "paper_rms_mm": rms(ep) * 1e3,
        "paper_mean_mm": (sum(ep) / len(ep) * 1e3) if ep else float("nan"),
        "decoded": s["bursts_decoded"], "rendered": s["bursts_rendered"], "misdecodes": s["misdecodes"],
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tool", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--crossings", type=int, default=100)
    ap.add_argument("--images", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    t0 = time.time()
    rows = []
    runs = {}
    # 1. The paper's operating points, both beams.
    for scene, beam in (("blade-crossing.yaml", "14.5"), ("blade-crossing-wide.yaml", "116")):
        for rpm in (400, 450, 500):
            name = "bc-%s-%d" % (beam, rpm)
            path = variant(scene, a.work, name, rpm=rpm, crossings=a.crossings)
            runs[(beam, rpm)] = simulate(a.tool, path, os.path.join(a.work, name))
            rows.append((beam, rpm, stats(runs[(beam, rpm)][0])))
    # 2. Where the method works: lower speeds (14.5 degree beam, the real transducer).
    for rpm in (20, 40, 60, 100, 150, 200):
        name = "bc-14.5-%d" % rpm
        path = variant("blade-crossing.yaml", a.work, name, rpm=rpm, crossings=max(20, a.crossings // 2))
        runs[("14.5", rpm)] = simulate(a.tool, path, os.path.join(a.work, name))
        rows.append(("14.5", rpm, stats(runs[("14.5", rpm)][0])))
    # 3. Doppler at constant line-of-sight speed.
    dop_csv = os.path.join(a.work, "doppler.csv")
    speeds = ",".join(str(v) for v in [-20, -10, -6, -4, -3, -2, -1, -0.5, 0, 0.5, 1, 2, 3, 4, 6, 10, 20])
    r = subprocess.run([a.tool, "doppler", os.path.join(ROOT, "scenes", "blade-crossing.yaml"), "--speeds=" + speeds,
                        "--distance", "0.5", "--repeats", "5", "--out", dop_csv], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(r.stderr)
    dop = list(csv.DictReader(open(dop_csv)))
    wall = time.time() - t0

    print("| beam deg | RPM | crossings | with >= 2 meas. | mean meas. | bursts decoded / rendered | misdecodes |"
          " motion-aware rms mm (n) | paper eq. 1 rms mm (n) | paper mean mm |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for beam, rpm, s in rows:
        print("| %s | %d | %d | %d | %.2f | %d / %d | %d | %.3f (%d) | %.3f (%d) | %.3f |" % (
            beam, rpm, s["n"], s["with2"], s["mean_meas"], s["decoded"], s["rendered"], s["misdecodes"],
            s["motion_rms_mm"], s["motion_n"], s["paper_rms_mm"], s["paper_n"], s["paper_mean_mm"]))
    print()
    print("| v_los m/s | Doppler | decoded | misdecoded | missed | bias start mm | bias centre mm | std mm |")
    print("|---|---|---|---|---|---|---|---|")
    for d in dop:
        f = lambda k: float(d[k]) * 1e3 if d[k] not in ("", "nan") else float("nan")  # noqa: E731
        print("| %s | %.4f | %s/%s | %s | %s | %.3f | %.3f | %.3f |" % (
            d["los_speed_mps"], float(d["doppler"]), d["decoded"], d["bursts"], d["misdecoded"], d["missed"],
            f("bias_start_m"), f("bias_centre_m"), f("std_m")))
    print("\nwall time %.0f s" % wall)

    os.makedirs(a.images, exist_ok=True)
    # Figure: Doppler.
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.6))
    v = [float(d["los_speed_mps"]) for d in dop]
    n = [int(d["bursts"]) for d in dop]
    ax[0].plot(v, [int(d["decoded"]) / k for d, k in zip(dop, n)], "o-", label="decoded")
    ax[0].plot(v, [int(d["misdecoded"]) / k for d, k in zip(dop, n)], "s-", label="misdecoded (wrong code)")
    ax[0].plot(v, [int(d["missed"]) / k for d, k in zip(dop, n)], "^-", label="missed")
    ax[0].set_xlabel("line-of-sight speed, m/s (closing > 0)")
    ax[0].set_ylabel("fraction of bursts")
    ax[0].legend(fontsize=8)
    ax[0].set_title("M1, 0.5 m, fixed receiver, constant speed")
    ok = [(float(d["los_speed_mps"]), float(d["bias_start_m"]) * 1e3, float(d["bias_centre_m"]) * 1e3)
          for d in dop if int(d["decoded"]) > 0]
    ax[1].plot([o[0] for o in ok], [o[1] for o in ok], "o-", label="vs flight time of the burst start")
    ax[1].plot([o[0] for o in ok], [o[2] for o in ok], "s-", label="vs flight time of the burst centre")
    ax[1].set_xlabel("line-of-sight speed, m/s")
    ax[1].set_ylabel("ToF bias x c, mm")
    ax[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.images, "blade-crossing-doppler.png"), dpi=110)

    # Figure: where in the window bursts decode (wide beam, 450 RPM; and 14.5 deg at 60 RPM).
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    for axi, key, title in ((ax[0], ("116", 450), "paper's window (116 deg beam), 450 RPM"),
                            (ax[1], ("14.5", 60), "14.5 deg beam, 60 RPM")):
        b = runs[key][1]
        for dec, col, lab in (("0", "0.75", "not decoded"), ("1", "C2", "decoded")):
            pts = [(float(x["t_rel_s"]) * 1e3, float(x["h_true_m"])) for x in b if x["decoded"] == dec]
            axi.scatter([p[0] for p in pts], [p[1] for p in pts], s=6, c=col, label=lab)
        axi.set_xlabel("burst emission - crossing time, ms")
        axi.set_ylabel("h, m")
        axi.set_title(title, fontsize=9)
        axi.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.images, "blade-crossing-window.png"), dpi=110)

    # Figure: h estimated vs truth and error vs RPM.
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    s60 = runs[("14.5", 60)][0]["crossings"]
    ax[0].plot([c["h_true_m"] for c in s60 if c["h_est_m"] is not None],
               [(c["h_est_m"] - c["h_true_m"]) * 1e3 for c in s60 if c["h_est_m"] is not None], "o", label="motion-aware")
    ax[0].plot([c["h_true_m"] for c in s60 if c["h_est_paper_m"] is not None],
               [(c["h_est_paper_m"] - c["h_true_m"]) * 1e3 for c in s60 if c["h_est_paper_m"] is not None], "x",
               label="paper eq. 1")
    ax[0].set_xlabel("h true, m")
    ax[0].set_ylabel("h estimated - true, mm")
    ax[0].set_title("14.5 deg beam, 60 RPM", fontsize=9)
    ax[0].legend(fontsize=8)
    rpms = sorted(r for (b, r) in runs if b == "14.5")
    st = [stats(runs[("14.5", r)][0]) for r in rpms]
    ax[1].semilogy(rpms, [x["motion_rms_mm"] for x in st], "o-", label="motion-aware rms")
    ax[1].semilogy(rpms, [x["paper_rms_mm"] for x in st], "x-", label="paper eq. 1 rms")
    ax2 = ax[1].twinx()
    ax2.plot(rpms, [x["with2"] / x["n"] for x in st], "k--", label="crossings with >= 2 measurements")
    ax2.set_ylabel("fraction of crossings with >= 2 measurements")
    ax[1].set_xlabel("RPM (both rotors)")
    ax[1].set_ylabel("h error rms, mm")
    ax[1].set_title("14.5 deg beam, h = 0.1 .. 0.99 m", fontsize=9)
    ax[1].legend(fontsize=8, loc="upper left")
    ax2.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(os.path.join(a.images, "blade-crossing-error.png"), dpi=110)

    # Figure: error vs h at 60 RPM per estimator, and measurements per crossing vs h.
    fig, ax = plt.subplots(1, 1, figsize=(5.5, 3.6))
    for key, mk in ((("14.5", 60), "o"), (("14.5", 100), "s"), (("14.5", 150), "^"), (("116", 450), "x")):
        cr = runs[key][0]["crossings"]
        ax.plot([c["h_true_m"] for c in cr], [c["measurements"] for c in cr], mk, label="%s deg, %d RPM" % key)
    ax.set_xlabel("h, m")
    ax.set_ylabel("accepted measurements per crossing")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.images, "blade-crossing-measurements.png"), dpi=110)

    # Figure: timeline of a crossing (14.5 deg, 60 RPM, the crossing with h nearest 0.5 m).
    s, b, m = runs[("14.5", 60)]
    c = min(s["crossings"], key=lambda c: abs(c["h_true_m"] - 0.5))
    i = c["index"]
    fig, ax = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    tc = c["t_s"]
    bb = [x for x in b if int(x["crossing"]) == i]
    ax[0].plot([float(x["t_rel_s"]) * 1e3 for x in bb], [float(x["angle_deg"]) for x in bb], ".-", label="line of sight from vertical (burst centre)")
    ax[0].axhline(7.25, color="0.6", ls=":", label="half beam, 7.25 deg")
    ax[0].set_ylabel("deg")
    ax[0].legend(fontsize=8)
    ax[0].set_title("crossing %d: h = %.3f m, 60 RPM (tips %.1f m/s), 14.5 deg beam" % (i, c["h_true_m"], s["relative_tip_speed_mps"] / 2), fontsize=9)
    for x in bb:
        te = float(x["t_rel_s"]) * 1e3
        ax[1].axvline(te, color="C2" if x["decoded"] == "1" else "0.85", lw=0.8)
    mm = [x for x in m if int(x["crossing"]) == i]
    ax[1].plot([(float(x["t_emit_s"]) - tc + float(x["tof_s"])) * 1e3 for x in mm], [float(x["distance_m"]) for x in mm],
               "o", label="measured c ToF at reception (green lines: emissions decoded)")
    ax[1].axhline(c["h_true_m"], color="k", lw=0.8, label="h true")
    ax[1].set_xlabel("time - crossing, ms")
    ax[1].set_ylabel("distance, m")
    ax[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.images, "blade-crossing-timeline.png"), dpi=110)


if __name__ == "__main__":
    main()
