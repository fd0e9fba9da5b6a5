#!/usr/bin/python3
"""Example 8: your controller in the loop — a digital PD law, a stepped simulation, rollouts from a
saved state.

Kane's 10 m beam on a motor hub (cases/kane_hub_drive.toml: rotor inertia, damping, friction) is
spun up to 2 rad/s in 5 s (Kane's angular acceleration) and then braked.
1. The case's continuous PD law (input kind "pd") against the same law written in Python and run
   at a sample rate by rfem.run_controlled (zero-order hold): the difference in the hub angle falls
   in proportion to the sample time (first order: the hold's delay of half a sample).
2. The brake as a script would write it: rfem.Simulation stepped every 10 ms, reading the hub's
   rate and holding a braking torque; the state at t = 1 s saved.
3. Rollouts from that state (as model-predictive control does): three braking gains, each a new
   simulation from the saved state; the residual tip vibration in the last 0.5 s picks the gain.

    /usr/bin/python3 examples/ex8_control_loop.py        (~4 s)
"""
import math
import os

import numpy as np

import rfem

here = os.path.dirname(os.path.abspath(__file__))
KP, KD, OMEGA, T = 4.0e4, 1.2e4, 2.0, 5.0
base = rfem.load(os.path.join(here, "..", "cases", "kane_hub_drive.toml"),
                 overrides=["link.n=8", "simulation.t_end=7.0", "simulation.output_dt=0.01"])
pd_case = base.with_overrides([f'joints.0.input={{kind="pd", reference={{kind="spinup", Omega={OMEGA}, T={T}}}, '
                               f'kp={KP}, kd={KD}}}'])


def spinup(t):
    """Kane's spin-up law (solvers/inputs.hpp): the hub's reference angle and rate."""
    if t <= T:
        c = T / (2 * math.pi)
        return OMEGA / T * (t * t / 2 + c * c * (math.cos(t / c) - 1)), OMEGA / T * (t - c * math.sin(t / c))
    return OMEGA * (t - T / 2), OMEGA


# 1. Continuous PD against the sampled PD.
continuous = rfem.run(pd_case, threads=1)["run"]
q_c = continuous.column("joint_q", 0)
print(f"continuous PD: {continuous.status}, hub at t = 7 s: {q_c[-1]:.6f} rad, "
      f"peak tip u1 {continuous.peaks['link']['u1']:.6e} m")


def pd(t, y):
    q, qd = spinup(t)
    return {"hub": KP * (q - y["q"]["hub"]) + KD * (qd - y["qd"]["hub"])}


previous = None
for ts in (8e-3, 4e-3, 2e-3):
    r = rfem.run_controlled(base, pd, sample_time=ts, threads=1)
    d = np.abs(r.column("joint_q", 0) - q_c).max()
    order = f", observed order {math.log2(previous / d):.2f}" if previous else ""
    print(f"sampled every {ts * 1e3:g} ms: {r.status}, max |hub angle - continuous| = {d:.2e} rad{order}")
    previous = d

# 2. A stepped simulation: spin up under the sampled PD, then brake from a script.
sim = rfem.Simulation(base, threads=1)
for k in range(500):                      # the spin-up, 5 s in 10 ms samples
    t = sim.time
    sim.set_torque("hub", pd(t, sim.snapshot())["hub"])
    sim.advance(round((k + 1) * 0.01, 12))
state = sim.state()
y = sim.snapshot()
print(f"at t = {sim.time:g} s: hub rate {y['qd']['hub']:.6f} rad/s, tip deflection u1 "
      f"{y['tip_deflection']['link'][0]:.6e} m; state of {len(sim.q)} coordinates saved")
sim.finish()


# 3. Rollouts from the saved state: brake with τ = -g·(hub rate), which gain leaves the least vibration?
def rollout(gain):
    s = rfem.Simulation(base, state=state, threads=1)
    while s.time < s.t_end - 1e-12:
        s.set_torque("hub", -gain * s.snapshot()["qd"]["hub"])
        s.advance(min(s.t_end, round(s.time + 0.01, 12)))
    u1 = s.finish().table("tip_deflection")[:, 0]
    return np.abs(u1[-50:]).max()  # the last 0.5 s


for gain in (1.0e2, 3.0e2, 1.0e3):
    print(f"brake gain {gain:.0e} N m s: residual tip vibration {rollout(gain):.3e} m")
