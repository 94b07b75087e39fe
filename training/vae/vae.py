"""The VAE subspace model (paper Section 5.1.3, Table 1): fully connected encoder and mirrored decoder, Gaussian
observation model with one learned standard deviation per feature, standard normal prior. Works in float64 on
standardised features (feature - mean) / std with the training set's mean and std."""
import math

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
ACTIVATION = "elu"  # the C++ decoder implements the same function (sampler/src/mlp.cpp)


def mlp(widths):
    layers = []
    for i in range(len(widths) - 1):
        layers.append(nn.Linear(widths[i], widths[i + 1]))
        if i + 2 < len(widths):
            layers.append(nn.ELU())
    return nn.Sequential(*layers)


class VAE(nn.Module):
    def __init__(self, hidden, latent, dim=6):
        super().__init__()
        self.hidden, self.latent, self.dim = list(hidden), latent, dim
        self.encoder = mlp([dim] + self.hidden)
        self.encoder_act = nn.ELU()
        self.to_mu = nn.Linear(self.hidden[-1], latent)
        self.to_logvar = nn.Linear(self.hidden[-1], latent)
        self.decoder = mlp([latent] + self.hidden[::-1] + [dim])
        self.log_sigma = nn.Parameter(torch.zeros(dim, dtype=torch.float64))
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

    def elbo(self, s):
        mu, logvar = self.encode(s)
        z = mu + torch.exp(0.5 * logvar) * torch.randn_like(mu)
        rec = self.log_gaussian_obs(s, self.decoder(z))
        kl = 0.5 * (mu ** 2 + torch.exp(logvar) - 1 - logvar).sum(-1)
        return rec - kl

    @torch.no_grad()
    def iw_log_likelihood(self, s, samples, generator):
        """Importance-weighted estimate of log p(s) (standardised space) with `samples` draws from q(z|s)."""
        mu, logvar = self.encode(s)
        std = torch.exp(0.5 * logvar)
        out = []
        for i in range(s.shape[0]):
            eps = torch.randn(samples, self.latent, dtype=torch.float64, generator=generator)
            z = mu[i] + std[i] * eps
            log_q = (-0.5 * eps ** 2 - torch.log(std[i]) - 0.5 * math.log(2 * math.pi)).sum(-1)
            log_prior = (-0.5 * z ** 2 - 0.5 * math.log(2 * math.pi)).sum(-1)
            log_obs = self.log_gaussian_obs(s[i].expand(samples, -1), self.decoder(z))
            w = log_obs + log_prior - log_q
            out.append(torch.logsumexp(w, 0) - math.log(samples))
        return torch.stack(out)


def train(model, train_s, epochs, seed, lr=1e-4, weight_decay=1e-5, batch=16, log=None):
    """Adam, lr 1e-4, weight decay 1e-5, batch 16 (paper Section 5.1.3); maximises the ELBO."""
    torch.manual_seed(seed)
    opt = torch.optim.Adam(model.parameters(), lr=lr, weight_decay=weight_decay)
    data = torch.as_tensor(train_s, dtype=torch.float64)
    g = torch.Generator().manual_seed(seed)
    for epoch in range(epochs):
        order = torch.randperm(len(data), generator=g)
        total = 0.0
        for start in range(0, len(data), batch):
            x = data[order[start:start + batch]]
            loss = -model.elbo(x).mean()
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += float(loss) * len(x)
        if log and (epoch % max(1, epochs // 10) == 0 or epoch == epochs - 1):
            log(f"  epoch {epoch:5d}  -ELBO {total / len(data):.4f}")
    return model


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
