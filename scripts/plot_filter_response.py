#!/usr/bin/python3
"""|H(f)| of the float and the quantized bandpass design over the spec mask.

Called by `ranging filter --plot FILE.png`: argv[1] is the JSON the tool wrote (frequencies,
float_db, quantized_db = 20 log10 |H|, computed in C++, and the spec), argv[2] the PNG to write.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    data = json.load(open(sys.argv[1]))
    s = data["spec"]
    f = [v / 1e3 for v in data["f"]]
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(f, data["float_db"], label="float design", lw=1.5)
    ax.plot(f, data["quantized_db"], label="quantized coefficients", lw=1.2, ls="--")
    top = 5
    bottom = -max(2 * s["rs_db"], 60)
    fmax = f[-1]
    # Mask: the response must stay out of the grey areas.
    kw = dict(color="0.8", alpha=0.6, lw=0)
    ax.fill_between([0, s["fs1"] / 1e3], -s["rs_db"], top, **kw)
    ax.fill_between([s["fs2"] / 1e3, fmax], -s["rs_db"], top, **kw)
    ax.fill_between([s["fp1"] / 1e3, s["fp2"] / 1e3], bottom, -s["rp_db"], **kw, label="spec mask")
    ax.set_xlim(0, fmax)
    ax.set_ylim(bottom, top)
    ax.set_xlabel("frequency (kHz)")
    ax.set_ylabel("|H(f)| (dB)")
    ax.set_title(data["title"])
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower center")
    fig.tight_layout()
    fig.savefig(sys.argv[2], format="png", dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
