#!/usr/bin/python3
"""Independent oracle of the paper's Pearson matched filter for tests/test_metrics.cpp.

Usage: pearson_lags_oracle.py FILE LO HI
FILE is JSON {"x": [...], "templates": [[...], ...]}. For every template t (N samples) prints
the largest Pearson coefficient numpy.corrcoef(x[k:k+N], t)[0, 1] over the lags k in [LO, HI]
whose segment lies inside x, and its k (the first on ties), as JSON
{"best": [{"rho": r, "lag": k}, ...]}. Exits non-zero if numpy is missing, so the C++ test
fails rather than skips.
"""
import json
import sys

try:
    import numpy as np
except ImportError as e:  # the test must fail, not skip
    print(f"pearson_lags_oracle.py: cannot import numpy: {e}", file=sys.stderr)
    sys.exit(3)


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    with open(sys.argv[1]) as f:
        data = json.load(f)
    lo, hi = int(sys.argv[2]), int(sys.argv[3])
    x = np.asarray(data["x"], dtype=float)
    best = []
    for t in data["templates"]:
        t = np.asarray(t, dtype=float)
        n = len(t)
        ks = range(max(lo, 0), min(hi, len(x) - n) + 1)
        rhos = [np.corrcoef(x[k:k + n], t)[0, 1] for k in ks]
        i = int(np.argmax(rhos))
        best.append({"rho": float(rhos[i]), "lag": int(ks[i])})
    print(json.dumps({"best": best}))


if __name__ == "__main__":
    main()
