"""Writes a trained VAE in the drapegen model format (specified in sampler/include/drapegen/sampler/vae_model.hpp and
docs/SAMPLER.md): version 1 for a Gaussian observation model, version 2 (observation code and Student-t degrees of
freedom) otherwise."""
import struct

import numpy as np

MAGIC = b"DGVAE\x00\x00\x01"
VERSION_GAUSSIAN = 1
VERSION = 2
ACTIVATION_ELU = 1
OBSERVATION_CODES = {"gaussian": 0, "student": 1}


def fnv1a64(data):
    h = 0xCBF29CE484222325
    for b in data:
        h ^= b
        h = (h * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def _linear_layers(seq):
    return [m for m in seq if hasattr(m, "weight")]


def model_bytes(model, range_low, range_high):
    out = bytearray(MAGIC)
    gaussian = model.observation == "gaussian"
    out += struct.pack("<5I", VERSION_GAUSSIAN if gaussian else VERSION, model.dim, model.latent, len(model.hidden),
                       ACTIVATION_ELU)
    if not gaussian:
        out += struct.pack("<I", OBSERVATION_CODES[model.observation])
    out += struct.pack(f"<{len(model.hidden)}I", *model.hidden)

    def reals(values):
        arr = np.ascontiguousarray(np.asarray(values, dtype="<f8"))
        if not np.all(np.isfinite(arr)):  # the C++ loader refuses such a model; say so here, not there
            raise ValueError("the model has non-finite values (a diverged training?); not exported")
        return arr.tobytes()

    out += reals(model.feature_mean.numpy())
    out += reals(model.feature_std.numpy())
    out += reals(range_low)
    out += reals(range_high)
    out += reals(model.log_sigma.detach().numpy())
    if not gaussian:
        dof = model.degrees_of_freedom().detach().numpy()
        if not np.all(dof > 1.0):
            raise ValueError("Student-t degrees of freedom must be > 1; not exported")
        out += reals(dof)
    layers = _linear_layers(model.encoder) + [model.to_mu, model.to_logvar] + _linear_layers(model.decoder)
    for layer in layers:
        out += reals(layer.weight.detach().numpy())  # out x in, row-major
        out += reals(layer.bias.detach().numpy())
    out += struct.pack("<Q", fnv1a64(out))
    return bytes(out)


def write_model(model, range_low, range_high, path):
    with open(path, "wb") as f:
        f.write(model_bytes(model, range_low, range_high))
