#!/usr/bin/python3
"""Distance error against true distance of a scene run.

Called by `ranging simulate SCENE --plot FILE.png`: argv[1] is the JSON the tool wrote (per
family: every detected measurement's true distance and error, the per-distance mean and standard
deviation, the distances of missed or misdecoded measurements; all computed in C++), argv[2] the
PNG to write.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    d = json.load(open(sys.argv[1]))
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k, f in enumerate(d["families"]):
        color = f"C{k % 10}"
        ax.plot([x * 1e3 for x in f["true_m"]], [e * 1e3 for e in f["error_m"]], ".", ms=3, alpha=0.4, color=color)
        ax.errorbar([x * 1e3 for x in f["distance_m"]], [e * 1e3 for e in f["mean_error_m"]],
                    yerr=[e * 1e3 for e in f["std_error_m"]], fmt="o-", ms=4, lw=1, capsize=3, color=color,
                    label=f"{f['family']}: mean +- std ({f['detected']} of {f['measurements']} decoded)")
        if f["failed_m"]:
            ax.plot([x * 1e3 for x in f["failed_m"]], [0] * len(f["failed_m"]), "x", color=color, ms=7,
                    label=f"{f['family']}: missed or misdecoded ({len(f['failed_m'])})")
    ax.axhline(0, color="0.3", lw=0.8)
    ax.set_xlabel("true distance (mm)")
    ax.set_ylabel("distance error (mm)")
    ax.set_title(d["title"])
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(sys.argv[2], format="png", dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
