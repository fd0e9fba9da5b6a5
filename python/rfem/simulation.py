"""A simulation a script steps, and controllers in the loop (rfem.Simulation, rfem.run_controlled).

    sim = rfem.Simulation(case, n=10)          # the case's initial state (or state=...)
    while sim.time < 1.0:
        y = sim.snapshot()                      # joint q, qd, tau, tips: dicts by name
        sim.set_torque("hub", -50.0 * y["qd"]["hub"])
        sim.advance(sim.time + 1e-3)            # the last step ends exactly there
    state = sim.state()                         # start other simulations from it, save, pickle
    run = sim.finish()                          # the Run (status, peaks, series)

The library's simulation/simulation.hpp does the work; see README.md, "Control in the loop".
"""

import os as _os

from . import _case, _rfem
from ._rfem import SimulationState

__all__ = ["Simulation", "SimulationState", "run_controlled", "load_state"]


def _state(state):
    if state is None or isinstance(state, SimulationState):
        return state
    if isinstance(state, (str, _os.PathLike)):
        return load_state(state)
    raise TypeError(f"state must be an rfem.SimulationState or a file, not {type(state).__name__}")


def _raise(error, result):
    """Raises what a C++ call kept (call_guard.hpp): Ctrl-C as RunInterrupted with the results so
    far in .result, anything else as it was; nothing if it kept nothing."""
    from . import RunInterrupted  # (the package's; imported late: this module is part of it)
    if error is None:
        return
    if isinstance(error, KeyboardInterrupt):
        raise RunInterrupted(result, "interrupted by Ctrl-C; the results so far are in .result") from error
    raise error


def load_state(path):
    """A state saved with SimulationState.save (HDF5) or numpy.savez (.npz with `model`, `packed`),
    or a single run's results file: its newest checkpoint (a run that was interrupted or killed)."""
    path = _os.fspath(path)
    if path.endswith(".npz"):
        import numpy as np
        with np.load(path) as z:
            return SimulationState.unpack(str(z["model"]), z["packed"])
    return SimulationState.load(path)


class Simulation:
    """A run of the case that a script steps, its integrator's state kept between calls.

    case:        an rfem.Case or a case file
    n:           rfes in all links (None: the case's own)
    output:      an HDF5 results file written as it goes (the layout of `rfem run`, group "run")
    state:       start from an rfem.SimulationState (or a file saved from one) of the same model
    threads:     kernel threads (0: the run times one thread against all and keeps the faster, as rfem.run)
    keep_series: keep every series in memory for finish()'s Run

    time, t_end [s]; q, v: every coordinate and rate in the model's order (numpy), named by
    coordinate_names (LINK/rfeK/x1 … phi3, then the joints); joint_names, joint_inputs ("motion",
    "torque" or "feedback"). The integrator is ESDIRK (simulation.integrator = "bdf" is refused).
    One thread at a time: a call from a second thread while another is inside (advance releases the
    GIL) raises RuntimeError; finish() or leaving `with` closes and unlocks the results file."""

    def __init__(self, case, n=None, output=None, state=None, threads=0, keep_series=True):
        # (the arguments are checked by the module: TypeError, ValueError naming them)
        self._sim = _rfem._Simulation(_case(case), n, threads, output, keep_series, _state(state), "rfem.Simulation (Python)")

    time = property(lambda self: self._sim.time, doc="where the simulation is [s]")
    t_end = property(lambda self: self._sim.t_end, doc="the case's simulation.t_end [s]: advance() goes no further")
    q = property(lambda self: self._sim.q, doc="every coordinate (numpy, the model's order)")
    v = property(lambda self: self._sim.v, doc="every rate (numpy, the model's order)")
    coordinate_names = property(lambda self: self._sim.coordinate_names)
    joint_names = property(lambda self: self._sim.joint_names)
    joint_inputs = property(lambda self: self._sim.joint_inputs)
    status = property(lambda self: self._sim.status, doc='"running", "completed", "failed: …", …')
    finished = property(lambda self: self._sim.finished)

    def advance(self, t):
        """Integrates to t [s] (time ≤ t ≤ t_end), the last step ending exactly at t; returns the
        status. Ctrl-C raises RunInterrupted (the rows so far are kept)."""
        status, error = self._sim.advance(t)
        if error is not None:
            _raise(error, self._sim.finish())
        return status

    def set_torque(self, joint, tau):
        """Holds torque (force) tau [N m or N] on a force-input joint from now on (zero-order hold)."""
        self._sim.set_torque(joint, tau)

    def set_reference(self, joint, q, qd=0.0, tau_ff=0.0):
        """Holds the reference of a PD joint: tau = tau_ff + kp (q - joint q) + kd (qd - joint qd)."""
        self._sim.set_reference(joint, q, qd, tau_ff)

    def release(self, joint):
        """The joint follows the case's own law again."""
        self._sim.release(joint)

    def snapshot(self):
        """What a lab measures now: {"t", "q", "qd", "tau": {joint: value}, "tip_position",
        "tip_deflection": {link: array of 3}} (u1, u2 [m], theta [rad] in the link's frame)."""
        return self._sim.snapshot()

    def state(self):
        """The state now (rfem.SimulationState): rfem.Simulation(case, state=...) goes on from it."""
        return self._sim.state()

    def linearize(self, equilibrium=True, dense=False):
        """The linear model about the state now (rfem.LinearModel), the laws in force included: at rest
        (equilibrium=True: accelerations zero, u0 the free joints' torques that hold it) or on the
        motion (the state's own accelerations). Sparse (dense=True: column by column, the reference)."""
        return self._sim.linearize(equilibrium, dense)

    def finish(self):
        """Ends the run (completed at t_end, else "interrupted (stopped)"), closes the file, returns the Run."""
        return self._sim.finish()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.finish()
        return False

    def __repr__(self):
        return f"<rfem.Simulation t = {self.time:g} s of {self.t_end:g} s, {self.status}>"


def run_controlled(case, controller, sample_time, n=None, delay=0, output=None, state=None, threads=0,
                   keep_series=True):
    """Runs the case with controller(t, y) in the loop at t = k * sample_time: y is the snapshot
    there (Simulation.snapshot) and it returns a dict by joint name — a torque [N m or N] for a
    force-input joint, a reference q_ref or (q_ref, qd_ref[, tau_ff]) for a PD joint — held from
    t_{k+delay} until the next output takes effect (zero-order hold). Returns the Run; the
    controller's outputs are in the results file's run/control. An exception in the controller ends
    the run "failed: controller: …" (rows kept); a return that is not a dict of finite numbers by
    known joints raises TypeError or ValueError (the run in .run); Ctrl-C raises RunInterrupted."""
    run, error, bad = _rfem._run_controlled(_case(case), n, threads, output, keep_series, _state(state),
                                            "rfem.run_controlled (Python)", controller, sample_time, delay)
    if error is not None:
        _raise(error, run)
    if bad is not None:
        bad.run = run
        raise bad
    return run
