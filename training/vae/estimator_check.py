#!/usr/bin/python3
"""Compares log-likelihood estimators on the validation fabrics a saved VAE (train.py --checkpoint) finds least
likely: plain IWAE (draws from q(z|x)) with K = 1,000 and 100,000 against the defensive-mixture importance sampling
of VAE.log_likelihood with K = 1,000 and 100,000. Feature-space nats per fabric (docs/SAMPLER.md)."""
import argparse
import os
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vae  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    vae.add_checkpoint_arguments(ap, REPO)
    ap.add_argument("--worst", type=int, default=3)
    args = ap.parse_args()
    torch.set_num_threads(1)
    model, state, x, tr, va = vae.load_for_evaluation(args)
    m, s = model.feature_mean.numpy(), model.feature_std.numpy()
    logdet = float(np.log(s).sum())
    sv = torch.as_tensor((x[va] - m) / s)
    g = torch.Generator().manual_seed(1)
    base = model.log_likelihood(sv, 1000, g).numpy() - logdet
    print("fabric (validation index) | IWAE K=1e3 | IWAE K=1e5 | mixture K=1e3 | mixture K=1e5")
    for i in np.argsort(base)[:args.worst]:
        row = [model.iw_log_likelihood(sv[i:i + 1], k, g).item() - logdet for k in (1000, 100000)]
        row += [model.log_likelihood(sv[i:i + 1], k, g).item() - logdet for k in (1000, 100000)]
        print(f"{i:3d} | " + " | ".join(f"{v:8.2f}" for v in row))
    return 0


if __name__ == "__main__":
    sys.exit(main())
