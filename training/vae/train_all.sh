#!/usr/bin/env bash
# Trains and evaluates every candidate of the paper's Table 1 (GMM K = 3..7, VAE-1..4), exports the chosen VAE-3 to
# sampler/models/vae3.dgvae (and its PyTorch state to training/vae/models/vae3.pt, the reference of the decoder test),
# and writes training/vae/results/metrics.json and the table in docs/SAMPLER.md (between its TABLE markers).
# Two processes in parallel, one thread each; about 33 minutes on the 2-core development machine (shared).
# VAEs: Student-t observation model (docs/SAMPLER.md), otherwise the paper's settings; at most the given epochs,
# early-stopped on a tenth of the training fabrics (checks every --check-every epochs). The paper does not state
# epochs; the large VAE-1 and VAE-2 get fewer, for time.
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=/usr/bin/python3
T=training/vae
SEED=${SEED:-0}
mkdir -p $T/results $T/models
common=(--seed "$SEED" --iw-samples 1000 --generated 6000 --threads 1)
vae=(--observation student)
(
  $PY $T/train.py "${common[@]}" "${vae[@]}" --models VAE-1 --epochs 400 --check-every 25 \
      --results $T/results/vae1.json
  $PY $T/train.py "${common[@]}" "${vae[@]}" --models VAE-4 --epochs 20000 --check-every 500 \
      --results $T/results/vae4.json
) 2> $T/results/log_a.txt &
a=$!
(
  $PY $T/train.py "${common[@]}" --models GMM-3,GMM-4,GMM-5,GMM-6,GMM-7 --results $T/results/gmm.json
  $PY $T/train.py "${common[@]}" "${vae[@]}" --models VAE-3 --epochs 10000 --check-every 250 \
      --results $T/results/vae3.json --export VAE-3=sampler/models/vae3.dgvae --checkpoint $T/models/vae3.pt
  $PY $T/train.py "${common[@]}" "${vae[@]}" --models VAE-2 --epochs 3000 --check-every 100 \
      --results $T/results/vae2.json
) 2> $T/results/log_b.txt &
b=$!
wait $a
wait $b
$PY $T/make_table.py $T/results/gmm.json $T/results/vae1.json $T/results/vae2.json $T/results/vae3.json \
    $T/results/vae4.json --merged $T/results/metrics.json --doc docs/SAMPLER.md
