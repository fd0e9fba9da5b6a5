#!/usr/bin/python3
"""Example 3: a parameter study in a few lines - deployment time T against the peak tip deflection
and the peak joint-3 torque ripple (flexible minus rigid torque), the paper's manipulator at n = 60.

A faster deployment excites link 3 more: the peak tip deflection grows roughly as 1/T^2 (the
deployment's accelerations); the ripple also depends on how the deployment's spectrum meets the
link's first frequencies, so it is not monotone. Below T = 8 s the 8 m link deflects more than 2 %
of its length and twists beyond 0.1 rad: outside the small-deformation model. Sixteen pairs of the
rigid and kinematic runs of the paper's procedure (the force run is not needed here).

    /usr/bin/python3 examples/ex3_parameter_study.py        (~15 s)
"""
import os

import numpy as np

import rfem

here = os.path.dirname(os.path.abspath(__file__))
case = rfem.load(os.path.join(here, "..", "cases", "paper_deployment.toml"))
print(f"{'T [s]':>6} {'peak |u1| [m]':>14} {'ripple [N m]':>13}")
for T in np.linspace(8.0, 23.0, 16):
    c = case.with_values({f"joints.{j}.input.T": T for j in range(3)} | {"simulation.t_end": T + 2.0})
    rigid, flex = rfem.run(c, n=60, runs=["rigid", "kinematic"], threads=1)
    ripple = np.abs(flex.column("joint_tau", 2) - rigid.column("joint_tau", 2)).max()
    print(f"{T:>6.1f} {flex.peaks['link']['u1']:>14.6e} {ripple:>13.6e}")
