#!/usr/bin/python3
"""Example 7: a flexible link on a robot described in URDF, seen moving.

cases/urdf_arm.toml takes its rigid chain from cases/urdf/three_link_arm.urdf (waist, shoulder,
elbow, a tool flange welded to the forearm) and mounts a 1.2 m aluminium tube on the flange. The
example prints what the URDF built, the torques the motion needs against the URDF's effort limits,
the tube's sag at rest against beam theory, then feeds the torques back as force input (the arm
should follow the same motion), and writes ParaView files and a short GIF of the run.

    /usr/bin/python3 examples/ex7_urdf_arm.py [OUTDIR]        (~3 s; OUTDIR: a temporary directory)
"""
import os
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np

import rfem

here = os.path.dirname(os.path.abspath(__file__))
path = os.path.join(here, "..", "cases", "urdf_arm.toml")
out = sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp()
os.makedirs(out, exist_ok=True)
case = rfem.load(path, values={"simulation.store_flexible_every": 5})

tree = rfem.show(case)
print(f"URDF {os.path.basename(tree.urdf)}: " + ", ".join(f"{f['name']} on {f['parent']}" for f in tree.frames))
for e in tree:
    if e["kind"] == "joint":
        print(f"  joint {e['name']}: {e['detail'].split(';')[0]}, body {e['mass']:.4g} kg")

# Kinematic input: the torques the motion needs, against the limits the URDF declares.
h5 = os.path.join(out, "urdf_arm.h5")
kin = rfem.run(case, output=h5, threads=1)[0]
limits = {j.get("name"): float(j.find("limit").get("effort"))
          for j in ET.parse(tree.urdf).getroot().iter("joint") if j.find("limit") is not None}
tau = kin.table("joint_tau")
for j, name in enumerate(["waist", "shoulder", "elbow"]):
    peak = np.abs(tau[:, j]).max()
    print(f"  {name}: peak |tau| {peak:.4f} N m" + (f" ({peak / limits[name]:.1%} of its effort limit)" if name in limits else ""))

# At rest (t = 0, static start) the tube is a cantilever under its weight and the payload:
# tip sag w L^4 / 8 E I + P L^3 / 3 E I (Euler-Bernoulli; shear would add about 6e-4 of it).
E, rho, L, b, h = 7.0e10, 2700.0, 1.2, 0.03, 0.027
A, I = b * b - h * h, (b**4 - h**4) / 12
w, P = rho * A * 9.81, 0.2 * 9.81
beam = w * L**4 / (8 * E * I) + P * L**3 / (3 * E * I)
u2 = kin.table("tip_deflection")[0, 1]
print(f"  tube sag at rest {abs(u2):.6e} m, beam theory {beam:.6e} m ({abs(u2) / beam - 1:+.2%}, n = 12)")

# Force input: the kinematic run's torques drive the joints; the arm follows the same motion.
force = case.with_values({f"base.joints.{name}.input": {"kind": "torque_from_run", "file": h5, "run": "run", "joint": j + 1}
                          for j, name in enumerate(["waist", "shoulder", "elbow"])})
frc = rfem.run(force, threads=1)[0]
dq = np.abs(frc.table("joint_q") - kin.table("joint_q")).max(axis=0)
# (how far off depends on the steps the integrator takes, which differ between CPUs: the bound
# is what is compared, the values follow on a comment line)
print(f"force input from those torques: {frc.status}; every joint within 1e-4 rad of the motion: {bool(dq.max() < 1e-4)}")
print("# largest joint errors: " + ", ".join(f"{x:.2e}" for x in dq) + " rad")

xdmf = [f for f in os.listdir(out) if f.endswith(".xdmf")]
gif = rfem.animate(h5, output=os.path.join(out, "urdf_arm.gif"), frames=10)
print(f"ParaView: {', '.join(xdmf)}; animation: {os.path.basename(gif)}")
