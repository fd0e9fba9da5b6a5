#!/usr/bin/python3
"""Compare rfem's in-plane tip deflection u1 with the Simbody peer (simbody_spinup).

    /usr/bin/python3 compare.py RFEM.h5 SIMBODY.csv [RFEM.h5 SIMBODY.csv ...] [--group run]

One row per pair: n, peak |u1| of each, relative difference of the peaks, max |Δu1| over the common
output times (and when it occurs), u1 at 15 s and 20 s, wall time of each (and Simbody's CPU time),
the wall-time ratio Simbody/rfem, and the step counts. Run with Debian's /usr/bin/python3 (needs python3-h5py and python3-numpy).
"""
import argparse
import re
import sys

import h5py
import numpy as np


def read_rfem(path, group):
    with h5py.File(path, "r") as f:
        g = f[group]
        status = g.attrs["status"]
        status = status.decode() if isinstance(status, bytes) else str(status)
        return {
            "t": g["time"][:, 0],
            "u1": g["tip_deflection"][:, 0],
            "n": int(g.attrs["n"]),
            "wall": float(g.attrs["wall_time_s"]),
            "steps": int(g.attrs["steps"]),
            "status": status,
        }


def read_simbody(path):
    meta = {"wall": float("nan"), "cpu": float("nan"), "steps": -1, "n": -1}
    header, rows = None, []
    # '#' lines: the first carries n, the last the wall time and steps (absent if the run was cut
    # short). The first other line names the columns.
    with open(path) as fh:
        for line in fh:
            if not line.startswith("#"):
                if header is None:
                    header = line.strip().split(",")
                else:
                    rows.append([float(x) for x in line.split(",")])
                continue
            for key, val in re.findall(r"(\w+)=(\S+)", line):
                if key == "n":
                    meta["n"] = int(val)
                elif key == "wall_time_s":
                    meta["wall"] = float(val)
                elif key == "cpu_time_s":
                    meta["cpu"] = float(val)
                elif key == "steps":
                    meta["steps"] = int(val)
    data = np.array(rows).reshape(-1, len(header))
    return {"t": data[:, header.index("t")], "u1": data[:, header.index("u1")], **meta}


def value_at(t, u, when):
    i = np.flatnonzero(np.abs(t - when) < 1e-9)
    return u[i[0]] if i.size else float("nan")


def compare(r, s):
    # Outputs should be at the same times (0, 0.05, …); interpolate Simbody's only if they are not.
    t = r["t"][r["t"] <= s["t"][-1] + 1e-12]
    if len(t) == len(s["t"]) and np.allclose(t, s["t"], atol=1e-9):
        us = s["u1"]
    else:
        us = np.interp(t, s["t"], s["u1"])
    ur = r["u1"][: len(t)]
    d = np.abs(ur - us)
    i = int(np.argmax(d))
    pr, ps = np.abs(ur).max(), np.abs(us).max()
    return {
        "n": r["n"],
        "peak_rfem": pr,
        "peak_simbody": ps,
        "peak_rel": (ps - pr) / pr,
        "max_du1": d[i],
        "t_max_du1": t[i],
        "du1_over_peak": d[i] / pr,
        "u1_15": (value_at(t, ur, 15.0), value_at(t, us, 15.0)),
        "u1_20": (value_at(t, ur, 20.0), value_at(t, us, 20.0)),
        "wall": (r["wall"], s["wall"]),
        "cpu_simbody": s["cpu"],
        "steps": (r["steps"], s["steps"]),
        "t_end": t[-1],
    }


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", help="pairs: RFEM.h5 SIMBODY.csv")
    ap.add_argument("--group", default="run", help="run group in the HDF5 file (default: run)")
    a = ap.parse_args(argv)
    if len(a.files) % 2:
        ap.error("give files in pairs: RFEM.h5 SIMBODY.csv")

    rows = []
    for h5, csv in zip(a.files[::2], a.files[1::2]):
        r, s = read_rfem(h5, a.group), read_simbody(csv)
        if r["status"] != "completed":
            print(f"warning: {h5}: rfem run status '{r['status']}'", file=sys.stderr)
        if s["n"] not in (-1, r["n"]):
            print(f"warning: n differs: rfem {r['n']}, simbody {s['n']} ({csv})", file=sys.stderr)
        rows.append(compare(r, s))

    hdr = (f"{'n':>4} {'peak|u1| rfem':>14} {'peak|u1| simb':>14} {'rel diff':>10} {'max|du1| [m]':>12}"
           f" {'at t':>6} {'/peak':>9} {'u1(15) rfem':>12} {'u1(15) simb':>12} {'u1(20) rfem':>12}"
           f" {'u1(20) simb':>12} {'wall rfem':>9} {'wall simb':>9} {'cpu simb':>9} {'ratio':>7} {'steps rfem':>10} {'steps simb':>10}")
    print(hdr)
    for c in rows:
        ratio = c["wall"][1] / c["wall"][0] if c["wall"][0] > 0 else float("nan")
        print(f"{c['n']:>4} {c['peak_rfem']:>14.9f} {c['peak_simbody']:>14.9f} {c['peak_rel']:>+10.2e}"
              f" {c['max_du1']:>12.3e} {c['t_max_du1']:>6.2f} {c['du1_over_peak']:>9.2e}"
              f" {c['u1_15'][0]:>12.6f} {c['u1_15'][1]:>12.6f} {c['u1_20'][0]:>12.6f} {c['u1_20'][1]:>12.6f}"
              f" {c['wall'][0]:>9.3f} {c['wall'][1]:>9.2f} {c['cpu_simbody']:>9.2f} {ratio:>7.0f} {c['steps'][0]:>10d} {c['steps'][1]:>10d}")
        if c["t_end"] < 20.0 - 1e-9:
            print(f"     (compared up to t = {c['t_end']:g} s only)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
