#!/usr/bin/env python3
"""A long capture for the decode benchmark (scripts/bench.sh): a periodic train that
`ranging simulate --write-captures` wrote (WAV, float32, with its sidecar JSON), tiled to N
samples (its second cycle, repeated). The train is cut to a whole number of periods of eta bursts, so the tiled file keeps the
schedule (codes 1..eta every period_s) that its metadata states.

  make_long_capture.py TRAIN.wav N OUT.wav [ETA]   (writes OUT.wav and OUT.json)
  make_long_capture.py TRAIN.wav N OUT.csv [ETA]   (the same samples as an oscilloscope CSV:
                                                    TIME,CH1 then rows '%.9e,%.9e', 32 bytes each)
"""
import json
import sys

import numpy as np


def read_wav_float(path):
    b = open(path, "rb").read()
    assert b[:4] == b"RIFF" and b[8:12] == b"WAVE", path
    at, rate, data = 12, None, None
    while at + 8 <= len(b):
        cid, size = b[at:at + 4], int.from_bytes(b[at + 4:at + 8], "little")
        if cid == b"fmt ":
            fmt, rate, bits = (int.from_bytes(b[at + 8:at + 10], "little"), int.from_bytes(b[at + 12:at + 16], "little"),
                               int.from_bytes(b[at + 22:at + 24], "little"))
            assert fmt == 3 and bits == 32, "float32 WAV expected"
        elif cid == b"data":
            data = np.frombuffer(b[at + 8:at + 8 + size], dtype="<f4")
            break
        at += 8 + size + (size & 1)
    return rate, data


def main():
    src, n, out = sys.argv[1], int(float(sys.argv[2])), sys.argv[3]
    rate, x = read_wav_float(src)
    meta = json.load(open(src[:-4] + ".json"))
    period = meta["period_s"]
    eta = int(sys.argv[4]) if len(sys.argv) > 4 else 15
    cycle = int(round(period * rate)) * eta
    # The second cycle: every burst of it arrived (the first starts with the propagation delay's
    # silence) and it carries the ring-down of the previous cycle, as a steady train does.
    assert len(x) >= 2 * cycle, f"the train holds {len(x)} samples, fewer than two cycles of {eta} bursts ({cycle})"
    one = x[cycle:2 * cycle]
    if out.endswith(".csv"):
        write_csv(out, one, n, rate)
    else:
        write_wav(out, one, n, rate)
    meta.pop("true_distance_m", None)
    meta["code_sent"] = 0
    json.dump(meta, open(out[:-4] + ".json", "w"), indent=2)


def write_csv(out, one, n, rate):
    with open(out, "w") as f:
        f.write("TIME,CH1\n")
        for at in range(0, n, 1 << 18):
            k = min(n - at, 1 << 18)
            i = np.arange(at, at + k)
            v = one[i % len(one)].astype(np.float64)
            f.write("".join(f"{t:.9e},{y:.9e}\n" for t, y in zip(i / rate, v)))


def write_wav(out, one, n, rate):
    with open(out, "wb") as f:
        f.write(b"RIFF" + (36 + 4 * n).to_bytes(4, "little") + b"WAVEfmt " + (16).to_bytes(4, "little"))
        f.write((3).to_bytes(2, "little") + (1).to_bytes(2, "little") + rate.to_bytes(4, "little"))
        f.write((4 * rate).to_bytes(4, "little") + (4).to_bytes(2, "little") + (32).to_bytes(2, "little"))
        f.write(b"data" + (4 * n).to_bytes(4, "little"))
        left = n
        while left > 0:
            k = min(left, len(one))
            f.write(one[:k].astype("<f4").tobytes())
            left -= k


if __name__ == "__main__":
    main()
