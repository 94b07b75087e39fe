#!/usr/bin/python3
"""Where a saved VAE (train.py --checkpoint) loses: its observation parameters, and the fabrics of the training and
validation splits it finds least likely, each with the VAE's log-likelihood (defensive-mixture importance sampling,
K = 1,000, as in the table), the exact one of GMM K = 3 (fitted as train.py fits it) and whether a beta is positive.
Feature-space nats per fabric (docs/SAMPLER.md)."""
import argparse
import os
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gmm  # noqa: E402
import vae  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    vae.add_checkpoint_arguments(ap, REPO)
    ap.add_argument("--worst", type=int, default=6)
    args = ap.parse_args()
    torch.set_num_threads(1)
    model, state, x, tr, va = vae.load_for_evaluation(args)
    observation = state.get("observation", "gaussian")
    m, s = model.feature_mean.numpy(), model.feature_std.numpy()
    logdet = float(np.log(s).sum())
    mixture = gmm.GaussianMixture(3, iterations=200, seed=args.seed).fit((x[tr] - m) / s)
    print(f"{state['name']} ({observation} observation): scale sigma (standardised) "
          + " ".join(f"{v:.3f}" for v in torch.exp(model.log_sigma).detach().numpy()))
    if observation == "student":
        print("  degrees of freedom nu " + " ".join(f"{v:.2f}" for v in model.degrees_of_freedom().detach().numpy()))
    g = torch.Generator().manual_seed(1)
    for part, idx in (("train", tr), ("validation", va)):
        ll = model.log_likelihood(torch.as_tensor((x[idx] - m) / s), 1000, g).numpy() - logdet
        ll_gmm = mixture.log_likelihood((x[idx] - m) / s) - logdet
        d = ll - ll_gmm
        print(f"{part}: VAE mean {ll.mean():.3f} median {np.median(ll):.3f}; GMM-3 mean {ll_gmm.mean():.3f} "
              f"median {np.median(ll_gmm):.3f}; VAE better on {int((ll > ll_gmm).sum())} of {len(idx)}; "
              f"VAE - GMM-3 per fabric: mean {d.mean():.3f} +- {d.std(ddof=1) / np.sqrt(len(d)):.3f} (standard "
              f"error), median {np.median(d):.3f}")
        print("  fabric (index in split) | VAE | GMM-3 | positive beta")
        for i in np.argsort(ll)[:args.worst]:
            print(f"  {i:3d} | {ll[i]:9.2f} | {ll_gmm[i]:7.2f} | {'yes' if (x[idx[i], 3:] > 0).any() else 'no'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
