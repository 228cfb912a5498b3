#!/usr/bin/python3
"""Plot the Pareto fronts of a `ranging sweep` (sweep.json -> PNG): cost against distance RMSE
and against decode errors; front points joined, the default configuration marked."""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(src, dst):
    doc = json.load(open(src))
    cost_name = doc.get("cost_for_front", "word_bits")
    ok = [p for p in doc["points"] if p["status"] == "ok"]

    def cost(p):
        ice = p["cost"].get("ice40", {})
        return ice["lut4"] if cost_name == "lut4" and "lut4" in ice else p["cost"]["word_bits"]

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, (metric, label, flag) in zip(axes, [
            (lambda p: (p["accuracy"]["distance_rmse_m"] or float("nan")) * 1e3, "distance RMSE (mm)", "pareto"),
            (lambda p: p["accuracy"]["decode_errors"], "decode errors", "pareto_errors")]):
        xs = [cost(p) for p in ok]
        ys = [metric(p) for p in ok]
        ax.scatter(xs, ys, s=18, color="0.6", label="points")
        front = sorted((cost(p), metric(p)) for p in ok if p.get(flag))
        if front:
            ax.plot([f[0] for f in front], [f[1] for f in front], "o-", color="C0", label="Pareto front")
        for p in ok:
            if p["default"]:
                ax.scatter([cost(p)], [metric(p)], marker="*", s=220, color="C3", zorder=5, label="default")
        ax.set_xlabel(cost_name + (" (yosys synth_ice40)" if cost_name == "lut4" else " (proxy, --no-synth)"))
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("sweep %s: %d points (%d refused)" % (doc["spec"]["name"], len(doc["points"]),
                                                       len(doc["points"]) - len(ok)))
    fig.tight_layout()
    fig.savefig(dst, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
