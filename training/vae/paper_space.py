#!/usr/bin/python3
"""Tests one explanation of the paper's VAE-GMM gap (docs/SAMPLER.md, "Where the paper's gap may come from"): that its
GMMs were fitted on the raw (standardised) normalised moduli k, not on the sign-log features x = sign(k) ln|k| its
VAE uses. On the table's split (seed 0: 201 train / 50 validation distinct fabrics) it fits GMM K = 3..7 as train.py
does (gmm.GaussianMixture: full covariances, EM 200 iterations, k-means++-style seeding with the split seed,
regularisation 1e-6 in standardised units) once on the sign-log features ("sign-log GMM", the table's models) and once
on the raw normalised moduli standardised by the training split's mean and std ("raw GMM"), and evaluates them and the
committed VAE-3 (training/vae/models/vae3.pt) in two common spaces:

- validation log-likelihood, nats per fabric, mean (median) over the 50 validation fabrics (also "own space": each
  model in the standardised space it was fitted in, i.e. log p_u for the raw GMMs, which is not a common space):
  in sign-log space (the table's space) and in standardised raw space u = (k - m_k) / s_k (m_k, s_k of the training
  split). Change of variables, per feature dk/dx = |k| = exp|x|:
      log p_x(x) = log p_u(u) - sum log s_k + sum ln|k|.
  GMMs: exact. VAE-3: the table's estimator (defensive-mixture importance sampling, K = 1,000 draws, torch generator
  seeded with --seed and used for the training then the validation fabrics as train.py does, so the sign-log
  validation figure equals the table's), mapped by the same Jacobian.
- W1: the table's procedure (metrics.wasserstein_exact: 6,000 generated vectors cut into 23 chunks of 251, each matched
  to the 251 distinct fabrics by an optimal assignment, mean +- std over chunks), once in sign-log space and once in
  the raw moduli standardised by the mean and std of all 251 distinct fabrics. The same generated vectors in both
  spaces: VAE-3 decoder means of prior latents N(0, I) (numpy generator seed + 1, as train.py), GMM mixture draws
  (numpy generator seed + 1, as train.py), each mapped to the other space by k = sign(x) exp|x| or x = sign(k) ln|k|.
- W1 with the sampler's rejection (a sensitivity check): the same, but from 4 x 6,000 candidates drawn the same way
  (same generator seeds) the first 6,000 inside the measured fabrics' sign-log range widened by 10% of its width per
  side and with every alpha > 0 (the C++ sampler's rule, docs/SAMPLER.md "Sampling"); "accepted" is their fraction.
  Its "floor": the same W1 against 251 fresh accepted draws of the model itself (--references samples, generator seeds
  100, 101, ...), what an exactly right model of that kind would reach (as w1_floor.py).
- VAE-3 "+noise" (sensitivity check): the full generative model, decoder mean plus the learned Student-t observation
  noise; its log-likelihood is VAE-3's.

Deterministic from --seed (one thread). Writes results.json and table.txt into --out; about 20 s.
"""
import argparse
import json
import os
import sys

import numpy as np
import torch
from scipy.special import ndtr

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fabrics  # noqa: E402
import gmm  # noqa: E402
import metrics  # noqa: E402
import vae  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
PAPER = {"VAE-3": (-6.42, 11.1), "GMM-5": (-13.61, 72.6), "GMM-3": (-14.86, 98.9), "GMM-4": (-13.88, 84.6),
         "GMM-6": (-15.71, 72.5), "GMM-7": (-15.79, 97.6)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    vae.add_checkpoint_arguments(ap, REPO)
    ap.add_argument("--iw-samples", type=int, default=1000)
    ap.add_argument("--generated", type=int, default=6000)
    ap.add_argument("--components", default="3,4,5,6,7")
    ap.add_argument("--references", type=int, default=5, help="reference samples of the W1 floor")
    ap.add_argument("--out", default=os.path.join(REPO, "training", "vae", "results", "paper_space"))
    args = ap.parse_args()
    torch.set_num_threads(1)

    x = fabrics.distinct_fabrics(args.data)
    k = fabrics.from_features(x)
    tr, va = fabrics.split(len(x), args.seed)
    # sign-log standardisation (train.py) and raw standardisation, both by the training split
    mx, sx = x[tr].mean(0), x[tr].std(0)
    mk, sk = k[tr].mean(0), k[tr].std(0)
    # the W1 space of raw moduli: standardised by all 251 distinct fabrics
    mk_all, sk_all = k.mean(0), k.std(0)
    log_jac = np.abs(x).sum(1)  # sum ln|k| = log |dk/dx| per fabric
    log_sk, log_sx = float(np.log(sk).sum()), float(np.log(sx).sum())

    width = x.max(0) - x.min(0)
    lo, hi = x.min(0) - 0.1 * width, x.max(0) + 0.1 * width

    def rejected_sample(draw):
        """The first `generated` of 4x as many candidates (sign-log vectors from draw(n)) that the sampler keeps."""
        cand = draw(4 * args.generated)
        keep = np.all((cand >= lo) & (cand <= hi), axis=1) & np.all(fabrics.from_features(cand)[:, :3] > 0, axis=1)
        if keep.sum() < args.generated:
            raise RuntimeError("too few accepted candidates")
        return cand[keep][:args.generated], float(keep.mean())

    def w1_both(gen_x):
        gen_k = fabrics.from_features(gen_x)
        w_x = metrics.wasserstein_exact(gen_x, x)
        w_k = metrics.wasserstein_exact((gen_k - mk_all) / sk_all, (k - mk_all) / sk_all)
        return w_x, w_k

    def ll_summary(ll):
        return {"mean": float(ll.mean()), "median": float(np.median(ll))}

    def floor(draw_factory):
        """W1 of the accepted generated vectors against 251 fresh accepted draws of the same model, in both spaces
        (mean over --references reference samples): the value an exactly right model would reach."""
        gen, _ = rejected_sample(draw_factory(np.random.default_rng(args.seed + 1)))
        fx, fk = [], []
        for r in range(args.references):
            ref_x = rejected_sample(draw_factory(np.random.default_rng(100 + r)))[0][:len(x)]
            ref_k = (fabrics.from_features(ref_x) - mk_all) / sk_all
            fx.append(metrics.wasserstein_exact(gen, ref_x)[0])
            fk.append(metrics.wasserstein_exact((fabrics.from_features(gen) - mk_all) / sk_all, ref_k)[0])
        return [float(np.mean(fx)), float(np.std(fx))], [float(np.mean(fk)), float(np.std(fk))]

    def evaluate(space, draw_factory, ll_v, ll_t, own_shift):
        """ll_v, ll_t: sign-log log-likelihoods of the validation and training fabrics; draw_factory(rng) gives
        draw(n), n sign-log vectors from the model."""
        gen_x = draw_factory(np.random.default_rng(args.seed + 1))(args.generated)
        (wx, wxs, ch), (wk, wks, _) = w1_both(gen_x)
        acc_x, acc = rejected_sample(draw_factory(np.random.default_rng(args.seed + 1)))
        rej = w1_both(acc_x)
        fx, fk = floor(draw_factory)
        gen_k = fabrics.from_features(gen_x)
        return {"space": space,
                "ll_validation_signlog": ll_summary(ll_v),
                "ll_validation_rawstd": ll_summary(ll_v - log_jac[va] + log_sk),
                "ll_train_signlog": ll_summary(ll_t),
                "ll_validation_own_space": ll_summary(ll_v + own_shift),
                "w1_signlog": [wx, wxs], "w1_rawstd": [wk, wks], "w1_chunks": ch,
                "generated_alpha_at_most_1": int((gen_x[:, :3] <= 0).any(1).sum()),
                "generated_positive_beta": int((gen_k[:, 3:] > 0).any(1).sum()),
                "rejection": {"accepted": acc, "w1_signlog": [rej[0][0], rej[0][1]],
                              "w1_rawstd": [rej[1][0], rej[1][1]], "floor_signlog": fx, "floor_rawstd": fk}}

    rows = {}
    # VAE-3, committed: decoder means of prior latents (as the sampler and the table), and, as a sensitivity check,
    # the full generative model (decoder mean plus the learned Student-t observation noise)
    model, state = vae.load_checkpoint(args.checkpoint)
    vae.check_split(model, x, tr)
    g = torch.Generator().manual_seed(args.seed)
    with torch.no_grad():
        ll_x = {part: model.log_likelihood(torch.as_tensor((x[idx] - mx) / sx), args.iw_samples, g).numpy() - log_sx
                for part, idx in (("train", tr), ("validation", va))}
        sigma = torch.exp(model.log_sigma).numpy()
        nu = model.degrees_of_freedom().numpy() if model.observation == "student" else None

    def vae_means(rng):
        return lambda n: vae.decode_numpy(model, vae.prior_latents(n, model.latent, rng))

    def vae_full(rng):
        def draw(n):
            mean = vae.decode_numpy(model, vae.prior_latents(n, model.latent, rng))
            noise = rng.standard_t(nu, (n, len(nu))) if nu is not None else rng.standard_normal((n, len(sigma)))
            return mean + noise * sigma * sx
        return draw

    rows["VAE-3"] = evaluate("sign-log (VAE; decoder means)", vae_means, ll_x["validation"], ll_x["train"],
                             log_sx)
    rows["VAE-3 +noise"] = evaluate("sign-log (VAE; with obs. noise)", vae_full, ll_x["validation"], ll_x["train"],
                                    log_sx)

    for K in [int(c) for c in args.components.split(",")]:
        # sign-log GMM, exactly as train.py
        m1 = gmm.GaussianMixture(K, iterations=200, seed=args.seed).fit((x[tr] - mx) / sx)
        rows[f"GMM-{K} sign-log"] = evaluate(
            "sign-log", lambda rng, m1=m1: (lambda n: m1.sample(n, rng) * sx + mx),
            m1.log_likelihood((x[va] - mx) / sx) - log_sx, m1.log_likelihood((x[tr] - mx) / sx) - log_sx, log_sx)
        # raw GMM: the same EM on the standardised raw moduli; log p_x = log p_u - sum log s_k + sum ln|k|
        m2 = gmm.GaussianMixture(K, iterations=200, seed=args.seed).fit((k[tr] - mk) / sk)
        rows[f"GMM-{K} raw"] = evaluate(
            "standardised raw moduli", lambda rng, m2=m2: (lambda n: fabrics.signlog(m2.sample(n, rng) * sk + mk)),
            m2.log_likelihood((k[va] - mk) / sk) - log_sk + log_jac[va],
            m2.log_likelihood((k[tr] - mk) / sk) - log_sk + log_jac[tr], log_sk - log_jac[va])
        # x = sign(k) ln|k| is one-to-one only on |k| > 1; the change of variables ignores the mass at |k| < 1.
        # Its size, bounded by the sum over components and features of the marginal Gaussian mass in (-1, 1):
        lo_, hi_ = (-1 - mk) / sk, (1 - mk) / sk
        sd_ = np.sqrt(np.diagonal(m2.cov, axis1=1, axis2=2))
        rows[f"GMM-{K} raw"]["mass_abs_k_below_1_bound"] = float(np.sum(
            m2.weight[:, None] * (ndtr((hi_ - m2.mean) / sd_) - ndtr((lo_ - m2.mean) / sd_))))

    command = ("nice -n 15 env OMP_NUM_THREADS=1 /usr/bin/python3 training/vae/paper_space.py"
               + ("" if args.seed == 0 else f" --seed {args.seed}"))
    v = rows["VAE-3"]

    def fmt(w):
        return f"{w[0]:.3f} +- {w[1]:.3f}" if w[0] < 1e3 else f"{w[0]:.2g} +- {w[1]:.2g}"

    def label(name, r):
        return f"| {name.split()[0]} | {r['space']} |"

    lines = [f"# {command}",
             f"# {len(x)} distinct fabrics, {len(tr)} train / {len(va)} validation (split seed {args.seed}).",
             "# paper (Table 1): VAE-3 LL -6.42, W 11.1; GMM-5 LL -13.61, W 72.6 (difference 7.19 nats, W ratio 6.54)",
             "",
             "## validation log-likelihood, nats per fabric, mean (median); VAE-3: importance sampling "
             f"K = {args.iw_samples} (the table's estimator), GMM: exact",
             "# raw GMMs in sign-log space by the change of variables on |k| > 1; their mass at some |k| < 1 is "
             "at most "
             + ", ".join(f"{rows[n]['mass_abs_k_below_1_bound']:.1e}" for n in rows if n.endswith(" raw"))
             + " (K = " + args.components + ")",
             "# differences between models are the same in every common space (a change of variables adds the same "
             "Jacobian term to every model); own space: each model in the standardised space it was fitted in "
             "(not comparable)",
             "| model | fitted in | LL sign-log | LL raw-std | VAE-3 minus model | LL own space |",
             "|---|---|---:|---:|---:|---:|"]
    for name, r in rows.items():
        if name == "VAE-3 +noise":
            continue
        a_, b_ = r["ll_validation_signlog"], r["ll_validation_rawstd"]
        lines.append(f"{label(name, r)} {a_['mean']:.3f} ({a_['median']:.3f}) | "
                     f"{b_['mean']:.3f} ({b_['median']:.3f}) | "
                     f"{v['ll_validation_signlog']['mean'] - a_['mean']:+.3f} | "
                     f"{r['ll_validation_own_space']['mean']:.3f} ({r['ll_validation_own_space']['median']:.3f}) |")
    lines += ["",
              f"## W1, {args.generated} generated vs the {len(x)} fabrics, mean +- std over chunks; "
              "raw-std: normalised "
              "moduli standardised by all fabrics' mean/std",
              f"# alpha<=1: of the {args.generated}, vectors with a sign-log alpha <= 0, i.e. an alpha <= 1 "
              "(negative ones included; the smallest measured |k| is 915); beta>0: vectors with a positive beta "
              "(4 of the 251 fabrics)",
              "# rejection: the sampler's rule (sign-log range of the fabrics widened 10% per side) on the candidates; "
              f"floor: the same W1 against 251 fresh accepted draws of the model itself (mean of {args.references})",
              "# ratio: model / VAE-3 (decoder means), sign-log W1, without / with rejection",
              "| model | fitted in | W1 sign-log | W1 raw-std | alpha<=1 | beta>0 | accepted "
              "| rejection: W1 sign-log | floor "
              "| W1 raw-std | floor | ratio sign-log |",
              "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for name, r in rows.items():
        j = r["rejection"]
        lines.append(f"{label(name, r)} {fmt(r['w1_signlog'])} | {fmt(r['w1_rawstd'])} | "
                     f"{r['generated_alpha_at_most_1']} | {r['generated_positive_beta']} | {j['accepted']:.3f} | "
                     f"{fmt(j['w1_signlog'])} | "
                     f"{j['floor_signlog'][0]:.3f} | {fmt(j['w1_rawstd'])} | {j['floor_rawstd'][0]:.3f} | "
                     f"{r['w1_signlog'][0] / v['w1_signlog'][0]:.2f} / "
                     f"{j['w1_signlog'][0] / v['rejection']['w1_signlog'][0]:.2f} |")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "table.txt"), "w") as f:
        f.write(text)
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump({"command": command, "seed": args.seed, "iw_samples": args.iw_samples,
                   "generated": args.generated, "train": len(tr), "validation": len(va), "paper": PAPER,
                   "raw_std_train": {"mean": mk.tolist(), "std": sk.tolist()},
                   "raw_std_all": {"mean": mk_all.tolist(), "std": sk_all.tolist()},
                   "models": rows}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
