#!/usr/bin/python3
"""Example 15: force input with a reduced link (modes = m) against the full model.

The paper's procedure (cases/paper_deployment.toml, n = 60 rfes on link 3; rigid, kinematic and
force runs) with link 3 kept whole and reduced to its first m = 4, 8, 16 clamped modes
(`--set link.modes=8`; README "Reduced links", docs/formulation.md §9). Each rfe keeps its axial
coordinate; the other five coordinates of the 60 rfes (300) become the m modal amplitudes. Printed:
1. the unknowns, steps and residual evaluations of each run (what the reduction buys: the force
   run follows the undamped modes the full model carries; the reduced one only the m it keeps and
   the coupled joint-link modes they make),
2. the peaks |u1|, |u2|, |θ| of the tip and their distance from the full model's (u1 and u2 converge
   as m grows to ~1e-4 and ~1e-3; θ does not: segment B1's torsion constant as the paper prints it,
   J = 2.2e-11 m⁴, leaves its rfes nearly free to twist, and the twist the full model shows comes from
   second-order kinematics that a basis of linear modes in rfe coordinates does not carry — README),
3. the force run's tip u1 at a few times, full against m = 8, and its energy balance (the work of
   the joint torques against T + V: the Galerkin projection conserves what the full model does).
Steps and wall times vary with the machine and the build: they are on lines starting with "#".
Measured on the project's two-core machine (one thread): force run 5 690 steps, 1.9 s (full);
2 251, 0.7 s (m = 4); 3 765, 1.3 s (m = 8); 4 958, 2.0 s (m = 16) — at n = 60 a reduced step costs
about what a full one does (the full residual is still evaluated, and the projection is added), and
the coupled modes of the kept shapes reach tens of Hz:
bench/reduction_bench.py measures n = 1 000.

    PYTHONPATH=build/python /usr/bin/python3 examples/ex15_reduced_force.py        (~8 s)
"""
import os

import numpy as np

import rfem

here = os.path.dirname(os.path.abspath(__file__))
path = os.path.join(here, "..", "cases", "paper_deployment.toml")
N = 60

results = {}
for m in (0, 4, 8, 16):
    case = rfem.load(path, {"link.modes": m})
    results[m] = rfem.run(case, n=N, threads=1)
    unknowns = 6 * N if m == 0 else N + m
    name = "full" if m == 0 else f"modes = {m}"
    print(f"{name}: link 3 has {unknowns} unknowns; the kinematic and force runs (steps differ between CPUs' builds):")
    for r in ("kinematic", "force"):
        run = results[m][r]
        s = run.stats
        print(f"# {r:<9}: {s['steps']:5d} steps, {s['residual_evals']:6d} residual evaluations, wall time {run.wall_time:.2f} s")

print("peaks of the tip (full) and the reduced runs' relative distance from them")
for r in ("kinematic", "force"):
    full = results[0][r].peaks["link"]
    print(f"  {r}: full |u1| = {full['u1']:.6e} m, |u2| = {full['u2']:.6e} m, |theta| = {full['theta']:.6e} rad")
    for m in (4, 8, 16):
        p = results[m][r].peaks["link"]
        d = [abs(p[k] - full[k]) / full[k] for k in ("u1", "u2", "theta")]
        print(f"    modes = {m:2d}: u1 {d[0]:.1e}, u2 {d[1]:.1e}, theta {d[2]:.2f}")

full, red = results[0]["force"], results[8]["force"]
t = full.column("time", 0)
u_full = full.column("tip_deflection", 0)
u_red = red.column("tip_deflection", 0)
print("force run, tip u1 [m]: full against modes = 8")
for tk in (2.0, 5.0, 10.0, 15.0, 20.0):
    k = int(np.argmin(np.abs(t - tk)))
    print(f"  t = {t[k]:5.2f} s: {u_full[k]:+.6e}  modes = 8: {u_red[k]:+.6e}")
print(f"  largest difference over the run: {np.abs(u_red - u_full).max() / np.abs(u_full).max():.1e} of the peak")
for m, res in ((0, full), (8, red)):
    ok = res.energy_drift < 1e-6 * res.energy_scale
    print(f"energy balance of the force run ({'full' if m == 0 else 'modes = 8'}): drift below 1e-6 of its scale: {ok}")
    assert ok
assert np.abs(u_red - u_full).max() < 1e-2 * np.abs(u_full).max()
