#!/usr/bin/python3
"""Example 4: natural frequencies of a rotating beam and the Southwell line.

Kane's 10 m beam on its hub turning steadily at rate W: centrifugal stiffening raises the flap
(out-of-plane) frequency, w^2 = w0^2 + K W^2 for small W (Southwell), K = 1.193 for the first flap
mode of a uniform cantilever on a hub of zero radius (Wright et al. 1982); in the plane of rotation
the centrifugal softening takes exactly W^2 off, so the lag mode has K - 1. The coefficients come
from the slope at W = 0.1 rad/s; at larger rates the frequencies leave the Southwell line.

    /usr/bin/python3 examples/ex4_modes_rotation.py        (~2 s)
"""
import os

import numpy as np

import rfem

here = os.path.dirname(os.path.abspath(__file__))
case = rfem.load(os.path.join(here, "..", "cases", "kane_spinup.toml"))


def flap_lag(W):
    """The lowest flap (bending-z: deflection along the rotation axis) and lag (bending-y) circular
    frequencies about the stretched equilibrium in the frame turning at W about the hub."""
    m = rfem.modes(case, n=40, count=4, rate=W, joint=1)
    return m.omega[m.kinds.index("bending-z")], m.omega[m.kinds.index("bending-y")]


# 1. The Southwell coefficients: the slope of w^2 against W^2 near W = 0.
w0 = np.array(flap_lag(0.0))
w1 = np.array(flap_lag(0.1))
K = (w1 ** 2 - w0 ** 2) / 0.1 ** 2
print(f"Southwell coefficients: flap {K[0]:.4f} (uniform cantilever 1.193), lag {K[1]:.4f}, flap - lag = {K[0] - K[1]:.3f}")  # (1 in theory; the slope from W = 0.1 holds ~5e-5)

# 2. The frequencies against the rate, beside the Southwell line.
print(f"{'W [rad/s]':>9} {'flap [Hz]':>10} {'line':>9} {'lag [Hz]':>10} {'line':>9}")
for W in np.arange(0.0, 6.5, 1.0):
    w = np.array(flap_lag(W))
    line = np.sqrt(w0 ** 2 + K * W ** 2)
    print(f"{W:>9.1f} {w[0] / (2 * np.pi):>10.6f} {line[0] / (2 * np.pi):>9.6f} {w[1] / (2 * np.pi):>10.6f} {line[1] / (2 * np.pi):>9.6f}")
