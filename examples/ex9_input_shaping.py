#!/usr/bin/python3
"""Example 9: input shaping — ZV shapers from the link's modes stop the paper's deployment ringing.

The paper's deployment (cases/paper_deployment.toml as it is: the three joints swing the 8 m link 3
through 90°, 135° and 180° by Kane's cycloidal law in T = 15 s, prescribed motion, n = 6 as in the
paper) leaves the link ringing after the move: ±5.7 mm at the tip in the plane of the deployment
(u1), ±0.77 mm out of it (u2) — the case has no damping, so it would ring for ever. A ZV shaper,
two impulses A1 = 1/(1+K) at 0 and A2 = K/(1+K) at Δ = π/ω_d (K = exp(−ζπ/√(1−ζ²)), ω_d = ω√(1−ζ²)),
convolved with a joint's motion, q_s(t) = A1 q(t) + A2 q(t − Δ), cancels a mode at ω: what A2
excites arrives half a period after what A1 excites, and in antiphase. The move lasts Δ longer.
1. rfem.modes with the joints held (a prescribed joint is held once its move ends): first
   bending-y, the in-plane bending u1 measures (0.768 Hz), then bending-z, out of the plane (u2,
   0.937 Hz). They are the same at the start and at the end of the deployment: links 1 and 2 are
   rigid, the joints held, and there is no gravity, so the configuration does not enter. Nor does
   the motion: the joints turn at 0.21 rad/s at most, and in a frame turning that fast about joint
   3 the modes are 0.09 % stiffer; a ZV leaves ≈ (π/2)|δω/ω| of a mode it misses by δω, here
   0.14 %. The shapers use the modes at the end, where the arm rings. ζ = βω/2 from the case's sde
   damping β (link.damping_beta): none here, so ζ = 0 and A1 = A2 = 1/2.
2. Each shaped motion goes to rfem as a motion table (kind = "table", a natural cubic spline through
   (t, q) rows) in a temporary directory: rows 10 ms apart and one at each time where the shaped
   law's third derivative jumps (0, Δ, T, T + Δ), so that between rows the law is smooth and the
   spline's error is O(h⁴ q⁗) ≈ 1e-12 rad, O(h² q⁗) ≈ 1e-7 rad/s² in the acceleration (peak
   0.044 rad/s²); the natural end conditions (q̈ = 0) hold at both ends. The check: the unshaped law
   through such a table rings as the case's own law does, within the integration's error.
3. The ZV at the first mode on every joint: u1's ringing falls by 99.7 %, the tip's (|u| =
   √(u1² + u2²)) by 95 %, but u2's by only 65 %: u2 is the second mode, of which a ZV at ω_s leaves
   |cos(π ω / (2 ω_s))| — 0.339, printed beside the observed 0.346.
4. The fix: shape each joint for the mode it excites. Joint 1 (about the vertical) swings the link
   out of the plane (u2), joints 2 and 3 (parallel horizontal axes) swing it in the plane (u1): ZV
   at f2 on joint 1, at f1 on joints 2 and 3. Both components fall by 99.8 %, and the move lasts no
   longer than under design 3 (Δ = π/ω1 = 0.65 s, 4 % of T); a ZV at both modes on every joint
   (four impulses) would do as well but take π/ω1 + π/ω2 = 1.2 s.
Shaping costs time, not torque: the peak joint torques fall by 3 to 6 %. The unshaped link's
ringing adds 5.6 % to the rigid arm's torques (the paper's rigid run: 3.124 N m at joint 3, here
3.299); the shaped link hardly rings during the move either, and its accelerations peak 1 % lower
(cos(πΔ/T): two half-size copies of the cycloid Δ apart).
The residual is max |u| over the same 5 s (almost four periods of the first mode) for every design,
from T + 0.65 s, when the slowest shaped move ends; outputs every 10 ms (a sampled peak is within
5e-4 of the true one). atol is 1e-11 m (default 1e-10): the shaped ringing is ~1e-6 m, and the
default's error in it reaches 2 %, this one's 0.2 %. Last, the model's error: the per-joint shaper
designed on n = 6 applied to the n = 24 model, whose modes are 1.3 % and 1.2 % lower: the ringing
still falls by 98 %, as (π/2)·1.3 % ≈ 2 % predicts.

    /usr/bin/python3 examples/ex9_input_shaping.py        (~2 s)
"""
import math
import os
import tempfile
import tomllib

import numpy as np

import rfem

here = os.path.dirname(os.path.abspath(__file__))
path = os.path.join(here, "..", "cases", "paper_deployment.toml")
with open(path, "rb") as f:
    spec = tomllib.load(f)
PSI0 = [j["value"] for j in spec["joints"]]
ALPHA = [j["input"]["alpha"] for j in spec["joints"]]
T = spec["joints"][0]["input"]["T"]
assert all(j["input"]["kind"] == "deployment" and j["input"]["T"] == T for j in spec["joints"])
BETA = spec["link"].get("damping_beta", 0.0)   # sde damping d = β·stiffness [s]
H = 0.01          # the tables' row spacing [s]
WINDOW = 5.0      # [s] after the slowest shaped move, where the residual ringing is measured
# One run of the case's inputs (prescribed motion), outputs every 10 ms; atol 1e-11 m (default 1e-10):
# the shaped ringing is ~1e-6 m, and the default's error in it reaches 2 %, this one's 0.2 %.
case = rfem.load(path, overrides=['simulation.procedure="single"', "simulation.output_dt=0.01",
                                  "simulation.atol=1e-11"])

# 1. The modes with the joints held, at the start and the end of the deployment.
end = case.with_values({f"joints.{j}.value": PSI0[j] - math.pi * ALPHA[j] / 2 for j in range(3)})
start_modes, end_modes = rfem.modes(case, count=2), rfem.modes(end, count=2)
for label, m in (("start", start_modes), ("end", end_modes)):
    psi = m.equilibrium[-3:]                   # the joints come after the link's coordinates
    print(f"modes at the {label} (psi = {', '.join(f'{v:.6f}' for v in psi)} rad): "
          + ", ".join(f"{k} {f:.6f} Hz" for k, f in zip(m.kinds, m.frequencies)))
assert start_modes.kinds[:2] == ["bending-y", "bending-z"]
omega = end_modes.omega[:2]                    # the configuration the arm rings in after the move
zeta = BETA * omega / 2                       # modal damping ratio of the sde damping
print(f"sde damping beta = {BETA:g} s: zeta = {zeta[0]:g}, {zeta[1]:g}")


def zv(w, z):
    """The ZV shaper of a mode at w [rad/s] with damping ratio z: [(amplitude, time), ...]."""
    K = math.exp(-z * math.pi / math.sqrt(1 - z * z))
    return [(1 / (1 + K), 0.0), (K / (1 + K), math.pi / (w * math.sqrt(1 - z * z)))]


ZV1, ZV2 = zv(omega[0], zeta[0]), zv(omega[1], zeta[1])
for name, s, f in (("f1", ZV1, end_modes.frequencies[0]), ("f2", ZV2, end_modes.frequencies[1])):
    print(f"ZV at {name} = {f:.6f} Hz: A1 = {s[0][0]:.6f}, A2 = {s[1][0]:.6f} at Delta = {s[1][1]:.6f} s")
T_END = T + ZV1[1][1] + WINDOW   # ZV1's Δ is the longest of the shapers below


def deployment(t, j):
    """Kane's deployment law of joint j (solvers/inputs.hpp), the joint at rest before t = 0."""
    t = np.clip(t, 0.0, T)
    return PSI0[j] - math.pi * ALPHA[j] / (2 * T) * (t - T / (2 * math.pi) * np.sin(2 * math.pi * t / T))


def table(j, shaper, scratch, label):
    """Joint j's motion convolved with the shaper, as a CSV for a kind = "table" input: rows at most
    H apart, one at every kink of the law's third derivative."""
    breaks = sorted({0.0, T_END} | {d for _, d in shaper} | {T + d for _, d in shaper})
    t = np.unique(np.concatenate([np.linspace(a, b, max(2, math.ceil((b - a) / H - 1e-9) + 1))
                                  for a, b in zip(breaks[:-1], breaks[1:])]))
    q = sum(A * deployment(t - d, j) for A, d in shaper)
    file = os.path.join(scratch, f"{label}_psi{j + 1}.csv")
    np.savetxt(file, np.column_stack([t, q]), fmt="%.17g", delimiter=",", header="t [s], psi [rad]")
    return file


def run(label, shapers, scratch, n=None):
    """The deployment with each joint's motion shaped (None: the case's own law); the run."""
    c = case.with_values({"simulation.t_end": T_END})
    if shapers is not None:
        c = c.with_values({f"joints.{j}.input": {"kind": "table", "file": table(j, s, scratch, label)}
                           for j, s in enumerate(shapers)})
    r = rfem.run(c, n=n, threads=1)["run"]
    assert r.completed, r.status
    t = r.column("time", 0)
    u = r.table("tip_deflection")[t >= T_END - WINDOW - 1e-9, :2]
    return {"u1": np.abs(u[:, 0]).max(), "u2": np.abs(u[:, 1]).max(), "u": np.hypot(u[:, 0], u[:, 1]).max(),
            "tau": np.abs(r.table("joint_tau")).max(axis=0),
            "move": T + max((s[-1][1] for s in shapers), default=0.0) if shapers else T}


def report(label, r, ref):
    cut = {k: 100 * (1 - r[k] / ref[k]) for k in ("u1", "u2", "u")}
    print(f"{label}: move ends at {r['move']:.6f} s (+{r['move'] - T:.6f} s)")
    # Three digits: a shaped residual is what is left of a 99 % cancellation, so it carries the run's
    # integration error (~0.2 % at atol 1e-11) and the round-off of the shaper's times (CPUs differ
    # by 8e-4 of it), not six.
    print(f"  residual max|u1| {r['u1']:.3e} m ({cut['u1']:.3f} % cut), max|u2| {r['u2']:.3e} m "
          f"({cut['u2']:.3f} % cut), max|u| {r['u']:.3e} m ({cut['u']:.3f} % cut)")
    print(f"  peak |joint torque| {', '.join(f'{x:.6f}' for x in r['tau'])} N m "
          f"(unshaped {', '.join(f'{x:.6f}' for x in ref['tau'])})")
    return cut


with tempfile.TemporaryDirectory() as scratch:
    # 2. The unshaped deployment: the case's law, and the same law through a table (the spline's error).
    ref = run("law", None, scratch)
    tab = run("table", [[(1.0, 0.0)]] * 3, scratch)
    print(f"residual ringing after the unshaped move, over {T_END - WINDOW:g} ... {T_END:g} s: "
          f"max|u1| {ref['u1']:.6e} m, max|u2| {ref['u2']:.6e} m, max|u| {ref['u']:.6e} m")
    print(f"  the same law as a {H * 1e3:g} ms table: max|u| {tab['u']:.6e} m (differs by "
          f"{abs(tab['u'] / ref['u'] - 1):.0e} of it)")

    # 3. ZV at the first mode on every joint.
    a = report("ZV at f1 on every joint", run("zv1", [ZV1] * 3, scratch), ref)
    leave = abs(math.cos(math.pi * omega[1] / (2 * omega[0])))
    print(f"  u2 rings at f2, which a ZV at f1 leaves |cos(pi f2 / 2 f1)| = {leave:.4f} of; observed "
          f"{1 - a['u2'] / 100:.4f}")
    assert a["u"] >= 90.0 and a["u1"] >= 90.0

    # 4. Each joint shaped for the mode it excites: psi1 (out of the plane) at f2, psi2 and psi3 at f1.
    per_joint = [ZV2, ZV1, ZV1]
    b = report("ZV per joint (psi1 at f2, psi2 and psi3 at f1)", run("per_joint", per_joint, scratch), ref)
    assert min(b.values()) >= 90.0

    # Robustness: the same shaper (designed on n = 6) on the n = 24 model.
    fine = rfem.modes(end, n=24, count=2).frequencies
    ref24, b24 = run("law24", None, scratch, n=24), run("per_joint24", per_joint, scratch, n=24)
    print(f"n = 24 (f1 {fine[0]:.6f} Hz, f2 {fine[1]:.6f} Hz) with the n = 6 shaper: residual max|u| "
          f"{ref24['u']:.3e} -> {b24['u']:.3e} m ({100 * (1 - b24['u'] / ref24['u']):.3f} % cut)")
