#!/usr/bin/python3
"""Reference bandpass designs from scipy.signal for tests/test_filter_design.cpp.

Usage: filter_oracle.py FP1 FP2 FS1 FS2 RP RS FS   (Hz, dB, Hz)
Prints JSON: for each of butter, cheby1, ellip the minimum order and natural frequencies
(scipy buttord / cheb1ord / ellipord, analog=False) and the complex response of
butter / cheby1 / ellip(output='sos') (sosfreqz) at the listed frequencies: a uniform grid
over [0, fs/2] plus a dense grid around the band. Exits non-zero if scipy is missing, so
the C++ test fails rather than skips.
"""
import json
import sys

try:
    import numpy as np
    from scipy import signal
except ImportError as e:  # the test must fail, not skip
    print(f"filter_oracle.py: cannot import scipy/numpy: {e}", file=sys.stderr)
    sys.exit(3)


def main():
    if len(sys.argv) != 8:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    fp1, fp2, fs1, fs2, rp, rs, fs = (float(a) for a in sys.argv[1:])
    wp, ws = [fp1, fp2], [fs1, fs2]
    freqs = np.concatenate([
        np.linspace(0.0, fs / 2, 201),
        np.linspace(0.5 * fs1, min(1.5 * fs2, fs / 2), 200),
    ])
    out = {"freqs": freqs.tolist(), "designs": {}}
    designs = {
        "butter": (signal.buttord, lambda n, wn: signal.butter(n, wn, "bandpass", output="sos", fs=fs)),
        "cheby1": (signal.cheb1ord, lambda n, wn: signal.cheby1(n, rp, wn, "bandpass", output="sos", fs=fs)),
        "ellip": (signal.ellipord, lambda n, wn: signal.ellip(n, rp, rs, wn, "bandpass", output="sos", fs=fs)),
    }
    for name, (order_fn, design_fn) in designs.items():
        n, wn = order_fn(wp, ws, rp, rs, analog=False, fs=fs)
        sos = design_fn(n, wn)
        _, h = signal.sosfreqz(sos, worN=freqs, fs=fs)
        out["designs"][name] = {
            "order": int(n),
            "wn": [float(w) for w in np.atleast_1d(wn)],
            "re": h.real.tolist(),
            "im": h.imag.tolist(),
        }
    json.dump(out, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
