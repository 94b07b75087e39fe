"""Coverage metrics shared by every model: exact Wasserstein-1 distance by optimal assignment."""
import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist


def wasserstein_exact(generated, data):
    """Exact W1 (Euclidean ground cost) between the empirical measure of `data` (n points) and that of n generated
    points, solved as an assignment problem; averaged over the floor(len(generated) / n) disjoint chunks of n
    generated points. Returns (mean, standard deviation over chunks, chunks)."""
    n = len(data)
    chunks = len(generated) // n
    if chunks == 0:
        raise ValueError(f"{len(generated)} generated points: the exact W1 needs at least as many as the {n} data "
                         "points")
    values = []
    for c in range(chunks):
        cost = cdist(generated[c * n:(c + 1) * n], data)
        rows, cols = linear_sum_assignment(cost)
        values.append(cost[rows, cols].mean())
    return float(np.mean(values)), float(np.std(values)), chunks
