#!/usr/bin/python3
"""Example 13: an LQR designed on rfem's linear model and run on the nonlinear arm.

The two-link arm of cases/two_link_arm.toml (n = 8: 4 rfes per link, no gravity) is held at rest by
its own PD laws (the references frozen at t = 0 with Simulation.set_reference). Then:
1. Simulation.linearize() gives the linear model about that rest with the held PD laws in force
   (their kp, kd are in K and D); state_space() gives A, B, C, D with x = (δq, δq̇) over lin.states.
   Its lowest modes: the in-plane ones (the joints and the links' bending in the plane of motion)
   and out-of-plane ones the joint torques cannot reach (uncontrollable; their damping is the
   links' own).
2. An LQR on it (scipy.linalg.solve_continuous_are): Q = W_TIP Cᵀ C over the forearm's tip
   deflection outputs (forearm/tip_u1, tip_u2) plus W_X·I, R = R_U·I on the two torques,
   Kx = R⁻¹ Bᵀ P. The closed loop's in-plane modes against the PD alone, and a check the
   continuous design needs: the loop runs at 1 kHz with a zero-order hold, so the exactly
   discretised model's closed loop must have a spectral radius below 1 (here the largest is an
   out-of-plane mode's, which no torque reaches). R ten times smaller damps more in continuous
   time and is unstable at 1 kHz (its gains reach the rfes' kHz modes).
3. The nonlinear simulation twice from the same held rest: an elbow torque pulse of 0.5 N m for
   0.05 s (added to the held feed-forward), then 2 s of free response; (a) the PD alone, (b) PD +
   LQR: every 1 ms x from sim.q, sim.v minus the operating point (lin.q0, lin.v0, coordinates
   matched to lin.states by name), u = −Kx x added to the feed-forward. The forearm tip's residual
   vibration (RMS of |(u1, u2)| over the last second) falls by 95 %, for a peak LQR torque of
   0.65 N m at the elbow. Part of that is the LQR fighting the pulse itself (the peak deflection is
   8x smaller), the rest the damping: relative to its own peak the residual is 1.0 %, against 2.4 %
   under the PD alone. The weights trade the joint servo's stiffness for a quiet tip: the slowest
   mode goes from 0.48 Hz to 0.22 Hz (well damped).
4. The linear model's prediction of run (b) (the same pulse and sampled law on the discretised
   model) against the nonlinear arm: within 1.5 % of the peak (the PD alone: 16 %). The difference
   is the drives' smoothed Coulomb friction (0.02 and 0.005 N m, smoothed over 0.01 rad/s):
   linearised at rest it is a viscous 2 and 0.5 N m s, but the pulse swings the elbow at up to
   0.2 rad/s, where it is a constant 0.005 N m. With the drives' friction set to zero the same
   comparison agrees within 1e-6 of the peak (the integrator's accuracy).

Caveats: the LQR is full-state feedback from the simulator's own coordinates (every rfe's six and
their rates); a lab has encoders and a few strain gauges or IMUs and would need an observer
(a Kalman filter on the same linear model) and would see its delay and noise. The numbers are at
n = 8 (50 unknowns; the design model's in-plane modes below 100 Hz are at 0.48, 3.4, 12.9, 23.4,
43, 63 and 85 Hz); the weights are picked by hand, not tuned.

    PYTHONPATH=build/python /usr/bin/python3 examples/ex13_lqr.py        (~2 s)
"""
import math
import os

import numpy as np
import scipy.linalg as sl

import rfem

here = os.path.dirname(os.path.abspath(__file__))
N, TS = 8, 1e-3                                   # rfes in all; the controller's sample time [s]
PULSE, T_PULSE, T_END = 0.5, 0.05, 2.05            # elbow torque pulse [N m] for T_PULSE s; the run's end
W_TIP, W_X, R_U = 1e5, 1.0, 0.1                    # LQR weights: tip deflection [1/m²], every state, torques
JOINTS = ["shoulder", "elbow"]
case = rfem.load(os.path.join(here, "..", "cases", "two_link_arm.toml"))


def held(case):
    """A simulation at t = 0 with both PD joints held where they are; the held (q, tau_ff) by joint."""
    sim = rfem.Simulation(case, n=N, threads=1)
    u0 = sim.linearize().u0                       # the torques that hold the state (zero here)
    y = sim.snapshot()
    hold = {j: (y["q"][j], y["tau"][j] + u0[i]) for i, j in enumerate(JOINTS)}
    for j in JOINTS:
        sim.set_reference(j, hold[j][0], 0.0, hold[j][1])
    return sim, hold


def in_plane(lin, vectors):
    """Per eigenvector of A: whether it moves mostly in the plane (x1, x2, phi3 of the rfes, the joints)."""
    rows = [i for i, s in enumerate(lin.states) if s.endswith(("/x1", "/x2", "/phi3")) or "/" not in s]
    q = np.abs(vectors[:len(lin.states)]) ** 2
    return q[rows].sum(0) > 0.5 * q.sum(0)


def modes(lin, A):
    """Oscillating modes of A, ascending: frequencies [Hz], damping ratios, in-plane flags."""
    ev, vec = np.linalg.eig(A)
    keep = ev.imag > 0
    ev, vec = ev[keep], vec[:, keep]
    order = np.argsort(np.abs(ev))
    ev, vec = ev[order], vec[:, order]
    return np.abs(ev) / (2 * math.pi), -ev.real / np.abs(ev), in_plane(lin, vec)


# 1. The linear model about the held rest.
sim, _ = held(case)
lin = sim.linearize()
A, B, C, D = lin.state_space()
print(f"linear model about rest at t = {lin.t:g} s (both PD joints held): {len(lin.states)} states "
      f"({A.shape[0]} first order), {len(lin.inputs)} inputs ({', '.join(lin.inputs)}), {len(lin.outputs)} outputs; "
      f"u0 = [{lin.u0[0]:g}, {lin.u0[1]:g}] N m")
f_pd, z_pd, plane_pd = modes(lin, A)
for k in range(6):
    kind = "in plane" if plane_pd[k] else "out of plane, uncontrollable"
    print(f"  mode {k + 1}: {f_pd[k]:.4f} Hz, damping ratio {z_pd[k]:.4f} ({kind})")

# 2. The LQR.
tip = [lin.outputs.index("forearm/tip_u1"), lin.outputs.index("forearm/tip_u2")]
Q = W_TIP * C[tip].T @ C[tip] + W_X * np.eye(A.shape[0])


def lqr(r):
    P = sl.solve_continuous_are(A, B, Q, r * np.eye(B.shape[1]))
    return np.linalg.solve(r * np.eye(B.shape[1]), B.T @ P)


n2 = A.shape[0]
E = sl.expm(np.block([[A, B], [np.zeros((B.shape[1], n2 + B.shape[1]))]]) * TS)
Ad, Bd = E[:n2, :n2], E[:n2, n2:]                 # x_{k+1} = Ad x_k + Bd u_k (zero-order hold)
Kx = lqr(R_U)
f_cl, z_cl, plane_cl = modes(lin, A - B @ Kx)
print(f"LQR: Q = {W_TIP:g} C_tip^T C_tip + {W_X:g} I (C_tip: forearm/tip_u1, tip_u2), R = {R_U:g} I; "
      f"largest gain {np.abs(Kx).max():.4g}")
print("  in-plane modes, PD alone -> PD + LQR (continuous time):")
for k, (a, b) in enumerate(zip(np.flatnonzero(plane_pd)[:4], np.flatnonzero(plane_cl)[:4])):
    print(f"    {f_pd[a]:8.4f} Hz, damping ratio {z_pd[a]:.4f} -> {f_cl[b]:8.4f} Hz, damping ratio {z_cl[b]:.4f}")
print(f"  out-of-plane modes unchanged (the lowest: {f_cl[~plane_cl][0]:.4f} Hz, damping ratio {z_cl[~plane_cl][0]:.4f})")
for r, K in ((R_U, Kx), (R_U / 10, lqr(R_U / 10))):
    rho = np.abs(np.linalg.eigvals(Ad - Bd @ K)).max()
    print(f"  R = {r:g} I sampled at {1e-3 / TS:g} kHz: closed-loop spectral radius {rho:.6f} "
          f"({'stable' if rho < 1 else 'UNSTABLE'})")

# 3. The nonlinear arm, PD alone and PD + LQR, and 4. the linear model's prediction.
idx = [sim.coordinate_names.index(s) for s in lin.states]   # the unknowns among all coordinates
STEPS, PULSE_STEPS = round(T_END / TS), round(T_PULSE / TS)


def pulse(k):
    return np.array([0.0, PULSE if k < PULSE_STEPS else 0.0])   # on the elbow


def nonlinear(case, lin, K):
    """The forearm tip (u1, u2) and the joints after every sample; the controller's torques."""
    sim, hold = held(case)
    tips, joints, torques = [], [], []
    for k in range(STEPS):
        x = np.concatenate([sim.q[idx] - lin.q0, sim.v[idx] - lin.v0])
        u = -K @ x if K is not None else np.zeros(2)
        for i, j in enumerate(JOINTS):
            sim.set_reference(j, hold[j][0], 0.0, hold[j][1] + u[i] + pulse(k)[i])
        sim.advance(round((k + 1) * TS, 12))
        y = sim.snapshot()
        tips.append(y["tip_deflection"]["forearm"][:2].copy())
        joints.append([y["q"][j] - hold[j][0] for j in JOINTS])
        torques.append(u)
    return np.array(tips), np.array(joints), np.array(torques)


def linear(lin, K):
    """The same experiment on the discretised linear model: the forearm tip (u1, u2) after every sample."""
    A, B, C, _ = lin.state_space()
    E = sl.expm(np.block([[A, B], [np.zeros((B.shape[1], n2 + B.shape[1]))]]) * TS)
    Ad, Bd = E[:n2, :n2], E[:n2, n2:]
    tip = [lin.outputs.index("forearm/tip_u1"), lin.outputs.index("forearm/tip_u2")]
    x, out = np.zeros(n2), []
    for k in range(STEPS):
        x = Ad @ x + Bd @ (-K @ x + pulse(k))
        out.append(C[tip] @ x)
    return np.array(out)


def gap(nl, lin_):
    """Largest |nonlinear - linear| of the tip's u1 over the linear prediction's peak."""
    return np.abs(nl[:, 0] - lin_[:, 0]).max() / np.abs(lin_[:, 0]).max()


t = TS * np.arange(1, STEPS + 1)
last = t > T_END - 1.0 + 1e-9                      # the last second
results = {}
for label, K in (("PD alone", None), ("PD + LQR", Kx)):
    tips, joints, torques = nonlinear(case, lin, K)
    mag = np.hypot(tips[:, 0], tips[:, 1])
    results[label] = (tips, np.sqrt(np.mean(mag[last] ** 2)))
    print(f"{label}: peak |tip| {mag.max():.6e} m; last second: RMS {results[label][1]:.6e} m, peak {mag[last].max():.6e} m; "
          f"joints' largest excursion {np.abs(joints[:, 0]).max():.4e}, {np.abs(joints[:, 1]).max():.4e} rad")
    if K is not None:
        print(f"  LQR torque: peak |u| shoulder {np.abs(torques[:, 0]).max():.4f} N m, elbow {np.abs(torques[:, 1]).max():.4f} N m")
rms_pd, rms_lqr = results["PD alone"][1], results["PD + LQR"][1]
print(f"residual vibration of the forearm tip (RMS, last second): {1 - rms_lqr / rms_pd:.1%} below the PD alone")

tips = results["PD + LQR"][0]
predicted = linear(lin, Kx)
print("PD + LQR, forearm tip u1 [m]: nonlinear arm against the linear model's prediction")
for tk in (0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0):
    k = round(tk / TS) - 1
    print(f"  t = {tk:4.2f} s: {tips[k, 0]:+.6e}  linear {predicted[k, 0]:+.6e}")
pd_gap = gap(results["PD alone"][0], linear(lin, np.zeros_like(Kx)))
print(f"  largest difference {gap(tips, predicted):.2%} of the peak (the PD alone: {pd_gap:.2%})")

# The difference is the drives' friction (linearised at rest, its smoothing left behind by the swing):
# the same Kx on the arm without it, against that arm's own linear model.
smooth = case.with_values({"joints.0.drive.friction": 0.0, "joints.1.drive.friction": 0.0})
lin0 = held(smooth)[0].linearize()
d = gap(nonlinear(smooth, lin0, Kx)[0], linear(lin0, Kx))
print(f"  drives without friction, the same Kx: the nonlinear arm stays within "
      f"{10 ** math.ceil(math.log10(d)):.0e} of the linear prediction's peak")
