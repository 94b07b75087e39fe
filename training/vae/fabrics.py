"""The measured fabrics as the subspace models see them (paper Section 5.1.2 and the data README).

Features, in this order: alpha warp, alpha bias, alpha weft, beta warp, beta bias, beta weft, each normalised to the
standard density 300 g/m^2 (k * 0.3 / rho) and mapped by sign(k) * ln|k| (alpha in g*mm^2/s^2, beta in
g*mm^3/s^2). The CSV stores warp, weft, diag (= bias); the mapping below puts them in the paper's order.
"""
import numpy as np

FEATURES = ["alpha_warp", "alpha_bias", "alpha_weft", "beta_warp", "beta_bias", "beta_weft"]
STANDARD_DENSITY = 0.3  # kg/m^2
# CSV columns: 0 density, 1 linear warp, 2 linear weft, 3 linear diag, 4 nonlinear warp, 5 nonlinear weft, 6 diag.
CSV_TO_FEATURE = [1, 3, 2, 4, 6, 5]


class DataError(Exception):
    pass


HEADER_NAMES = ["density", "warp", "weft", "diag", "warp", "weft", "diag"]


def read_rows(path):
    """All 618 rows as (density kg/m^2, 6 moduli in feature order, paper units)."""
    try:
        with open(path, encoding="utf-8") as f:
            header = f.readline().split(",")
    except (OSError, UnicodeDecodeError) as e:
        raise DataError(f"cannot read fabric data '{path}': {e}") from e
    # The header fixes the columns' order (CSV_TO_FEATURE); a file without one would lose its first fabric.
    # The linear block first, then the nonlinear one (a swapped file would put beta into alpha).
    blocks_in_order = all(("nonlinear" in field) == (k >= 4) and "linear" in field
                          for k, field in enumerate(header[1:], start=1))
    if len(header) != 7 or not blocks_in_order or any(name not in field
                                                      for name, field in zip(HEADER_NAMES, header)):
        raise DataError(f"'{path}' line 1: expected the header (density, linear warp, linear weft, linear diag, "
                        "nonlinear warp, nonlinear weft, nonlinear diag)")
    try:
        raw = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except (OSError, ValueError) as e:
        raise DataError(f"cannot read fabric data '{path}': {e}") from e
    if raw.shape[1] != 7 or raw.shape[0] == 0:
        raise DataError(f"'{path}': expected 7 columns (density and six moduli), got shape {raw.shape}")
    if not np.all(np.isfinite(raw)) or np.any(raw[:, 0] <= 0) or np.any(raw[:, 1:] == 0):
        raise DataError(f"'{path}': non-finite values, non-positive densities or zero moduli")
    if np.any(raw[:, 1:4] <= 0):
        raise DataError(f"'{path}': the linear moduli (bending stiffness) must be positive")
    # signlog is one-to-one only for |k| > 1 at 300 g/m^2 (paper units): smaller moduli are in other units.
    if np.any(np.abs(raw[:, 1:] * (STANDARD_DENSITY / raw[:, :1])) <= 1):
        raise DataError(f"'{path}': a modulus with |k| <= 1 at 300 g/m^2: the columns are in SI*1e9 (linear) and "
                        "SI*1e12 (nonlinear), density in kg/m^2")
    return raw[:, 0], raw[:, CSV_TO_FEATURE]


def signlog(k):
    """The feature map sign(k) * ln|k| (one-to-one for |k| > 1); from_features is its inverse."""
    return np.sign(k) * np.log(np.abs(k))


def to_features(density, moduli):
    """sign(k) * ln|k| of the moduli normalised to 300 g/m^2."""
    return signlog(moduli * (STANDARD_DENSITY / density[:, None]))


def from_features(x):
    """The moduli (normalised density, paper units) of feature vectors."""
    return np.sign(x) * np.exp(np.abs(x))


def distinct_fabrics(path):
    """Feature vectors of the distinct fabrics (rows repeat in the CSV), in first-occurrence order."""
    density, moduli = read_rows(path)
    rows = np.column_stack([density, moduli])
    _, first = np.unique(rows, axis=0, return_index=True)
    first = np.sort(first)
    return to_features(density[first], moduli[first])


def split(n, seed, validation_fraction=0.2):
    """Indices (train, validation) of a seeded 80/20 split of n distinct fabrics."""
    order = np.random.default_rng(seed).permutation(n)
    n_val = int(round(validation_fraction * n))
    return np.sort(order[n_val:]), np.sort(order[:n_val])


def summary(path, seed=0):
    """The facts about the data that docs/SAMPLER.md quotes."""
    density, moduli = read_rows(path)
    rows = np.column_stack([density, moduli])
    _, counts = np.unique(rows, axis=0, return_counts=True)
    x = distinct_fabrics(path)
    tr, va = split(len(x), seed)
    positive = (x[:, 3:] > 0).any(axis=1)
    k = moduli * (STANDARD_DENSITY / density[:, None])
    return "\n".join([
        f"rows {len(rows)}, distinct fabrics {len(x)}, most repeats of one fabric {counts.max()}",
        f"rows with a positive beta {int((moduli[:, 3:] > 0).any(axis=1).sum())}, distinct {int(positive.sum())}: "
        f"{int(positive[tr].sum())} in the training split, {int(positive[va].sum())} in validation (seed {seed}, "
        f"{len(tr)} / {len(va)})",
        f"of them in the VAEs' early-stopping set (train.py: a tenth of the training split, seed {seed + 1}): "
        f"{int(positive[tr[split(len(tr), seed + 1, 0.1)[1]]].sum())}",
        f"smallest normalised |k| {np.abs(k).min():.1f}",
        "feature min " + " ".join(f"{v:.2f}" for v in x.min(0)),
        "feature max " + " ".join(f"{v:.2f}" for v in x.max(0)),
    ])


if __name__ == "__main__":
    import os
    import sys
    here = os.path.dirname(os.path.abspath(__file__))
    print(summary(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "sampler", "data",
                                                                        "fabrics618.csv")))
