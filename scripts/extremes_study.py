#!/usr/bin/python3
"""Scene extremes study (issue 12 section 5) and sound-velocity compensation (issue 14 section 6).

Runs `ranging simulate` (the product; this script only drives it and plots):
  snr   decode error rate and ToF standard deviation from +40 to -12 dB SNR
        -> OUT/snr_curve.csv, OUT/snr_curve.png
  comp  distance error without and with the reference path over -20..+40 C, the receiver
        assuming 343.99 m/s (20 C, 50 %) -> OUT/sound_velocity.csv and a Markdown table on stdout,
        beside an independent prediction d * (c_rx / c(T) - 1) with c(T) from the ideal-gas law
        331.3 sqrt(1 + T/273.15) m/s (dry air).

usage: /usr/bin/python3 scripts/extremes_study.py --tool build/tool/ranging --out OUTDIR [snr] [comp]
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

SNR_SCENE = """name: snr
transducers: {{}}
geometry:
  distances_m: [0.5]
  repeats: {repeats}
excitation:
  family: Gold4
noise:
  snr_db: {snr}
  seed: 11
"""

COMP_SCENE = """name: comp
transducers: {{}}
medium:
  temperature_c: {t}
  relative_humidity: 50
geometry:
  distances_m: [0.5, 1.0]
  repeats: 2
excitation:
  family: Gold4
  codes: [1, 4, 7]
noise:
  snr_db: 20
  seed: 5
  adc:
    bits: 12
    full_scale_v: 1.0
receiver:
  speed_of_sound: 343.99
{comp}"""


def simulate(tool, text, work, name):
    path = os.path.join(work, name + ".yaml")
    with open(path, "w") as f:
        f.write(text)
    out = os.path.join(work, name)
    subprocess.run([tool, "simulate", path, "--out", out, "--quiet", "--json"], check=True,
                   stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "measurements.csv")) as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    return rows, summary


def snr_study(tool, out, work, repeats):
    table = []
    for snr in range(40, -13, -4):
        rows, summary = simulate(tool, SNR_SCENE.format(snr=snr, repeats=repeats), work, f"snr{snr}")
        fam = summary["families"][0]
        tofs = [float(r["tof_s"]) for r in rows
                if r["code_decoded"] == r["code_sent"] and r["tof_s"] != ""]
        mean = sum(tofs) / len(tofs) if tofs else float("nan")
        std = math.sqrt(sum((t - mean) ** 2 for t in tofs) / (len(tofs) - 1)) if len(tofs) > 1 else float("nan")
        table.append({"snr_db": snr, "measurements": fam["measurements"], "decode_errors": fam["decode_errors"],
                      "decode_error_rate": fam["decode_error_rate"], "missed": fam["missed"],
                      "detector_errors": fam["detector"]["decode_errors"],
                      "pearson_errors": fam["pearson"]["decode_errors"], "tof_std_ns": std * 1e9})
    with open(os.path.join(out, "snr_curve.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0].keys()))
        w.writeheader()
        w.writerows(table)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    x = [r["snr_db"] for r in table]
    ax[0].plot(x, [r["decode_error_rate"] for r in table], "o-", label="either decoder")
    ax[0].plot(x, [r["detector_errors"] / r["measurements"] for r in table], "s--", label="rho^2 detector")
    ax[0].plot(x, [r["pearson_errors"] / r["measurements"] for r in table], "^:", label="Pearson")
    ax[0].set_xlabel("SNR (dB)")
    ax[0].set_ylabel("decode error rate")
    ax[0].legend()
    ax[0].grid(True, alpha=0.3)
    ax[1].semilogy(x, [r["tof_std_ns"] for r in table], "o-")
    ax[1].set_xlabel("SNR (dB)")
    ax[1].set_ylabel("ToF std of right decodes (ns)")
    ax[1].grid(True, which="both", alpha=0.3)
    fig.suptitle(f"Gold4 at 0.5 m, {table[0]['measurements']} bursts per point")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "snr_curve.png"), dpi=110)
    print("| SNR dB | n | errors | rate | missed | det.err | prs.err | ToF std ns |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in table:
        print(f"| {r['snr_db']} | {r['measurements']} | {r['decode_errors']} | {r['decode_error_rate']:.3f} | "
              f"{r['missed']} | {r['detector_errors']} | {r['pearson_errors']} | {r['tof_std_ns']:.2f} |")


def comp_study(tool, out, work):
    table = []
    for t in range(-20, 41, 10):
        c_ideal = 331.3 * math.sqrt(1 + t / 273.15)
        res = {}
        for mode, comp in (("raw", ""), ("comp", "compensation:\n  reference_distance_m: 0.1\n")):
            rows, summary = simulate(tool, COMP_SCENE.format(t=t, comp=comp), work, f"c{mode}{t + 100}")
            c_channel = summary["speed_of_sound"]
            for d in (0.5, 1.0):
                errs = [float(r["error_m"]) for r in rows if float(r["true_distance_m"]) == d and r["error_m"] != ""]
                cs = [float(r["speed_used"]) for r in rows if float(r["true_distance_m"]) == d]
                res[(mode, d)] = (sum(errs) / len(errs), max(abs(e) for e in errs), sum(cs) / len(cs), len(errs),
                                  summary["families"][0]["decode_errors"])
        for d in (0.5, 1.0):
            table.append({"temperature_c": t, "distance_m": d, "c_channel": c_channel, "c_ideal_gas": c_ideal,
                          "predicted_error_mm": d * (343.99 / c_ideal - 1) * 1e3,
                          "error_mm_uncompensated": res[("raw", d)][0] * 1e3,
                          "error_mm_compensated": res[("comp", d)][0] * 1e3,
                          "max_abs_error_mm_compensated": res[("comp", d)][1] * 1e3,
                          "c_est": res[("comp", d)][2], "decode_errors": res[("comp", d)][4]})
    with open(os.path.join(out, "sound_velocity.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0].keys()))
        w.writeheader()
        w.writerows(table)
    print("| T (C) | d (m) | c channel (Cramer) | c ideal gas (indep.) | predicted error (mm) | "
          "error uncompensated (mm) | error compensated (mm) | max abs compensated (mm) | c_est (m/s) |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in table:
        print(f"| {r['temperature_c']} | {r['distance_m']} | {r['c_channel']:.2f} | {r['c_ideal_gas']:.2f} | "
              f"{r['predicted_error_mm']:.1f} | {r['error_mm_uncompensated']:.1f} | {r['error_mm_compensated']:.3f} | "
              f"{r['max_abs_error_mm_compensated']:.3f} | {r['c_est']:.2f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tool", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--repeats", type=int, default=8, help="snr: repeats of the 9 codes per SNR point")
    ap.add_argument("parts", nargs="*", default=["snr", "comp"])
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    with tempfile.TemporaryDirectory() as work:
        if "snr" in a.parts:
            snr_study(a.tool, a.out, work, a.repeats)
        if "comp" in a.parts:
            comp_study(a.tool, a.out, work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
