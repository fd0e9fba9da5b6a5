#!/usr/bin/python3
"""Example 15: force input with a reduced link (modes = m) against the full model.

The paper's procedure (cases/paper_deployment.toml, n = 60 rfes on link 3; rigid, kinematic and
force runs) with link 3 kept whole and reduced to its first m = 4, 8, 16 clamped modes
(`--set link.modes=8`; README "Reduced links", docs/formulation.md §9). Each rfe keeps its three
displacements; the three rotations of the 60 rfes (180) become the m modal amplitudes. Printed:
1. the unknowns, steps and residual evaluations of each run (the reduction does not buy steps on
   this link: the displacements keep the full model's stiff axial and shear frequencies),
2. the peaks |u1|, |u2|, |θ| of the tip and their distance from the full model's: all three
   converge as m grows (m = 8 within 1.3e-3, m = 16 within 8.6e-5). Segment B1 is nearly free to
   twist (J = 2.2e-11 m⁴ as the paper prints it) and part of its twist is second order in the
   bending: the static derivatives of the first 6 modes (`link.derivatives = 6`, docs/formulation.md
   §9: 18 second-order shapes more) bring θ within 6.3e-5 with 8 modes; beside each distance, the
   run's own estimate of it (Run.reduction_error: the full and the reduced model at n = 30), which
   a user without the full run has: within a factor of 2 above 1e-4 of a peak, its order only below
   (the force run's small errors change with n by as much as their size; docs/accuracy.md),
3. the force run's tip u1 at a few times, full against m = 8 with and without the derivatives, and
   the energy balance (the work of the joint torques against T + V: the Galerkin projection
   conserves what the full model does).
Steps and wall times vary with the machine and the build: they are on lines starting with "#".
Measured on the project's two-core machine (one thread, a slow hour), at the default tolerances:
force run 5 677 steps, 2.8 s (full); 2 499, 1.2 s (m = 4); 4 456, 2.4 s (m = 8); 6 584, 3.3 s
(m = 16); 5 492, 3.3 s (m = 8 with the derivatives). bench/reduction_bench.py measures n = 1 000,
where the reduced force run costs 1.17–1.23× the full one at the same tolerances (README, "Reduced
links").

    PYTHONPATH=build/python /usr/bin/python3 examples/ex15_reduced_force.py        (~16 s)
"""
import os

import numpy as np

import rfem

here = os.path.dirname(os.path.abspath(__file__))
path = os.path.join(here, "..", "cases", "paper_deployment.toml")
N = 60

CONFIGS = ((0, 0), (4, 0), (8, 0), (16, 0), (8, 6))  # (modes, derivatives)
DERIVED = 18  # of the 21 derivatives of modes 1 … 6, those that add a rotation (docs/formulation.md §9)


def label(c):
    m, p = c
    return "full" if m == 0 else f"modes = {m}" + (f" + derivatives of 1…{p}" if p else "")


results = {}
for c in CONFIGS:
    m, p = c
    case = rfem.load(path, {"link.modes": m, "link.derivatives": p})
    results[c] = rfem.run(case, n=N, threads=1)
    unknowns = 6 * N if m == 0 else 3 * N + m + (DERIVED if p else 0)  # (rfem show --json says the same)
    name = label(c)
    print(f"{name}: link 3 has {unknowns} unknowns; the kinematic and force runs (steps differ between CPUs' builds):")
    for r in ("kinematic", "force"):
        run = results[c][r]
        s = run.stats
        print(f"# {r:<9}: {s['steps']:5d} steps, {s['residual_evals']:6d} residual evaluations, wall time {run.wall_time:.2f} s")

print("peaks of the tip (full) and the reduced runs' relative distance from them, each beside the run's own")
print("estimate (Run.reduction_error: the full and the reduced model at n = N/2; README, \"Reduced links\")")
for r in ("kinematic", "force"):
    full = results[(0, 0)][r].peaks["link"]
    print(f"  {r}: full |u1| = {full['u1']:.6e} m, |u2| = {full['u2']:.6e} m, |theta| = {full['theta']:.6e} rad")
    for c in CONFIGS[1:]:
        p = results[c][r].peaks["link"]
        d = [abs(p[k] - full[k]) / full[k] for k in ("u1", "u2", "theta")]
        e = results[c][r].reduction_error["link"]
        est = [abs(e[k]) / full[k] for k in ("u1", "u2", "theta")]
        print(f"    {label(c)}: u1 {d[0]:.1e} (est. {est[0]:.1e}), u2 {d[1]:.1e} (est. {est[1]:.1e}), "
              f"theta {d[2]:.1e} (est. {est[2]:.1e}), at n = {e['n']}")
        if c[1]:
            assert max(d) < 1e-3, d

full, red, der = results[(0, 0)]["force"], results[(8, 0)]["force"], results[(8, 6)]["force"]
t = full.column("time", 0)
series = {k: np.asarray(x.column("tip_deflection", 0)) for k, x in (("full", full), ("red", red), ("der", der))}
theta = {k: np.asarray(x.column("tip_deflection", 2)) for k, x in (("full", full), ("red", red), ("der", der))}
print("force run, tip u1 [m]: full, modes = 8, and modes = 8 with derivatives")
for tk in (2.0, 5.0, 10.0, 15.0, 20.0):
    k = int(np.argmin(np.abs(t - tk)))
    print(f"  t = {t[k]:5.2f} s: {series['full'][k]:+.6e}  {series['red'][k]:+.6e}  {series['der'][k]:+.6e}")
peak = np.abs(series["full"]).max()
peak_theta = np.abs(theta["full"]).max()
for k, name in (("red", "modes = 8"), ("der", "modes = 8 + derivatives")):
    print(f"  {name}: largest difference over the run: u1 {np.abs(series[k] - series['full']).max() / peak:.1e} of its peak, "
          f"theta {np.abs(theta[k] - theta['full']).max() / peak_theta:.1e} of its peak")
for name, res in (("full", full), ("modes = 8", red), ("modes = 8 + derivatives", der)):
    ok = res.energy_drift < 1e-6 * res.energy_scale
    print(f"energy balance of the force run ({name}): drift below 1e-6 of its scale: {ok}")
    assert ok
assert np.abs(series["red"] - series["full"]).max() < 1e-2 * peak
assert np.abs(theta["der"] - theta["full"]).max() < np.abs(theta["red"] - theta["full"]).max()
