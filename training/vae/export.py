"""Writes a trained VAE in the drapegen model format (version 1; specified in
sampler/include/drapegen/sampler/vae_model.hpp and docs/SAMPLER.md)."""
import struct

import numpy as np

MAGIC = b"DGVAE\x00\x00\x01"
VERSION = 1
ACTIVATION_ELU = 1


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
    out += struct.pack("<5I", VERSION, model.dim, model.latent, len(model.hidden), ACTIVATION_ELU)
    out += struct.pack(f"<{len(model.hidden)}I", *model.hidden)

    def reals(values):
        arr = np.ascontiguousarray(np.asarray(values, dtype="<f8"))
        return arr.tobytes()

    out += reals(model.feature_mean.numpy())
    out += reals(model.feature_std.numpy())
    out += reals(range_low)
    out += reals(range_high)
    out += reals(model.log_sigma.detach().numpy())
    layers = _linear_layers(model.encoder) + [model.to_mu, model.to_logvar] + _linear_layers(model.decoder)
    for layer in layers:
        out += reals(layer.weight.detach().numpy())  # out x in, row-major
        out += reals(layer.bias.detach().numpy())
    out += struct.pack("<Q", fnv1a64(out))
    return bytes(out)


def write_model(model, range_low, range_high, path):
    with open(path, "wb") as f:
        f.write(model_bytes(model, range_low, range_high))
