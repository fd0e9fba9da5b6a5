#!/usr/bin/python3
"""Example 1: the paper's procedure and its Figures 5-8.

Adamiec-Wójcik (2001), section 4: Kane's deployment of a three-link manipulator whose link 3 is
flexible, (a) rigid inverse dynamics, (b) flexible link 3 under the rigid motion (kinematic input),
(c) flexible link 3 under the rigid torques (force input). Prints the peaks the figures show and
draws them (fig5_tip.png ... fig8_accel12.png) next to the results file.

    /usr/bin/python3 examples/ex1_paper_figures.py [OUTDIR]        (~2 s)
"""
import os
import sys

import numpy as np

import rfem

here = os.path.dirname(os.path.abspath(__file__))
out = sys.argv[1] if len(sys.argv) > 1 else "."

# 1. The case as the paper has it: n = 6 rfes on link 3, deployment over T = 15 s, run to 20 s.
case = rfem.load(os.path.join(here, "..", "cases", "paper_deployment.toml"))

# 2. The three runs of the procedure, written to HDF5 while they go (one thread: same bits everywhere).
runs = rfem.run(case, output=os.path.join(out, "paper_deployment.h5"), threads=1)
rigid, kinematic, force = runs["rigid"], runs["kinematic"], runs["force"]

# 3. Figure 5: tip deflections u1, u2 and torsion theta under kinematic and force input.
for r in (kinematic, force):
    p = r.peaks["link"]
    print(f"{r.name:<9} peak |u1| = {p['u1']:.6e} m, |u2| = {p['u2']:.6e} m, |theta| = {p['theta']:.6e} rad")

# 4. Figure 6: the joint-3 torque of the flexible arm rides on the rigid one; after the motion ends
#    (t > 15 s) the flexible torque keeps oscillating about the rigid value.
t = kinematic.column("time", 0)
tau_rigid, tau_flex = rigid.column("joint_tau", 2), kinematic.column("joint_tau", 2)
after = t > 15.0
print(f"joint-3 torque: peak rigid {np.abs(tau_rigid).max():.6e} N m, peak flexible {np.abs(tau_flex).max():.6e} N m")
print(f"joint-3 torque after the motion: {np.ptp(tau_flex[after]):.6e} N m peak to peak about {tau_rigid[after].mean():.6e} N m")

# 5. Figure 7: under force input joint 3 overshoots the law and keeps a residual rate.
v3_law, v3_force = kinematic.column("joint_v", 2), force.column("joint_v", 2)
print(f"joint-3 rate at 20 s: law {v3_law[-1]:.6e} rad/s, force input {v3_force[-1]:.6e} rad/s")
print(f"joint-3 angle at 20 s: law {kinematic.column('joint_q', 2)[-1]:.6f} rad, force input {force.column('joint_q', 2)[-1]:.6f} rad")

# 6. The energy books of the force run close: T + V + dissipated - input work stays constant.
print(f"energy balance drift of the force run below 1e-6 of its scale: {force.energy_drift < 1e-6 * force.energy_scale}")

# 7. The figures, as `rfem plot` draws them.
written = rfem.plot(os.path.join(out, "paper_deployment.h5"))
print("figures:", ", ".join(sorted(os.path.basename(f) for f in written if os.path.basename(f).startswith("fig"))))
