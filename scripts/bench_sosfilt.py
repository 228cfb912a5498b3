#!/usr/bin/env python3
"""Peer timing for scripts/bench.sh (a benchmark, not a test): scipy.signal.sosfilt (float64)
on the receiver's bandpass design, the same input as bench/bench_fixed_point (a 0.9 full-scale
200 kHz sine at 5 MS/s, 4096 samples) and a 1 M-sample version of it (call overhead
amortized). Prints "sosfilt_<n> <MS/s>" lines, process CPU time.

  scripts/bench_sosfilt.py SOS_JSON      (the output of `ranging filter --json`)
"""
import json
import sys
import time

import numpy as np
from scipy import signal


def rate(sos, x, budget=1.0):
    n = 0
    t0 = time.process_time()
    while time.process_time() - t0 < budget:
        signal.sosfilt(sos, x)
        n += len(x)
    return n / (time.process_time() - t0)


def main():
    with open(sys.argv[1]) as f:
        sos = np.array(json.load(f)["sos"], dtype=float)
    for n in (4096, 1 << 20):
        x = 0.9 * np.sin(2 * np.pi * 200e3 * np.arange(n) / 5e6)
        print(f"sosfilt_{n} {rate(sos, x) / 1e6:.2f}")
    print(f"sections {len(sos)}")


if __name__ == "__main__":
    main()
