#!/usr/bin/python3
"""Example 5: a two-link flexible arm under PD control with computed torque.

The planar arm of cases/two_link_arm.toml (two 1 m aluminium strips, the elbow motor on the upper
link's tip, a 0.1 kg payload) swings through -120 deg and +180 deg in 3 s; each joint has PD
feedback on its reference plus the rigid arm's inverse dynamics, on drives with friction. Prints
how closely the joints track, how far the links bend, and the energy the drives and the damping
take; the same run with the gains lowered shows what the feedback does.

    /usr/bin/python3 examples/ex5_two_link_pd.py        (~2 s)
"""
import math
import os

import numpy as np

import rfem

here = os.path.dirname(os.path.abspath(__file__))
case = rfem.load(os.path.join(here, "..", "cases", "two_link_arm.toml"))


def tracking(run, T=3.0, alphas=(-0.6667, 1.0)):
    """Largest |q - q_ref| of each joint; the references are the deployment laws from 0."""
    t = run.column("time", 0)
    errors = []
    for j, a in enumerate(alphas):
        k = math.pi * a / (2 * T)
        ref = np.where(t < T, -k * (t - T / (2 * math.pi) * np.sin(2 * math.pi * t / T)), -k * T)
        errors.append(np.abs(run.column("joint_q", j) - ref).max())
    return errors


for label, c in [("PD gains of the case", case),
                 ("gains / 10", case.with_values({"joints.0.input.kp": 4.0, "joints.0.input.kd": 0.8,
                                                  "joints.1.input.kp": 1.0, "joints.1.input.kd": 0.2}))]:
    r = rfem.run(c, threads=1)[0]
    e1, e2 = tracking(r)
    energy = r.table("energy")
    print(f"{label}: {r.status}; tracking error shoulder {e1:.4e} rad, elbow {e2:.4e} rad")
    print(f"  peak |u1|: upper {r.peaks['upper']['u1']:.4e} m, forearm {r.peaks['forearm']['u1']:.4e} m;"
          f" dissipated {energy[-1, 4]:.4e} J of {energy[:, 3].max():.4e} J input work")
