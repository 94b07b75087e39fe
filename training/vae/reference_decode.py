#!/usr/bin/python3
"""Decodes seeded latent vectors with a saved PyTorch VAE (train.py --checkpoint) and prints one line per vector:
the latent coordinates, then the six decoded features, with 17 significant digits. The C++ decoder test compares
its own decoding of the same latents against these lines."""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vae  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--checkpoint", required=True)
    ap.add_argument("--count", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    model, _ = vae.load_checkpoint(args.checkpoint)
    rng = np.random.default_rng(args.seed)
    z = rng.standard_normal((args.count, model.latent)) * 1.5  # wider than the prior, to exercise the decoder
    out = vae.decode_numpy(model, z)
    for zi, fi in zip(z, out):
        print(" ".join(f"{v:.17g}" for v in list(zi) + list(fi)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
