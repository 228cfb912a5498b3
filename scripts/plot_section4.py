#!/usr/bin/python3
"""Figures 13-15 of the paper's Section 4 from the data `ranging evaluate` writes.

usage: plot_section4.py STEM FIG13_FAMILY
reads STEM-per-code.csv, STEM-fig13.csv and STEM-rho-d.csv, writes STEM-fig13.png, STEM-fig14.png,
STEM-fig15.png and STEM-fig11.png (rho(d), eqs. 7-8).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    stem, fam13 = sys.argv[1], sys.argv[2]
    rows = list(csv.DictReader(open(stem + "-per-code.csv")))
    families = []
    for r in rows:
        if r["family"] not in families:
            families.append(r["family"])

    # Figure 13: filtered received bursts of every code of one family.
    with open(stem + "-fig13.csv") as fh:
        reader = csv.reader(fh)
        header = next(reader)
        cols = [[] for _ in header]
        for line in reader:
            for i, v in enumerate(line):
                cols[i].append(float(v))
    n = len(header) - 1
    fig, axes = plt.subplots(n, 1, figsize=(7, 1.3 * n + 0.6), sharex=True)
    if n == 1:
        axes = [axes]
    t_us = [t * 1e6 for t in cols[0]]
    for i, ax in enumerate(axes):
        ax.plot(t_us, cols[i + 1], lw=0.6)
        ax.set_ylabel(header[i + 1], rotation=0, ha="right", fontsize=8)
        ax.tick_params(labelsize=7)
        # Show the burst only (from its onset).
        nz = [k for k, v in enumerate(cols[i + 1]) if abs(v) > 1e-3 * max(map(abs, cols[i + 1]))]
        if nz:
            ax.set_xlim(t_us[nz[0]] - 10, t_us[nz[0]] + 230)
    axes[-1].set_xlabel("time since transmission (us)")
    fig.suptitle("Figure 13: filtered received signals, %s (V)" % fam13, fontsize=10)
    fig.tight_layout()
    fig.savefig(stem + "-fig13.png", dpi=110)
    plt.close(fig)

    def per_code(key, title, ylabel, out):
        groups = [("7-bit M-sequences", [f for f in families if f in ("M1", "M2")]),
                  ("15-bit M-sequences", [f for f in families if f in ("M3", "M4")]),
                  ("7-bit Gold codes", [f for f in families if f.startswith("Gold")])]
        groups = [g for g in groups if g[1]] or [("families", families)]
        fig, axes = plt.subplots(1, len(groups), figsize=(4.2 * len(groups), 3.4), squeeze=False)
        for ax, (name, fams) in zip(axes[0], groups):
            for fam in fams:
                pts = [(int(r["code"]), float(r[key])) for r in rows if r["family"] == fam and r[key] not in ("", "nan")]
                if pts:
                    ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", ms=3, lw=1, label=fam)
            ax.set_title(name, fontsize=9)
            ax.set_xlabel("code j", fontsize=8)
            ax.set_ylabel(ylabel, fontsize=8)
            ax.tick_params(labelsize=7)
            ax.legend(fontsize=6)
            ax.grid(alpha=0.3)
        fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        fig.savefig(out, dpi=110)
        plt.close(fig)

    # Figure 11 (bandpass curve): rho(d) per family (eqs. 7-8).
    try:
        rd = list(csv.DictReader(open(stem + "-rho-d.csv")))
    except FileNotFoundError:
        rd = []
    if rd:
        fig, ax = plt.subplots(figsize=(6, 3.6))
        for fam in families:
            pts = [(float(r["distance_m"]) * 1e3, float(r["rho_d"])) for r in rd if r["family"] == fam]
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", ms=3, lw=1, label=fam)
        ax.set_xlabel("distance d (mm)", fontsize=8)
        ax.set_ylabel("rho(d)", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6, ncol=2)
        ax.grid(alpha=0.3)
        fig.suptitle("Figure 11: correlation of the bandpass-filtered received signal with d_min (eqs. 7-8)",
                     fontsize=9)
        fig.tight_layout()
        fig.savefig(stem + "-fig11.png", dpi=110)
        plt.close(fig)

    per_code("u_mean", "Figure 14: distinguishability u per code (mean over distances)", "u",
             stem + "-fig14.png")
    per_code("energy_at_max_distance_v2", "Figure 15: received energy per code at the largest distance",
             "energy (V^2)", stem + "-fig15.png")


if __name__ == "__main__":
    main()
