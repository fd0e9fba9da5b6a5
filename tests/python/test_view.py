"""The ParaView files of `rfem run` / `rfem view` / rfem.write_xdmf, read as an XDMF reader does
(the times of the temporal grids, each grid's hyperslab row of the HDF5 tables) and compared with
the series the run wrote: the last axis point is the link's tip, the base polyline the joint
origins; the axis points are the rfes' stations, moved rigidly with {r} when the link does not bend;
the frames are rotations, {r} at the start and turned by the tip's rotation at the tip."""
import os
import subprocess
import xml.etree.ElementTree as ET

import h5py
import numpy as np
import pytest

import rfem

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RFEM = os.environ.get("RFEM", os.path.join(ROOT, "build", "apps", "rfem"))


def grids(xdmf):
    """{collection name: [(time, {item: (dataset path, row, points)})]} as a reader selects them."""
    out = {}
    for col in ET.parse(xdmf).getroot().iter("Grid"):
        if col.get("CollectionType") != "Temporal":
            continue
        steps = []
        for g in col.findall("Grid"):
            items = {}
            for kind in ("Geometry", "Attribute"):
                for e in g.findall(kind):
                    slab = e.find("DataItem")
                    sel, data = slab.findall("DataItem")
                    start = [int(v) for v in sel.text.split()]
                    rows, cols = (int(v) for v in data.get("Dimensions").split())
                    assert start[2:4] == [1, 1] and start[4] == 1 and start[5] == cols, "one whole row per step"
                    width = int(slab.get("Dimensions").split()[1])  # 3: points, vectors; 9: frames
                    items[e.get("Name", kind)] = (data.text.split(":")[1], start[0], cols // width)
            steps.append((float(g.find("Time").get("Value")), items))
        out[col.get("Name")] = steps
    return out


def test_xdmf_points_are_the_runs_positions(tmp_path):
    out = tmp_path / "arm.h5"
    p = subprocess.run([RFEM, "run", os.path.join(ROOT, "cases", "two_link_arm.toml"), "--n", "8", "-q", "-o", str(out),
                        "--set", "simulation.t_end=0.3", "--set", "simulation.store_flexible_every=3"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    xdmf = tmp_path / "arm.run.xdmf"
    assert xdmf.exists()
    f = h5py.File(out)
    g = f["run"]
    t_out = g["time"][:, 0]
    G = grids(xdmf)
    links = [k for k in G if k != "base" and not k.endswith("_payloads")]
    assert sorted(links) == sorted(g["links"].keys())
    for name in links:
        steps = G[name]
        assert np.allclose([s[0] for s in steps], g["flexible_time"][:, 0], rtol=0, atol=1e-12)
        assert len(steps) == len(range(0, len(t_out), 3))
        for t, items in steps:
            path, row, points = items["Geometry"]
            pos = f[path][row].reshape(points, 3)
            k = int(np.argmin(abs(t_out - t)))
            # the last point is the tip the run wrote at the same time (to round-off)
            assert np.allclose(pos[-1], g["links"][name]["tip_position"][k], rtol=0, atol=1e-12)
            dpath, drow, _ = items["deflection"]
            d = f[dpath][drow].reshape(points, 3)
            # undeformed = deformed − deflection: a straight line through the stations, as long as the link
            u = pos - d
            L = np.linalg.norm(u[-1] - u[0])
            e = (u[-1] - u[0]) / L
            assert np.allclose(np.cross(u - u[0], e), 0.0, atol=1e-12)
            # ... whose points sit at the link's start, its rfes' stations and its end
            stations = (u - u[0]) @ e
            assert np.allclose(stations[1:-1], f[f"run/links/{name}/rfe_centre"][:, 0], rtol=0, atol=1e-12)
            assert abs(L - 1.0) < 1e-12  # both links of two_link_arm.toml are 1 m long
            # each station's frame: a rotation; {r} at the start, whose x axis is the undeformed axis
            fpath, frow, fpoints = items["frame"]
            assert fpoints == points
            R = f[fpath][frow].reshape(points, 3, 3)
            assert np.allclose(R @ R.transpose(0, 2, 1), np.eye(3), atol=1e-12)
            assert np.allclose(np.linalg.det(R), 1.0, atol=1e-12)
            assert np.allclose(R[0][:, 0], e, atol=1e-12)
            # the tip's frame is turned from {r} by the tip rotation φ the run wrote (rx, ry, rz in
            # {r}): R_r^T R_tip = I + [φ]x up to terms of order |φ|²
            phi = g["links"][name]["tip"][k][3:]
            skew = np.array([[0, -phi[2], phi[1]], [phi[2], 0, -phi[0]], [-phi[1], phi[0], 0]])
            assert np.allclose(R[0].T @ R[-1], np.eye(3) + skew, atol=2 * np.dot(phi, phi) + 1e-14)
    # the base: a polyline through the joint origins at the same output row
    for t, items in G["base"]:
        path, row, points = items["Geometry"]
        assert abs(t_out[row] - t) < 1e-12
        assert np.array_equal(f[path][row], g["joint_position"][row])


def test_view_of_an_existing_file_and_its_errors(tmp_path):
    out = tmp_path / "d.h5"
    rfem.run(rfem.load(os.path.join(ROOT, "cases", "paper_deployment.toml"),
                       overrides=["simulation.t_end=0.2", "simulation.store_flexible_every=1"]), output=out, keep_series=False)
    written = rfem.write_xdmf(str(out))
    assert [os.path.basename(w) for w in written] == ["d.force.xdmf", "d.kinematic.xdmf"]  # the rigid run has no rfes
    p = subprocess.run([RFEM, "view", str(out), "--run", "force"], capture_output=True, text=True)
    assert p.returncode == 0 and p.stdout.strip() == "ParaView: " + str(tmp_path / "d.force.xdmf")
    # a file without poses: one line, exit 2 (a Python ResultsError with the same message)
    bare = tmp_path / "bare.h5"
    rfem.run(rfem.load(os.path.join(ROOT, "cases", "paper_deployment.toml"), overrides=["simulation.t_end=0.1"]),
             output=bare, keep_series=False)
    p = subprocess.run([RFEM, "view", str(bare)], capture_output=True, text=True)
    msg = f"{bare}: no run stores poses (run with simulation.store_flexible_every > 0)"
    assert p.returncode == 2 and p.stderr == f"rfem: error: {msg}\n"
    with pytest.raises(rfem.ResultsError, match="no run stores poses"):
        rfem.write_xdmf(str(bare))
    assert not list(tmp_path.glob("bare*.xdmf*"))


def test_animate_draws_the_stored_steps(tmp_path):
    out = tmp_path / "arm.h5"
    rfem.run(rfem.load(os.path.join(ROOT, "cases", "two_link_arm.toml"),
                       overrides=["simulation.t_end=0.2", "simulation.store_flexible_every=1"]), n=4, output=out,
             keep_series=False)
    gif = tmp_path / "arm.gif"
    p = subprocess.run([RFEM, "animate", str(out), "-o", str(gif), "--frames", "6", "--view", "xz"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    # frame counts ("\r…") only on a terminal: none in a pipe
    assert p.stderr == "" and p.stdout.startswith(f"wrote {gif} (6 frames, deflection ×")
    from PIL import Image
    im = Image.open(gif)
    assert im.n_frames == 6 and im.size == (720, 540)
    assert rfem.animate(out, output=tmp_path / "b.gif", frames=3, scale=1) == str(tmp_path / "b.gif")
    # no poses, or a format it cannot write: one line, exit 2, nothing written
    bare = tmp_path / "bare.h5"
    rfem.run(rfem.load(os.path.join(ROOT, "cases", "two_link_arm.toml"), overrides=["simulation.t_end=0.1"]), n=4,
             output=bare, keep_series=False)
    for args, msg in (([str(bare)], f"{bare}: no run stores poses"),
                      ([str(out), "-o", str(tmp_path / "x.avi")], f"{tmp_path / 'x.avi'}: write .mp4 or .gif")):
        p = subprocess.run([RFEM, "animate", *args], capture_output=True, text=True)
        assert p.returncode == 2 and p.stderr.strip().splitlines()[-1].startswith("rfem animate: error: " + msg)
    with pytest.raises(RuntimeError, match="no run stores poses"):
        rfem.animate(bare)
    assert not list(tmp_path.glob("*.part*")) and not (tmp_path / "x.avi").exists()
