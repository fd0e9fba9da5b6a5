"""rfem.plots and rfem.animate as modules: figures drawn onto the caller's own matplotlib Axes with
the run's data (from memory and from the results file), new Figures outside pyplot's care, the
figures of `rfem plot` written in-process, one-line errors, and `python3 -m rfem.plots`."""
import os
import subprocess
import sys

import numpy as np
import pytest

import rfem
import rfem.plots as plots

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CASES = os.path.join(ROOT, "cases")


@pytest.fixture(scope="module")
def paper(tmp_path_factory):
    out = tmp_path_factory.mktemp("plots") / "paper.h5"
    case = rfem.load(os.path.join(CASES, "paper_deployment.toml"), overrides=["simulation.t_end=3"])
    return rfem.run(case, n=4, output=out, threads=1), out


def test_draws_onto_the_users_axes(paper):
    runs, path = paper
    force = runs["force"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    try:
        assert plots.tip(force, "u1", ax=right) is fig  # from memory: the run rfem.run returned
        assert not left.lines and len(right.lines) == 1
        t, y = right.lines[0].get_data()
        assert np.array_equal(t, force.column("time", 0)) and np.array_equal(y, force.column("tip_deflection", 0))
        assert right.get_legend_handles_labels()[1] == ["u1"]
        # from the file: the rigid run's joint torques, one line per joint, on the other Axes
        assert plots.joint(str(path), "joint_tau", ax=left, name="rigid") is fig
        tau = runs["rigid"].table("joint_tau")
        assert len(left.lines) == tau.shape[1]
        for j, line in enumerate(left.lines):
            assert np.allclose(line.get_ydata(), tau[:, j], rtol=0, atol=0)
        # the paper's Figure 6 onto an Axes: rigid against flexible joint-3 torque
        fig2, ax = plt.subplots()
        plots.paper_figure(runs, 6, ax=ax)
        assert [l.get_label() for l in ax.lines] == ["rigid link 3", "flexible link 3 (kinematic input)"]
        assert np.array_equal(ax.lines[1].get_ydata(), runs["kinematic"].column("joint_tau", 2))
        plt.close(fig2)
    finally:
        plt.close(fig)


def test_new_figures_stay_out_of_pyplot(paper):
    runs, path = paper
    before = plt.get_fignums()
    figs = [plots.tips(runs["force"]), plots.joints(runs["kinematic"]), plots.energy(path),
            plots.paper_figure(path, 5), plots.paper_figure(runs, 8)]
    assert plt.get_fignums() == before  # Jupyter shows a returned Figure once; nothing piles up in a loop
    assert [len(f.axes) for f in figs] == [3, 3, 2, 3, 2]
    assert np.array_equal(figs[0].axes[2].lines[0].get_ydata(), runs["force"].column("tip_deflection", 2))
    # several panels into the caller's Figure
    fig = plt.figure()
    try:
        assert plots.energy(runs["force"], fig=fig) is fig and len(fig.axes) == 2
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="component"):
        plots.tip(runs["force"], "u3")


def test_refinement_from_memory(paper):
    case = rfem.load(os.path.join(CASES, "paper_deployment.toml"),
                     overrides=["simulation.t_end=2", 'simulation.procedure="single"'])
    result = rfem.refine(case, ns=[2, 4, 8], quantities=["peak:u1"], integration_check=False)
    fig = plots.refinement(result)
    ax = fig.axes[0]
    x, err = ax.lines[0].get_data()
    t = result.table("peak:u1")
    if np.isfinite(t["reference"]):
        assert np.allclose(err, np.abs(t["value"] - t["reference"])[:len(err)])
    else:
        assert np.allclose(err, np.abs(np.diff(t["value"])))
    assert "peak:u1" in ax.get_title()


def test_plot_writes_in_process(paper, tmp_path, monkeypatch):
    _, path = paper

    def no_subprocess(*args, **kwargs):
        raise AssertionError("rfem.plot started a process")

    monkeypatch.setattr(subprocess, "run", no_subprocess)
    monkeypatch.setattr(subprocess, "Popen", no_subprocess)
    written = rfem.plot(path, outdir=tmp_path / "figs")
    names = sorted(os.path.basename(p) for p in written)
    assert names[:4] == ["fig5_tip.png", "fig6_torque3.png", "fig7_velocity3.png", "fig8_accel12.png"]
    assert all(os.path.getsize(p) > 0 for p in written) and "rigid_tip.png" not in names
    bad = tmp_path / "bad.h5"
    bad.write_text("not hdf5")
    with pytest.raises(RuntimeError, match=r"bad\.h5: not an HDF5 file$") as e:
        rfem.plot(bad)
    assert isinstance(e.value, plots.PlotError)


def test_module_command_line(paper, tmp_path):
    _, path = paper
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(rfem.__file__)))
    p = subprocess.run([sys.executable, "-m", "rfem.plots", str(tmp_path / "none.h5")], capture_output=True, text=True,
                       env=env)
    assert p.returncode == 2 and p.stderr == f"rfem plot: error: {tmp_path / 'none.h5'}: no such file\n"
    p = subprocess.run([sys.executable, "-m", "rfem.plots", str(path), "-o", str(tmp_path / "f"), "--format", "svg"],
                       capture_output=True, text=True, env=env)
    assert p.returncode == 0 and p.stdout.splitlines()[0] == f"wrote {tmp_path / 'f' / 'fig5_tip.svg'}"


def test_animation_frame_onto_axes(tmp_path):
    out = tmp_path / "arm.h5"
    rfem.run(rfem.load(os.path.join(CASES, "two_link_arm.toml"),
                       overrides=["simulation.t_end=0.2", "simulation.store_flexible_every=1"]), n=4, output=out,
             keep_series=False)
    import rfem.animate as animate
    assert callable(rfem.animate) and rfem.animate is animate  # the module, called as rfem.animate(...) always was
    fig, (a, b) = plt.subplots(1, 2)
    try:
        assert animate.frame(out, view="xy", scale=50, ax=b) is fig and not a.lines
        lines = {l.get_label(): l for l in b.lines}
        assert {"link upper", "link forearm", "payload of forearm"} <= set(lines)
        assert "payload of forearm" in b.get_legend_handles_labels()[1]
        # the payload (at the forearm's tip) drawn with the link's magnification: at the drawn tip
        link = lines["link forearm"].get_xydata()
        assert np.allclose(lines["payload of forearm"].get_xydata()[0], link[-1])
        poses = animate.Poses(out)
        last = len(poses.t) - 1
        assert np.allclose(link, poses.axis("forearm", last, 50)[:, :2])
    finally:
        plt.close(fig)
    anim = animate.animation(out, frames=3, view="xz")
    assert anim.frames == 3 and "<script" in anim.to_jshtml()
