"""The VAE subspace model (paper Section 5.1.3, Table 1): fully connected encoder and mirrored decoder, a Gaussian
or Student-t observation model (OBSERVATIONS) with one learned scale per feature, standard normal prior. Works in
float64 on standardised features (feature - mean) / std with the training set's mean and std."""
import math
import os
import sys

import numpy as np
import torch
from torch import nn

# Table 1 of the paper: hidden layer widths (encoder order) and latent dimension.
ARCHITECTURES = {
    "VAE-1": ([2048, 1024, 512, 128], 64),
    "VAE-2": ([512, 256, 128, 32], 32),
    "VAE-3": ([128, 32, 16], 8),
    "VAE-4": ([32, 16, 8], 4),
}
OBSERVATIONS = ("gaussian", "student")
ACTIVATION = "elu"  # the C++ decoder implements the same function (sampler/src/vae_model.cpp)


def mlp(widths):
    layers = []
    for i in range(len(widths) - 1):
        layers.append(nn.Linear(widths[i], widths[i + 1]))
        if i + 2 < len(widths):
            layers.append(nn.ELU())
    return nn.Sequential(*layers)


class VAE(nn.Module):
    def __init__(self, hidden, latent, dim=6, observation="gaussian"):
        super().__init__()
        if observation not in OBSERVATIONS:
            raise ValueError(f"unknown observation model '{observation}'")
        self.hidden, self.latent, self.dim, self.observation = list(hidden), latent, dim, observation
        self.encoder = mlp([dim] + self.hidden)
        self.encoder_act = nn.ELU()
        self.to_mu = nn.Linear(self.hidden[-1], latent)
        self.to_logvar = nn.Linear(self.hidden[-1], latent)
        self.decoder = mlp([latent] + self.hidden[::-1] + [dim])
        self.log_sigma = nn.Parameter(torch.zeros(dim, dtype=torch.float64))
        if observation == "student":
            # degrees of freedom nu = 1 + exp(log_nu_minus_1) > 1 (so the decoder output is the mean), start at 5
            self.log_nu_minus_1 = nn.Parameter(torch.full((dim,), math.log(4.0), dtype=torch.float64))
        self.register_buffer("feature_mean", torch.zeros(dim, dtype=torch.float64))
        self.register_buffer("feature_std", torch.ones(dim, dtype=torch.float64))
        self.double()

    def encode(self, s):
        h = self.encoder_act(self.encoder(s))
        return self.to_mu(h), self.to_logvar(h)

    def decode_standardised(self, z):
        return self.decoder(z)

    def decode(self, z):
        """Feature vectors (sign-log moduli) of latent vectors: the decoder mean, unstandardised."""
        return self.decoder(z) * self.feature_std + self.feature_mean

    def log_gaussian_obs(self, s, mean):
        var = torch.exp(2 * self.log_sigma)
        return -0.5 * (((s - mean) ** 2) / var + 2 * self.log_sigma + math.log(2 * math.pi)).sum(-1)

    def degrees_of_freedom(self):
        return 1 + torch.exp(self.log_nu_minus_1)

    def log_obs(self, s, mean):
        """log p(s | decoder mean) of the observation model, summed over features."""
        if self.observation == "gaussian":
            return self.log_gaussian_obs(s, mean)
        nu = self.degrees_of_freedom()
        r = (s - mean) * torch.exp(-self.log_sigma)
        return (torch.lgamma((nu + 1) / 2) - torch.lgamma(nu / 2) - 0.5 * torch.log(nu * math.pi) - self.log_sigma
                - (nu + 1) / 2 * torch.log1p(r * r / nu)).sum(-1)

    def elbo(self, s, kl_weight=1.0):
        mu, logvar = self.encode(s)
        z = mu + torch.exp(0.5 * logvar) * torch.randn_like(mu)
        rec = self.log_obs(s, self.decoder(z))
        kl = 0.5 * (mu ** 2 + torch.exp(logvar) - 1 - logvar).sum(-1)
        return rec - kl_weight * kl

    @torch.no_grad()
    def iw_log_likelihood(self, s, samples, generator):
        """Importance-weighted estimate of log p(s) (standardised space) with `samples` draws from the encoder's
        q(z|s) (the IWAE bound; loose for fabrics far from the training data, where q is a poor proposal)."""
        return self._importance_estimate(s, samples, generator, defensive=False)

    @torch.no_grad()
    def log_likelihood(self, s, samples, generator):
        """Importance-sampling estimate of log p(s) (standardised space) with `samples` draws from the defensive
        mixture proposal 1/3 q(z|s) + 1/3 q(z|s) with 3x its standard deviation + 1/3 N(0, I) (for samples not a
        multiple of 3 the prior takes the remaining draws, and each part is weighted by its share). Unbiased for p(s),
        so a stochastic lower bound of log p(s); unlike plain IWAE it stays tight for atypical fabrics. The C++
        report (sampler/src/coverage.cpp) computes the same estimator."""
        return self._importance_estimate(s, samples, generator, defensive=True)

    def _importance_estimate(self, s, samples, generator, defensive):
        mu, logvar = self.encode(s)
        std = torch.exp(0.5 * logvar)
        half_log_2pi = 0.5 * math.log(2 * math.pi)
        out = []
        for i in range(s.shape[0]):
            eps = torch.randn(samples, self.latent, dtype=torch.float64, generator=generator)
            log_n = lambda z, c, sd: (-0.5 * ((z - c) / sd) ** 2 - torch.log(sd) - half_log_2pi).sum(-1)  # noqa: E731
            log_prior_of = lambda z: (-0.5 * z ** 2 - half_log_2pi).sum(-1)  # noqa: E731
            if defensive:
                if samples < 3:
                    raise ValueError(f"the defensive mixture needs at least 3 samples, got {samples}")
                k = samples // 3
                z = torch.cat([mu[i] + std[i] * eps[:k], mu[i] + 3 * std[i] * eps[k:2 * k], eps[2 * k:]])
                # the mixture's weights are the parts' shares of the draws (a third each when 3 divides samples)
                log_share = [math.log(k / samples), math.log(k / samples), math.log((samples - 2 * k) / samples)]
                log_q = torch.logsumexp(torch.stack([log_n(z, mu[i], std[i]) + log_share[0],
                                                     log_n(z, mu[i], 3 * std[i]) + log_share[1],
                                                     log_prior_of(z) + log_share[2]]), 0)
            else:
                z = mu[i] + std[i] * eps
                log_q = log_n(z, mu[i], std[i])
            log_obs = self.log_obs(s[i].expand(samples, -1), self.decoder(z))
            w = log_obs + log_prior_of(z) - log_q
            out.append(torch.logsumexp(w, 0) - math.log(samples))
        return torch.stack(out)


def fit(name, x_train, mean, std, seed, epochs, observation, check_every, log=None, **options):
    """A VAE of architecture `name` (ARCHITECTURES) trained on the raw features `x_train` standardised by `mean` and
    `std`, early-stopped on a tenth of them (split seed + 1; the validation fabrics stay unseen). `options` go to
    train(). Returns (model, chosen epoch, fit fabrics, stop fabrics)."""
    import fabrics  # the split; fabrics does not import this module
    hidden, latent = ARCHITECTURES[name]
    torch.manual_seed(seed)
    model = VAE(hidden, latent, observation=observation)
    model.feature_mean[:] = torch.as_tensor(mean)
    model.feature_std[:] = torch.as_tensor(std)
    fit_rows, stop_rows = fabrics.split(len(x_train), seed + 1, validation_fraction=0.1)
    chosen = train(model, (x_train[fit_rows] - mean) / std, epochs, seed, stop_s=(x_train[stop_rows] - mean) / std,
                   check_every=check_every, log=log, **options)
    return model, chosen, len(fit_rows), len(stop_rows)


def train(model, train_s, epochs, seed, stop_s=None, check_every=500, stop_samples=300, lr=1e-4,
          weight_decay=1e-5, batch=16, log=None, kl_warmup=0, lr_final=None, criterion="median"):
    """Adam, lr 1e-4, weight decay 1e-5, batch 16 (paper Section 5.1.3); maximises the ELBO. With `stop_s`, every
    `check_every` epochs (and at the end) the log-likelihood of those held-out fabrics is estimated (log_likelihood,
    `stop_samples` draws) and the state with the best *median* is kept (early stopping). The median, because the
    mean over 20 fabrics follows the single isolated positive-beta fabric of the stop set (docs/SAMPLER.md).
    Returns the chosen epoch."""
    torch.manual_seed(seed)
    opt = torch.optim.Adam(model.parameters(), lr=lr, weight_decay=weight_decay)
    data = torch.as_tensor(train_s, dtype=torch.float64)
    g = torch.Generator().manual_seed(seed)
    best = (-math.inf, epochs, None)
    for epoch in range(epochs):
        order = torch.randperm(len(data), generator=g)
        total = 0.0
        kl_weight = min(1.0, (epoch + 1) / kl_warmup) if kl_warmup else 1.0
        if lr_final is not None:  # cosine decay from lr to lr_final over the epochs
            for group in opt.param_groups:
                group["lr"] = lr_final + 0.5 * (lr - lr_final) * (1 + math.cos(math.pi * epoch / epochs))
        for start in range(0, len(data), batch):
            x = data[order[start:start + batch]]
            loss = -model.elbo(x, kl_weight).mean()
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += float(loss) * len(x)
        done = epoch + 1
        message = ""
        if stop_s is not None and (done % check_every == 0 or done == epochs):
            lls = model.log_likelihood(torch.as_tensor(stop_s), stop_samples, torch.Generator().manual_seed(seed + 7))
            ll = float(lls.median()) if criterion == "median" else float(lls.mean())
            if ll > best[0]:
                best = (ll, done, {k: v.clone() for k, v in model.state_dict().items()})
            message = (f"  stop-set LL median {float(lls.median()):.4f} mean {float(lls.mean()):.4f} "
                       f"(best {criterion} {best[0]:.4f} at {best[1]})")
        if log and (epoch % max(1, epochs // 10) == 0 or done == epochs or message):
            log(f"  epoch {done:6d}  -ELBO {total / len(data):.4f}{message}")
    if best[2] is not None:
        model.load_state_dict(best[2])
        return best[1]
    return epochs


def add_checkpoint_arguments(parser, repo):
    """--checkpoint, --data and --seed as the evaluation scripts take them."""
    parser.add_argument("--checkpoint", default=os.path.join(repo, "training", "vae", "models", "vae3.pt"))
    parser.add_argument("--data", default=os.path.join(repo, "sampler", "data", "fabrics618.csv"))
    parser.add_argument("--seed", type=int, default=0, help="the split seed of the training run")


def check_split(model, x, tr):
    """Raises ValueError unless the model was trained on the split `tr` of `x` (its stored standardisation is that
    split's): with another --seed, the "validation" fabrics would include the model's training fabrics."""
    if not (np.allclose(model.feature_mean.numpy(), x[tr].mean(0)) and np.allclose(model.feature_std.numpy(),
                                                                                     x[tr].std(0))):
        raise ValueError("the checkpoint was trained on another split of the data (its standardisation differs from "
                         "this --seed's training split): pass the training run's --seed and --data")


def load_for_evaluation(args):
    """For the evaluation scripts (add_checkpoint_arguments): the checkpoint's model and state, the distinct fabrics
    and the training run's split (train, validation). Exits with an error when the checkpoint was trained on another
    split."""
    import fabrics  # noqa: E402 (the evaluation scripts' dependency, not the model's)
    model, state = load_checkpoint(args.checkpoint)
    x = fabrics.distinct_fabrics(args.data)
    tr, va = fabrics.split(len(x), args.seed)
    try:
        check_split(model, x, tr)
    except ValueError as e:
        raise SystemExit(f"{os.path.basename(sys.argv[0])}: error: {e}") from None
    return model, state, x, tr, va


def load_checkpoint(path):
    """A model saved by train.py --checkpoint, in eval mode, and the saved state (name, hidden, latent, ...)."""
    state = torch.load(path)
    model = VAE(state["hidden"], state["latent"], observation=state.get("observation", "gaussian"))
    model.load_state_dict(state["state_dict"])
    model.eval()
    return model, state


def prior_latents(n, latent, rng):
    return rng.standard_normal((n, latent))


def widened_latents(n, latent, rng):
    """The paper's sampling: every coordinate from N(mu, sigma), mu ~ U[-0.5, 0.5], sigma ~ U[0.8, 1.2], drawn per
    sample and coordinate."""
    mu = rng.uniform(-0.5, 0.5, (n, latent))
    sigma = rng.uniform(0.8, 1.2, (n, latent))
    return mu + sigma * rng.standard_normal((n, latent))


@torch.no_grad()
def decode_numpy(model, z):
    return model.decode(torch.as_tensor(z, dtype=torch.float64)).numpy()
