#!/usr/bin/python3
"""An independent channel simulator (not the project's) for tests/test_foreign_captures.cpp.

Usage: foreign_channel.py OUTDIR FAMILY SEED
Writes captures of every code of FAMILY (M1 or Gold4; codes generated here from the paper's
rules: M1-1 = [1,0,1,1,1,0,0], M2-1 = [1,0,1,0,0,1,1], M family codes are cyclic left shifts,
Gold1 = [M1-1, M2-1, M1-1 xor shift^k(M2-1) for k = 0..6], Gold i = Gold1 shifted left by i-1)
through transducers unlike the project's model:
  - BPSK excitation, 200 kHz carrier, 4 cycles per chip, 5 MS/s (chip 1: +sin, chip 0: -sin);
  - TX resonator Q 7, RX resonator Q 9 (scipy.signal.iirpeak at 200 kHz);
  - ISO-like air absorption alpha(f) = 6.5 dB/m * (f / 200 kHz)^1.7 and the propagation delay
    d/c, c = 347 m/s, both applied exactly in the frequency domain (zero-phase magnitude);
  - spherical spreading 0.1/d; white Gaussian noise at an SNR drawn from 14-26 dB (signal mean
    square over the samples above a tenth of its peak / noise variance).
Each capture is written as a Tektronix-like CSV (header lines, TIME,CH1 rows) and a 16-bit PCM
WAV, no metadata: OUTDIR/<FAMILY>_j<J>.csv|.wav at the distances listed in OUTDIR/truth.json
({"c": 347, "captures": [{"stem": ..., "code": j, "distance_m": d, "snr_db": s}, ...],
"calibration": {"stem": ..., "distance_m": 0.2, "period_s": T}}). The calibration capture
is a train of every code, one every T = 0.6 ms, at 0.2 m (its sidecar JSON gives period_s).
Exits non-zero if numpy/scipy are missing, so the C++ test fails rather than skips.
"""
import json
import os
import sys

try:
    import numpy as np
    from scipy import signal
    from scipy.io import wavfile
except ImportError as e:  # the test must fail, not skip
    print(f"foreign_channel.py: cannot import numpy/scipy: {e}", file=sys.stderr)
    sys.exit(3)

FS = 5e6
F0 = 200e3
Q_CYCLES = 4
C = 347.0


def codes(family):
    m1 = [1, 0, 1, 1, 1, 0, 0]
    m2 = [1, 0, 1, 0, 0, 1, 1]
    shift = lambda v, k: v[k:] + v[:k]
    if family == "M1":
        return [shift(m1, k) for k in range(7)]
    if family == "Gold4":
        g1 = [m1, m2] + [[a ^ b for a, b in zip(m1, shift(m2, k))] for k in range(7)]
        return [shift(c, 3) for c in g1]
    raise SystemExit(f"foreign_channel.py: unknown family {family}")


def excitation(code):
    n = int(Q_CYCLES * FS / F0)
    t = np.arange(n) / FS
    chip = np.sin(2 * np.pi * F0 * t)
    return np.concatenate([chip if b else -chip for b in code])


def channel(x, d, total):
    b, a = signal.iirpeak(F0, 7.0, FS)
    y = signal.lfilter(b, a, np.concatenate([x, np.zeros(3000)]))
    b, a = signal.iirpeak(F0, 9.0, FS)
    y = signal.lfilter(b, a, y)
    n = 1 << int(np.ceil(np.log2(total + len(y))))
    f = np.fft.rfftfreq(n, 1 / FS)
    alpha_db = 6.5 * (f / F0) ** 1.7 * d
    h = 10 ** (-alpha_db / 20) * np.exp(-2j * np.pi * f * d / C) * (0.1 / d)
    return np.fft.irfft(np.fft.rfft(y, n) * h, n)[:total]


def add_noise(y, snr_db, rng):
    peak = np.max(np.abs(y))
    active = y[np.abs(y) > peak / 10]
    sigma = np.sqrt(np.mean(active ** 2) / 10 ** (snr_db / 10))
    return y + rng.normal(0.0, sigma, len(y))


def write(stem, y):
    with open(stem + ".csv", "w") as fh:
        fh.write("Model,foreign scope\nRecord Length,%d\nSample Interval,%.9e\nTIME,CH1\n" % (len(y), 1 / FS))
        for i, v in enumerate(y):
            fh.write("%.9e,%.9e\n" % (i / FS, v))
    full = 1.25 * np.max(np.abs(y))
    wavfile.write(stem + ".wav", int(FS), np.round(y / full * 32767).astype(np.int16))


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    out, family, seed = sys.argv[1], sys.argv[2], int(sys.argv[3])
    os.makedirs(out, exist_ok=True)
    rng = np.random.default_rng(seed)
    cs = codes(family)
    truth = {"c": C, "family": family, "captures": []}
    total = 20000
    for j, code in enumerate(cs, start=1):
        d = float(np.round(rng.uniform(0.3, 1.0), 3))
        snr = float(np.round(rng.uniform(14, 26), 1))
        y = add_noise(channel(excitation(code), d, total), snr, rng)
        stem = os.path.join(out, f"{family}_j{j}")
        write(stem, y)
        truth["captures"].append({"stem": stem, "code": j, "distance_m": d, "snr_db": snr})
    # Calibration: every code in turn, one every 0.6 ms, at 0.2 m, 26 dB.
    period, dcal = 0.6e-3, 0.2
    n = int(round(period * FS))
    cal = np.zeros(n * len(cs) + 12000)
    for k, code in enumerate(cs):
        y = channel(excitation(code), dcal, len(cal) - k * n)
        cal[k * n:] += y
    cal = add_noise(cal, 26.0, rng)
    stem = os.path.join(out, f"{family}_calibration")
    write(stem, cal)
    with open(stem + ".json", "w") as fh:
        json.dump({"period_s": period}, fh)
    truth["calibration"] = {"stem": stem, "distance_m": dcal, "period_s": period}
    with open(os.path.join(out, "truth.json"), "w") as fh:
        json.dump(truth, fh, indent=1)


if __name__ == "__main__":
    main()
