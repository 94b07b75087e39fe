#!/usr/bin/python3
"""How small the table's W1 can be: for each GMM of the table (fitted as train.py fits it), the W1 procedure of the
table run against 251 fresh draws of that same GMM instead of the 251 fabrics. The model is then exactly right, so
the result is the metric's finite-sample floor for a distribution like it; distances to the real data near or above
this floor cannot tell the models apart (docs/SAMPLER.md). Prints one line per K, about 10 s."""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fabrics  # noqa: E402
import gmm  # noqa: E402
import metrics  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--data", default=os.path.join(REPO, "sampler", "data", "fabrics618.csv"))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--generated", type=int, default=6000)
    ap.add_argument("--references", type=int, default=5, help="independent 251-point reference samples per model")
    args = ap.parse_args()
    x = fabrics.distinct_fabrics(args.data)
    tr, _ = fabrics.split(len(x), args.seed)
    m, s = x[tr].mean(0), x[tr].std(0)
    print(f"W1 of {args.generated} model draws against {len(x)} other draws of the same model "
          f"(mean +- std over {args.references} reference samples)")
    for k in range(3, 8):
        model = gmm.GaussianMixture(k, iterations=200, seed=args.seed).fit((x[tr] - m) / s)
        gen = model.sample(args.generated, np.random.default_rng(args.seed + 1)) * s + m
        values = [metrics.wasserstein_exact(gen, model.sample(len(x), np.random.default_rng(100 + r)) * s + m)[0]
                  for r in range(args.references)]
        print(f"GMM-{k}: {np.mean(values):.3f} +- {np.std(values):.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
