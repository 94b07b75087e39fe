"""Gaussian mixture with full covariances, fitted by expectation-maximisation (paper Section 5.1.3: 200 iterations)."""
import numpy as np
from scipy.special import logsumexp


class GaussianMixture:
    def __init__(self, components, iterations=200, seed=0, reg=1e-6):
        self.k, self.iterations, self.seed, self.reg = components, iterations, seed, reg

    def _log_components(self, x):
        """log(w_j N(x_i; m_j, C_j)) for every point i and component j."""
        n, d = x.shape
        out = np.empty((n, self.k))
        for j in range(self.k):
            chol = np.linalg.cholesky(self.cov[j])
            r = np.linalg.solve(chol, (x - self.mean[j]).T)
            log_det = 2.0 * np.sum(np.log(np.diag(chol)))
            out[:, j] = np.log(self.weight[j]) - 0.5 * (d * np.log(2 * np.pi) + log_det + np.sum(r * r, axis=0))
        return out

    def fit(self, x):
        n, d = x.shape
        rng = np.random.default_rng(self.seed)
        # k-means++ style seeding of the means, shared covariance of the data to start.
        centres = [x[rng.integers(n)]]
        for _ in range(1, self.k):
            d2 = np.min([np.sum((x - c) ** 2, axis=1) for c in centres], axis=0)
            centres.append(x[rng.choice(n, p=d2 / d2.sum())])
        self.mean = np.array(centres)
        self.cov = np.array([np.cov(x.T) + self.reg * np.eye(d)] * self.k)
        self.weight = np.full(self.k, 1.0 / self.k)
        for _ in range(self.iterations):
            log_r = self._log_components(x)
            log_r -= logsumexp(log_r, axis=1, keepdims=True)
            r = np.exp(log_r)
            nk = r.sum(axis=0) + 1e-12
            self.weight = nk / n
            self.mean = (r.T @ x) / nk[:, None]
            for j in range(self.k):
                c = x - self.mean[j]
                self.cov[j] = (r[:, j, None] * c).T @ c / nk[j] + self.reg * np.eye(d)
        return self

    def log_likelihood(self, x):
        """Exact log density of every point."""
        return logsumexp(self._log_components(x), axis=1)

    def sample(self, n, rng):
        which = rng.choice(self.k, size=n, p=self.weight)
        out = np.empty((n, self.mean.shape[1]))
        for j in range(self.k):
            idx = np.nonzero(which == j)[0]
            out[idx] = rng.multivariate_normal(self.mean[j], self.cov[j], size=len(idx))
        return out
