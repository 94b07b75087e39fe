#!/usr/bin/python3
"""Trains the parameter-subspace candidates of the paper's Table 1 (VAE-1..4, GMM K = 3..7) on the measured fabrics,
evaluates them, and exports the chosen VAE for the C++ sampler.

Metrics (docs/SAMPLER.md):
- log-likelihood: mean (and median) over distinct fabrics of log p(x), nats per fabric, in feature space
  x = sign(k) ln|k| of the six moduli normalised to 300 g/m^2. GMM: exact. VAE: importance sampling with K draws from
  the defensive mixture 1/3 q(z|x) + 1/3 q(z|x) widened 3x + 1/3 N(0, I), each part weighted by its share of the K
  draws (vae.VAE.log_likelihood); the plain IWAE estimate (K draws from q(z|x)) of the validation set is recorded
  too.
- VAE training: early stopping by the median log-likelihood of a tenth of the training fabrics (the "stop" set),
  never on the validation set.
- Wasserstein: exact W1 with Euclidean cost in the same feature space, between the distinct fabrics (train and
  validation) and 6,000 generated vectors, as the mean over the disjoint chunks of generated vectors of the size of
  the data (scipy.optimize.linear_sum_assignment). VAE vectors are decoder means (as the sampler uses them).
"""
import argparse
import json
import os
import sys
import time

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import export  # noqa: E402
import fabrics  # noqa: E402
import gmm  # noqa: E402
import metrics  # noqa: E402
import vae  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
DEFAULT_DATA = os.path.join(REPO, "sampler", "data", "fabrics618.csv")


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def evaluate_vae(model, x, tr, va, m, s, iw_samples, seed, generated):
    logdet = float(np.log(s).sum())
    g = torch.Generator().manual_seed(seed)
    res = {}
    for name, idx in (("train", tr), ("validation", va), ("all", np.arange(len(x)))):
        ll = model.log_likelihood(torch.as_tensor((x[idx] - m) / s), iw_samples, g).numpy() - logdet
        res[f"ll_{name}"] = float(ll.mean())
        res[f"ll_{name}_median"] = float(np.median(ll))
    iwae = model.iw_log_likelihood(torch.as_tensor((x[va] - m) / s), iw_samples, g).numpy() - logdet
    res["ll_validation_iwae"] = float(iwae.mean())
    rng = np.random.default_rng(seed + 1)
    prior = vae.decode_numpy(model, vae.prior_latents(generated, model.latent, rng))
    wide = vae.decode_numpy(model, vae.widened_latents(generated, model.latent, rng))
    res["w_prior"], res["w_prior_std"], res["w_chunks"] = metrics.wasserstein_exact(prior, x)
    res["w_widened"], res["w_widened_std"], _ = metrics.wasserstein_exact(wide, x)
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default=DEFAULT_DATA)
    ap.add_argument("--seed", type=int, default=0, help="split, initialisation, batches and evaluation")
    ap.add_argument("--models", default="GMM-3,GMM-4,GMM-5,GMM-6,GMM-7,VAE-1,VAE-2,VAE-3,VAE-4")
    ap.add_argument("--epochs", type=int, default=20000)
    ap.add_argument("--iw-samples", type=int, default=1000)
    ap.add_argument("--generated", type=int, default=6000)
    ap.add_argument("--results", default=None, help="write the metrics as JSON here")
    ap.add_argument("--export", default=None, help="NAME=PATH: export this VAE to the drapegen model format")
    ap.add_argument("--checkpoint", default=None, help="save the exported VAE's PyTorch state here")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--check-every", type=int, default=500, help="epochs between early-stopping checks")
    ap.add_argument("--observation", choices=vae.OBSERVATIONS, default="gaussian",
                    help="VAE observation model: Gaussian or Student-t (per-feature scale and degrees of freedom)")
    ap.add_argument("--lr", type=float, default=1e-4, help="Adam learning rate (the paper's 1e-4)")
    ap.add_argument("--lr-final", type=float, default=None, help="cosine decay of the learning rate to this value")
    ap.add_argument("--kl-warmup", type=int, default=0, help="epochs of linear KL weight warm-up from 0 to 1")
    ap.add_argument("--criterion", choices=("median", "mean"), default="median",
                    help="early-stopping statistic of the stop set's log-likelihoods")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)

    try:
        x = fabrics.distinct_fabrics(args.data)
    except fabrics.DataError as e:
        log(f"train.py: error: {e}")
        return 1
    tr, va = fabrics.split(len(x), args.seed)
    m, s = x[tr].mean(0), x[tr].std(0)
    logdet = float(np.log(s).sum())
    export_name, _, export_path = (args.export.partition("=") if args.export else (None, None, None))
    # Checked before any training: a request that would be dropped, or a path found unwritable only afterwards.
    names = args.models.split(",")

    def known(name):
        if name in vae.ARCHITECTURES:
            return True
        k = name[4:] if name.startswith("GMM-") else ""
        return k.isdigit() and int(k) >= 1

    unknown = [n for n in names if not known(n)]
    if args.generated < len(x):
        log(f"train.py: error: --generated {args.generated}: the coverage metric needs at least one draw per "
            f"distinct fabric ({len(x)})")
        return 1
    if unknown:
        log(f"train.py: error: unknown model(s) {', '.join(unknown)} (GMM-K with K >= 1, or one of "
            f"{', '.join(vae.ARCHITECTURES)})")
        return 1
    if args.export and (not export_path or export_name not in vae.ARCHITECTURES or export_name not in names):
        log(f"train.py: error: --export NAME=PATH needs NAME to be a VAE in --models ({args.export!r})")
        return 1
    if args.checkpoint and not args.export:
        log("train.py: error: --checkpoint saves the exported VAE: it needs --export")
        return 1
    for path in (export_path, args.checkpoint, args.results):
        if path and not os.access(os.path.dirname(os.path.abspath(path)), os.W_OK):
            log(f"train.py: error: cannot write {path}: its directory is missing or not writable")
            return 1
    log(f"{len(x)} distinct fabrics: {len(tr)} train, {len(va)} validation (seed {args.seed})")
    results = {"seed": args.seed, "epochs": args.epochs, "iw_samples": args.iw_samples,
               "generated": args.generated, "distinct_fabrics": len(x), "train": len(tr), "validation": len(va),
               "models": {}}
    for name in names:
        t0 = time.time()
        if name.startswith("GMM-"):
            k = int(name[4:])
            model = gmm.GaussianMixture(k, iterations=200, seed=args.seed).fit((x[tr] - m) / s)
            res = {}
            for part, idx in (("train", tr), ("validation", va), ("all", np.arange(len(x)))):
                ll = model.log_likelihood((x[idx] - m) / s) - logdet
                res[f"ll_{part}"] = float(ll.mean())
                res[f"ll_{part}_median"] = float(np.median(ll))
            gen = model.sample(args.generated, np.random.default_rng(args.seed + 1)) * s + m
            res["w_prior"], res["w_prior_std"], res["w_chunks"] = metrics.wasserstein_exact(gen, x)
        else:
            hidden, latent = vae.ARCHITECTURES[name]
            model, chosen, fit_count, stop_count = vae.fit(
                name, x[tr], m, s, args.seed, args.epochs, args.observation, args.check_every, log, lr=args.lr,
                lr_final=args.lr_final, kl_warmup=args.kl_warmup, criterion=args.criterion)
            model.eval()
            res = evaluate_vae(model, x, tr, va, m, s, args.iw_samples, args.seed, args.generated)
            if name == export_name:
                export.write_model(model, x.min(0), x.max(0), export_path)
                log(f"  exported {name} to {export_path}")
                if args.checkpoint:
                    torch.save({"name": name, "hidden": hidden, "latent": latent, "observation": args.observation,
                                "state_dict": model.state_dict()},
                               args.checkpoint)
        res["seconds"] = round(time.time() - t0, 1)
        if not name.startswith("GMM-"):
            res["epochs"] = args.epochs
            res["chosen_epoch"] = chosen
            res["fit_fabrics"], res["stop_fabrics"] = fit_count, stop_count
            res["training"] = {"observation": args.observation, "lr": args.lr, "lr_final": args.lr_final,
                               "kl_warmup": args.kl_warmup, "criterion": args.criterion}
        results["models"][name] = res
        log(f"{name}: " + ", ".join(f"{k} {v:.3f}" if isinstance(v, float) else f"{k} {v}" for k, v in res.items()))
        if args.results:  # after every model, so a long run keeps what it has
            with open(args.results, "w") as f:
                json.dump(results, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
