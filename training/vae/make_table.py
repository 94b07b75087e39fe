#!/usr/bin/python3
"""Merges the per-run metrics of train.py and writes the model table into a markdown file, between the lines
<!-- TABLE BEGIN --> and <!-- TABLE END --> (train_all.sh runs it)."""
import argparse
import json
import sys

import vae

PAPER = {"GMM-3": (-15.07, -14.86, 98.9), "GMM-4": (-14.45, -13.88, 84.6), "GMM-5": (-13.89, -13.61, 72.6),
         "GMM-6": (-15.63, -15.71, 72.5), "GMM-7": (-16.20, -15.79, 97.6), "VAE-1": (-8.91, -8.68, 14.3),
         "VAE-2": (-8.35, -7.92, 13.9), "VAE-3": (-6.91, -6.42, 11.1), "VAE-4": (-7.01, -6.59, 12.4)}


def describe(name, res):
    if name.startswith("GMM"):
        return f"K = {name[4:]}, full covariances, EM 200 it."
    hidden, latent = vae.ARCHITECTURES[name]
    training = res.get("training", {})
    observation = {"gaussian": "Gaussian", "student": "Student-t"}[training.get("observation", "gaussian")]
    schedule = ""
    if training.get("kl_warmup"):
        schedule += f", KL warm-up {training['kl_warmup']}"
    if training.get("lr_final") is not None:
        schedule += f", lr {training['lr']:g} -> {training['lr_final']:g} (cosine)"
    elif training.get("lr", 1e-4) != 1e-4:
        schedule += f", lr {training['lr']:g}"
    return (f"FC {'-'.join(map(str, hidden))}, latent {latent}, {observation} obs.{schedule}; epoch "
            f"{res['chosen_epoch']} of {res['epochs']} (early stop)")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--merged", required=True)
    ap.add_argument("--doc", required=True)
    args = ap.parse_args()
    merged = None
    for path in args.runs:
        with open(path) as f:
            run = json.load(f)
        if merged is None:
            merged = {k: v for k, v in run.items() if k not in ("models", "epochs")}
            merged["models"] = {}
        for k in ("seed", "iw_samples", "generated", "distinct_fabrics", "train", "validation"):
            if run[k] != merged[k]:
                sys.exit(f"make_table.py: {path} differs in {k}")
        merged["models"].update(run["models"])
    with open(args.merged, "w") as f:
        json.dump(merged, f, indent=1)
    lines = [
        "| model | configuration | LL train | LL validation (median) | W1 prior | W1 widened "
        "| paper: LL train / val / W |",
        "|---|---|---:|---:|---:|---:|---|",
    ]
    for name in sorted(merged["models"], key=lambda n: (n[:3], n)):
        r = merged["models"][name]
        widened = f"{r['w_widened']:.3f}" if "w_widened" in r else "-"
        p = PAPER.get(name)
        lines.append(f"| {name} | {describe(name, r)} | {r['ll_train']:.3f} | {r['ll_validation']:.3f} "
                     f"({r['ll_validation_median']:.3f}) | "
                     f"{r['w_prior']:.3f} +- {r['w_prior_std']:.3f} | {widened} | "
                     f"{p[0]:.2f} / {p[1]:.2f} / {p[2]:.1f} |")
    lines.append("")
    lines.append(f"{merged['distinct_fabrics']} distinct fabrics, {merged['train']} train / {merged['validation']} "
                 f"validation (split seed {merged['seed']}); log-likelihoods in nats per fabric, mean (median); "
                 f"VAE: importance sampling with K = {merged['iw_samples']} (defensive mixture proposal), GMM: exact; "
                 f"W1 against all {merged['distinct_fabrics']} distinct fabrics from {merged['generated']} generated "
                 f"vectors (mean +- std over {merged['models']['GMM-3']['w_chunks']} chunks).")
    with open(args.doc) as f:
        text = f.read()
    begin, end = "<!-- TABLE BEGIN -->\n", "<!-- TABLE END -->"
    if begin not in text or end not in text:
        sys.exit(f"make_table.py: {args.doc} lacks the TABLE markers")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    with open(args.doc, "w") as f:
        f.write(head + begin + "\n".join(lines) + "\n" + end + tail)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
