#!/usr/bin/python3
"""The capture, the bandpass output and the correlator bank's rho^2 per code, with the detections.

Called by `ranging decode CAPTURE --plot FILE.png`: argv[1] is the JSON the tool wrote (every
number computed in C++: min/max envelopes of the capture and of the float receiver's bandpass
output, the bank's rho^2 per code, the detections' calibrated arrivals), argv[2] the PNG to write.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    d = json.load(open(sys.argv[1]))
    fig, ax = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    us = 1e6
    ax[0].plot([t * us for t in d["capture"]["t"]], d["capture"]["v"], lw=0.6)
    ax[0].set_ylabel("capture (V)")
    ax[1].plot([t * us for t in d["filtered"]["t"]], d["filtered"]["v"], lw=0.6, color="C1")
    ax[1].set_ylabel("bandpass output (V)")
    for c in d["bank"]:
        ax[2].plot([t * us for t in c["t"]], c["rho2"], lw=0.9, label=f"code {c['code']}")
    ax[2].axhline(d["threshold"], color="0.4", ls=":", lw=1, label="detector threshold")
    ax[2].set_ylabel("bank rho^2")
    ax[2].set_ylim(0, 1.05)
    for det in d["detections"]:
        style = dict(color="C3" if det["passed"] else "0.6", ls="--", lw=0.9)
        for a in ax:
            a.axvline(det["arrival_s"] * us, **style)
        ax[2].annotate(f"j={det['code']} rho={det['rho']:.2f}", (det["arrival_s"] * us, 1.0), fontsize=7,
                       rotation=90, va="top", ha="right", color=style["color"])
    ax[2].set_xlabel("time (us); dashed: calibrated arrival of each detection (grey: below --min-rho)")
    ax[2].legend(loc="upper right", fontsize=7, ncol=3)
    for a in ax:
        a.grid(True, alpha=0.3)
    ax[0].set_title(d["title"])
    fig.tight_layout()
    fig.savefig(sys.argv[2], format="png", dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main())
