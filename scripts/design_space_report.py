#!/usr/bin/python3
"""The committed design-space study (issue 11 section 7): docs/results/design-space.{md,json,png}
from a `ranging sweep` (sweep.json), a `ranging wordlength` (wordlength.json) and the synthesis of
chosen points (scripts/design_space_synth.sh, one JSON object a line).

  scripts/design_space_report.py SWEEP.json WORDLENGTH.json SYNTH.jsonl OUT_PREFIX [SECONDS]

SECONDS: the sweep's wall time, for points per hour; POINTS:SECONDS when only POINTS of them were
timed (a resumed run's last leg). Accuracy tolerance for "the default's
accuracy": no decode error and RMSE <= 1.1 x the default's (as ranging wordlength)."""
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

UP5K = {"lc": 5280, "mac16": 8, "ebr": 30}
ECP5_25F = {"lut4": 24288, "mult18": 28, "ebr": 56}


def rmse(p):
    v = p["accuracy"]["distance_rmse_m"]
    return math.inf if v is None else v


def params(p):
    return ", ".join(f"{k}={v}" for k, v in sorted(p["params"].items())) or "(default)"


def main(sweep_path, wl_path, synth_path, prefix, seconds=None, timed_points=None):
    doc = json.load(open(sweep_path))
    wl = json.load(open(wl_path))
    synth = [json.loads(line) for line in open(synth_path) if line.strip()]
    pts = doc["points"]
    ok = [p for p in pts if p["status"] == "ok"]
    refused = [p for p in pts if p["status"] != "ok"]
    default = next(p for p in pts if p["default"])
    axes = doc["spec"]["axes"]
    cname = doc.get("cost_for_front", "word_bits")
    clabel = "iCE40 LUT4 (yosys synth_ice40 -dsp)" if cname == "lut4" else "word_bits (sum of the configured word lengths)"
    cshort = "LUT4" if cname == "lut4" else "word_bits"

    def cost(p):
        return p["cost"]["ice40"]["lut4"] if cname == "lut4" else p["cost"]["word_bits"]
    front = sorted((p for p in ok if p.get("pareto")), key=cost)
    front_e = sorted((p for p in ok if p.get("pareto_errors")), key=cost)
    d_rmse, d_err = rmse(default), default["accuracy"]["decode_errors"]
    fam = lambda p: p["params"].get("scene.excitation.family", "Gold4")  # noqa: E731
    # The default is a Gold4 receiver: it is compared with Gold4 points (M1 is another code set:
    # 7 codes of 7 chips against Gold4's 9 of 7: another system, shown on the fronts).
    dominators = [p for p in ok if p is not default and fam(p) == "Gold4" and cost(p) <= cost(default) and rmse(p) <= d_rmse
                  and (cost(p) < cost(default) or rmse(p) < d_rmse)]
    dominators.sort(key=lambda p: (rmse(p), cost(p)))
    tol = 1.1 * d_rmse
    as_good = [p for p in ok if fam(p) == "Gold4" and p["accuracy"]["decode_errors"] <= d_err and rmse(p) <= tol
               and p["cost"]["real_time"]]
    as_good.sort(key=lambda p: (cost(p), p["cost"]["bank_back_end_clocks_per_group"]))
    rt = sum(1 for p in ok if p["cost"]["real_time"])

    def channels(s):
        i, e = s["ice40"], s.get("ecp5")
        lc = i["lut4"]  # a logic cell holds one LUT4 and one DFF: LUT4 bounds the cells from below
        up = min(UP5K["lc"] // max(lc, 1), UP5K["mac16"] // max(i["mac16"], 1) if i["mac16"] else 99,
                 UP5K["ebr"] // max(i["ebr"], 1) if i["ebr"] else 99)
        if not e:  # not synthesized for ECP5
            return up, None
        ec = min(ECP5_25F["lut4"] // max(e["lut4"], 1), ECP5_25F["mult18"] // e["mult18"] if e["mult18"] else 99,
                 ECP5_25F["ebr"] // e["ebr"] if e["ebr"] else 99)
        return up, ec

    out = {"sweep": sweep_path, "spec": doc["spec"], "points": len(pts), "evaluated": len(ok),
           "refused": len(refused), "real_time_points": rt, "cost_for_front": cname,
           "default": default, "front": front, "front_errors": front_e,
           "default_on_front": bool(default.get("pareto")),
           "dominated_by": dominators[:3], "as_accurate_as_default": as_good[:10],
           "synthesis": [dict(s, channels={"up5k": channels(s)[0], "ecp5_25f": channels(s)[1]}) for s in synth],
           "wordlength": wl, "sweep_seconds": seconds,
           "points_per_hour": ((timed_points or len(pts)) * 3600.0 / seconds) if seconds else None,
           "timed_points": timed_points or len(pts)}
    json.dump(out, open(prefix + ".json", "w"), indent=1)

    fig, axs = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, (metric, label, fr) in zip(axs, [(lambda p: rmse(p) * 1e3, "distance RMSE (mm)", front),
                                             (lambda p: p["accuracy"]["decode_errors"], "decode errors", front_e)]):
        for fam, colour in (("Gold4", "tab:blue"), ("M1", "tab:orange")):
            sel = [p for p in ok if p["params"].get("scene.excitation.family", "Gold4") == fam]
            ax.scatter([cost(p) for p in sel], [metric(p) for p in sel], s=16, color=colour, alpha=0.6, label=fam)
        ax.plot([cost(p) for p in fr], [metric(p) for p in fr], "k-", lw=1, label="Pareto front")
        ax.scatter([cost(default)], [metric(default)], marker="*", s=160, color="red", label="default", zorder=5)
        ax.set_xlabel(clabel)
        ax.set_ylabel(label)
        if label.startswith("distance"):
            ax.set_yscale("log")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"design space: {len(ok)} points evaluated ({len(refused)} refused), fixed model")
    fig.tight_layout()
    fig.savefig(prefix + ".png", dpi=110)

    L = []
    a = default["accuracy"]
    L.append("# Design-space study (issue 11 section 7)\n")
    L.append(f"Spec `sweeps/design-space.yaml` (mode {doc['spec']['mode']}, seed {doc['spec'].get('seed')}), "
             f"scene `sweeps/design-space-scene.yaml` (the paper's Section 4 chain: 5 MS/s, 0.005 V rms, 12-bit "
             f"ADC at 5 V; 0.1-1.0 m in 0.1 m steps, 2 repeats), base `configs/default.yaml`, fixed model; "
             f"{len(pts)} points over {len(axes)} axes, {len(ok)} evaluated, {len(refused)} refused by the design "
             f"(recorded with their error), {rt} of the evaluated keep real time.\n")
    L.append("Axes: " + "; ".join(f"`{x['key']}` {x['values']}" for x in axes) + ".\n")
    L.append("Reproduce (the points per hour below were measured with this command):\n")
    sweep_cmd = ("nice -n 10 build/tool/ranging sweep sweeps/design-space.yaml --out out/design-space "
                 + ("--synth-targets " + ",".join(t for t in ("ice40", "ecp5", "xilinx") if default["cost"].get(t))
                    if cname == "lut4" else "--no-synth") + " --jobs 2")
    L.append("```sh\n" + sweep_cmd + "\n"
             "nice -n 10 build/tool/ranging wordlength sweeps/design-space-wordlength.yaml --out out/wordlength\n"
             "scripts/design_space_synth.sh out/synth default \"\" wordlength \"$(the joint result's KEY=VALUE list, "
             "table below)\" > out/synth.jsonl\n"
             "scripts/design_space_report.py out/design-space/sweep.json out/wordlength/wordlength.json "
             "out/synth.jsonl docs/results/design-space SECONDS\n```\n")
    if cname == "lut4":
        rtls = len({p["cost"]["ice40"].get("rtl_hash") for p in ok})
        L.append("**Cost on the fronts is measured**: iCE40 LUT4 from yosys `synth_ice40 -dsp` of every evaluated "
                 f"point's generated receiver top ({rtls} distinct RTLs, cached by hash), with SB_MAC16 and EBR beside "
                 "it and the ECP5 LUT4 / MULT18 from `synth_ecp5` where the run asked for it. Real time: the design's "
                 "rule (model/hw/realtime.hpp).\n")
    else:
        L.append("**Cost on the fronts is `word_bits`** (the sum of the configured word lengths), the sweep's proxy "
                 "without synthesis (`--no-synth`). The iCE40/ECP5 figures are measured by yosys for the points in "
                 "the synthesis table only. Real time: the design's rule (model/hw/realtime.hpp).\n")
    if seconds:
        tp = timed_points or len(pts)
        L.append(f"Speed: {tp} points in {seconds:.0f} s wall with `--jobs 2` on the shared 2-core machine"
                 + (" (the last leg of the resumed run; the points before it were evaluated by earlier legs and kept)"
                    if tp != len(pts) else "") + ": "
                 f"**{tp * 3600.0 / seconds:.0f} points per hour** "
                 + ("with synthesis (every distinct RTL through yosys for each target)" if cname == "lut4" else
                    "without synthesis") + ".\n")
    hdr = (f"| id | params | {cshort} | MAC16 | EBR | ECP5 LUT4 / MULT18 | word_bits | errors (wrong/missed/false) | RMSE mm | "
           "max mm | clk/sample needed / avail | real time | stable |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|")

    def row(p):
        q = p["accuracy"]
        r = "--" if q["distance_rmse_m"] is None else f"{q['distance_rmse_m'] * 1e3:.3f}"
        m = "--" if q["max_abs_error_m"] is None else f"{q['max_abs_error_m'] * 1e3:.3f}"
        st = p.get("stability", {}).get("stable")
        i = p["cost"].get("ice40") or {}
        e = p["cost"].get("ecp5")
        ec = f"{e['lut4']} / {e['mult18']}" if e else "--"
        return (f"| {p['id']} | {params(p)} | {cost(p)} | {i.get('mac16', '--')} | {i.get('ebr', '--')} | {ec} | "
                f"{p['cost']['word_bits']} | {q['decode_errors']} ({q['wrong_code']}/{q['missed']}/"
                f"{q['false_alarms']}) | {r} | {m} | {p['cost']['clocks_per_sample_needed']:.2f} / "
                f"{p['cost']['clocks_per_sample_available']} | {'yes' if p['cost']['real_time'] else 'NO'} | {st} |")
    L.append("## The default\n")
    L.append(hdr)
    L.append(row(default) + "\n")
    if default.get("pareto"):
        L.append(f"The default is **on** the ({cshort}, RMSE) front.\n")
    elif dominators:
        b = dominators[0]
        L.append(f"The default is **not** on the ({cshort}, RMSE) front: {len(dominators)} Gold4 points dominate it; "
                 f"the most accurate, {b['id']} ({params(b)}), has RMSE {rmse(b) * 1e3:.3f} mm vs "
                 f"{d_rmse * 1e3:.3f} mm ({(1 - rmse(b) / d_rmse) * 100:.0f} % lower) at {cshort} {cost(b)} vs "
                 f"{cost(default)}, {b['accuracy']['decode_errors']} decode errors vs {d_err}, real time: "
                 f"{'yes' if b['cost']['real_time'] else 'NO'}.\n")
    L.append(f"## Pareto front ({cshort}, RMSE)\n")
    L.append(hdr)
    L += [row(p) for p in front]
    L.append(f"\n## Pareto front ({cshort}, decode errors)\n")
    L.append(hdr)
    L += [row(p) for p in front_e]
    L.append(f"\n## Gold4 designs as accurate as the default (0 decode errors beyond the default's {d_err}, RMSE <= "
             f"{tol * 1e3:.3f} mm = 1.1 x), real time, cheapest first\n")
    L.append(hdr)
    L += [row(p) for p in as_good[:10]]
    if cname == "lut4" and as_good:
        b = as_good[0]
        up, ec = channels(b["cost"])
        i = b["cost"]["ice40"]
        L.append(f"\n**Smallest swept UP5K design with the default's accuracy**: {b['id']} ({params(b)}): {i['lut4']} LUT4, "
                 f"{i['mac16']} SB_MAC16, {i['ebr']} EBR against the default's {default['cost']['ice40']['lut4']} / "
                 f"{default['cost']['ice40']['mac16']} / {default['cost']['ice40']['ebr']}; {up} receive channel(s) on "
                 f"the UP5K" + (f", {ec} on an ECP5-25F" if ec is not None else "") + ".")
    L.append("\n## Synthesis of chosen points (yosys synth_ice40 -dsp, synth_ecp5 and synth_xilinx -family xc7 of receiver_top)\n")
    L.append("| point | overrides | iCE40 LUT4 | DFF | carry | SB_MAC16 | EBR | channels on UP5K | ECP5 LUT4 | FF | MULT18 | EBR | "
             "channels on ECP5-25F | Xilinx-7 LUT | FF | DSP48E1 | RAMB18 / 36 |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for s in out["synthesis"]:
        i, e, c = s["ice40"], s.get("ecp5") or {}, s["channels"]
        e = {k: e.get(k, "--") for k in ("lut4", "ff", "mult18", "ebr")}
        x = s.get("xilinx") or {}
        x = {k: x.get(k, "--") for k in ("lut", "ff", "dsp48", "ramb18", "ramb36")}
        c = {"up5k": c["up5k"], "ecp5_25f": "--" if c["ecp5_25f"] is None else c["ecp5_25f"]}
        L.append(f"| {s['name']} | {' '.join(s['set']) or '(default)'} | {i['lut4']} | {i['dff']} | {i['carry']} | "
                 f"{i['mac16']} | {i['ebr']} | {c['up5k']} | {e['lut4']} | {e['ff']} | {e['mult18']} | {e['ebr']} | "
                 f"{c['ecp5_25f']} | {x['lut']} | {x['ff']} | {x['dsp48']} | {x['ramb18']} / {x['ramb36']} |")
    L.append("\nChannels = min over LUT4 / 5280 logic cells, SB_MAC16 / 8, EBR / 30 (UP5K) and LUT4 / 24288, "
             "MULT18 / 28, EBR / 56 (ECP5-25F), receiver only (the system around it, UART and transmitter, not "
             "counted; LUT4 is a lower bound on logic cells). The paper's system has four pairs.\n")
    L.append("## Per-node minimal widths (`ranging wordlength`, Gold4, the study's scene)\n")
    L.append("| node | default | minimal alone | in the joint result |\n|---|---|---|---|")
    for n in wl.get("nodes", []):
        L.append(f"| {n['key']} | {n['base']} | {n['min']} | {n.get('joint', '')} |")
    jp = wl.get("joint_params")
    if jp is not None:
        L.append("\nJoint result (passes the tolerance jointly; docs/results/design-space-wordlength-config.yaml): "
                 + " ".join(f"{k}={v}" for k, v in (jp.items() if isinstance(jp, dict) else jp)) + ".")
        ws = [s for s in synth if s["name"] == "wordlength"]
        if ws and synth and synth[0]["name"] == "default":
            d0, w0 = synth[0]["ice40"], ws[0]["ice40"]
            cw = [x for x in out["synthesis"] if x["name"] == "wordlength"][0]["channels"]
            L.append(f"\n**Smallest UP5K design with the default's accuracy found**: this joint result, "
                     f"{w0['lut4']} LUT4 (logic cells >= that), {w0['mac16']} SB_MAC16, {w0['ebr']} EBR: "
                     f"{cw['up5k']} receive channel(s) on the UP5K"
                     + (f", {cw['ecp5_25f']} on an ECP5-25F" if cw["ecp5_25f"] is not None else
                        " (not synthesized for ECP5 in time; the default itself fits 4 on an ECP5-25F, table above)") + ".")
            L.append(f"\n**Proposed default**: the joint word lengths keep the default's accuracy (0 decode errors, "
                     f"RMSE within 1.1 x) at {w0['lut4']} LUT4 / {w0['mac16']} SB_MAC16 / {w0['ebr']} EBR against "
                     f"{d0['lut4']} / {d0['mac16']} / {d0['ebr']} ({(1 - w0['lut4'] / d0['lut4']) * 100:.0f} % fewer LUT4). "
                     "Not applied to configs/default.yaml here: the bitstream targets (place and route, timing, "
                     "the equivalence tests) must be re-checked first.")
    L.append("")
    import os
    large = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "generated", "large", "manifest.json")
    if os.path.exists(large):
        lr = json.load(open(large))["real_time"]
        L.append("## The large configuration\n")
        L.append("configs/large.yaml (DECIM 1, 524 taps, 90 MHz) is not a point of this sweep (its word lengths "
                 "and clock differ from the base in several keys at once); the real-time rule refuses it for the "
                 f"bitstream: {lr['summary']}.\n")
    L.append("## Notes\n")
    L.append("- `hardware.clock_hz` is the clocks-per-sample axis: the bandpass shares its multipliers over "
             "clock_hz / fs clocks (SAMPLE_CYCLES); the values are multiples of the 1.5 Mbaud UART's rate, "
             "because `ranging generate` (and so the synthesis of a point) refuses a clock the UART divider does "
             "not divide. Clocks above the UP5K's ~33 MHz Fmax are receivers for a faster part (ECP5 columns).")
    if cname != "lut4":
        L.append("- `word_bits` ignores the structure (taps, sections, sharing): the synthesis table is the measured cost "
                 "for the points it holds.")
    else:
        L.append("- LUT4 is yosys's count before place and route (nextpnr packs LUT4 and DFF into logic cells; the "
                 "bitstream of the default has 4328 LUT4 with the system around the receiver, docs/bitstream.md). "
                 "`--place` is not in this run.")
    L.append("- M1 (7 codes of 7 chips, m-sequence shifts) and Gold4 (9 Gold codes of 7 chips) are different code sets; the default "
             "(Gold4) is compared with Gold4 points only.")
    L.append("- The word-length minima hold on this one scene (greedy, monotone assumption, "
             "docs/design-space.md); a new default needs a margin check on more scenes.\n")
    L.append(f"## Refused points ({len(refused)})\n")
    reasons = {}
    for p in refused:
        e = p.get("error", "")
        key = e.split(" (with --set")[0]
        key = key.split(": ", 1)[-1][:110]
        reasons[key] = reasons.get(key, 0) + 1
    for k, v in sorted(reasons.items(), key=lambda kv: -kv[1]):
        L.append(f"- {v} x {k}")
    open(prefix + ".md", "w").write("\n".join(L) + "\n")


if __name__ == "__main__":
    t = sys.argv[5].split(":") if len(sys.argv) > 5 else None
    main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], float(t[-1]) if t else None,
         int(t[0]) if t and len(t) == 2 else None)
