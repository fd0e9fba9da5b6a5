#!/usr/bin/python3
"""Runs the examples and compares what they print with their answer files (answers/NAME.out),
SUNDIALS' habit: a changed number is a changed result.

    /usr/bin/python3 examples/run_examples.py [--pythonpath build/python] [--cpp BUILD_DIR]
                                              [--only ex1,ex3,notebook] [--update]

The notebook (notebook.ipynb) runs in a Jupyter kernel (Debian's python3-nbclient, python3-ipykernel;
kernel python3, working directory the repository, --pythonpath passed into its environment); what it
prints is its cells' standard output, and a line "[image/png]" or "[text/html]" for each figure or
animation it shows.

Text must match exactly; numbers to a relative 1e-5 (or 1e-12 absolute). Why 1e-5: builds for
different CPUs round differently (an AVX-512 build against a portable one: the shipped cases'
results differ by at most 2.2e-7 relative, where a force-input run takes a different step
sequence; 1e-11 where the steps are the same), and the defaults' own integration error is up to
3e-5 of a peak (README, "Performance"). A tolerance between the two passes round-off and fails on
any change of the physics or of the method's accuracy. A number printed with a decimal point or an
exponent may also differ by one unit of its last printed digit: a value printed to two digits
(a distance 2.5e-04) flips to the next (2.6e-04) when round-off moves it across a rounding
boundary, however small the round-off. Lines starting with "#" are not compared.
"""
import argparse
import difflib
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?|[-+]?\b(?:nan|inf)\b")
RTOL, ATOL = 1e-5, 1e-12
PYTHON = ["ex1_paper_figures", "ex2_refinement", "ex3_parameter_study", "ex4_modes_rotation", "ex5_two_link_pd",
          "ex7_urdf_arm", "ex8_control_loop", "ex9_input_shaping", "ex10_strain_feedback",
          "ex11_urdf_strain_feedback", "ex13_lqr", "ex14_kane_hub_linear",
          "ex15_reduced_force"]
CPP = ["ex6_library", "ex12_controller"]
NOTEBOOKS = ["notebook"]


def last_digit(text):
    """One unit of the last printed digit of a number with a decimal point or an exponent (0: an integer)."""
    mantissa, _, exponent = text.lower().partition("e")
    if "." not in mantissa and not exponent:
        return 0.0
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (int(exponent or 0) - decimals)


def same(expected, got):
    """Whether two outputs agree: the same text between numbers, numbers within tolerance."""
    a, b = expected.splitlines(), got.splitlines()
    if len(a) != len(b):
        return False
    for x, y in zip(a, b):
        if x.startswith("#") and y.startswith("#"):
            continue
        if NUMBER.sub("#", x) != NUMBER.sub("#", y):
            return False
        for p, q in zip(NUMBER.findall(x), NUMBER.findall(y)):
            fp, fq = float(p), float(q)
            if p == q or (fp != fp and fq != fq):
                continue
            # (1.001: a unit's difference computed in binary is a hair above the unit)
            allowed = max(RTOL * max(abs(fp), abs(fq)) + ATOL, 1.001 * min(last_digit(p), last_digit(q)))
            if not abs(fp - fq) <= allowed:
                return False
    return True


class NotebookRun:
    """A notebook executed by nbclient, with what subprocess.run returns: returncode, stdout, stderr."""

    def __init__(self, path, env, timeout=600):
        self.returncode, self.stdout, self.stderr = 0, "", ""
        # finding the kernel imports ipykernel and debugpy here, which warns about Python's frozen modules
        os.environ.setdefault("PYDEVD_DISABLE_FILE_VALIDATION", "1")
        try:
            import nbformat
            from nbclient import NotebookClient
        except ImportError as e:
            self.returncode, self.stderr = -1, f"{e} (apt-get install python3-nbclient python3-nbformat python3-ipykernel)"
            return
        nb = nbformat.read(path, as_version=4)
        client = NotebookClient(nb, kernel_name="python3", timeout=timeout,
                                resources={"metadata": {"path": os.path.dirname(HERE)}})
        with tempfile.TemporaryFile("w+") as log:  # the kernel's own output (debugpy's warnings), shown on failure
            try:
                client.execute(env=env, stdout=log, stderr=log)
            except Exception as e:  # a cell's error (CellExecutionError), a kernel that died or timed out
                log.seek(0)
                self.returncode, self.stderr = 1, f"{e}\n{log.read()}"
        out, err = [], []
        for cell in nb.cells:
            for o in cell.get("outputs", []) if cell.cell_type == "code" else []:
                if o.output_type == "stream":
                    (out if o.name == "stdout" else err).append(o.text)
                elif o.output_type in ("display_data", "execute_result"):
                    shown = [m for m in ("image/png", "text/html") if m in o.data]
                    out.append("[%s]\n" % ", ".join(shown or ["text/plain"]))
        self.stdout = "".join(out)
        self.stderr = "".join(err) + self.stderr


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pythonpath", help="directory holding the rfem package (default: the installed one)")
    ap.add_argument("--cpp", help="where examples/cpp was built (Examples 6 and 12, against the installed library)")
    ap.add_argument("--only", help="comma-separated example names (ex1, ex6, …)")
    ap.add_argument("--update", action="store_true", help="rewrite the answer files")
    args = ap.parse_args()
    env = dict(os.environ, OMP_WAIT_POLICY="PASSIVE")
    if args.pythonpath:
        env["PYTHONPATH"] = os.path.abspath(args.pythonpath)
    jobs = [(name, [sys.executable, os.path.join(HERE, name + ".py")]) for name in PYTHON]
    if args.cpp:
        built = os.path.abspath(args.cpp if os.path.isdir(args.cpp) else os.path.dirname(args.cpp))
        for name in CPP:
            jobs.append((name, [os.path.join(built, name), os.path.join(HERE, "..", "cases")]))
    jobs += [(name, os.path.join(HERE, name + ".ipynb")) for name in NOTEBOOKS]
    if args.only:
        wanted = args.only.split(",")
        jobs = [(n, c) for n, c in jobs if any(n == w or n.startswith(w + "_") for w in wanted)]
    failed = skipped = 0
    for name, cmd in jobs:
        if name in NOTEBOOKS:
            p = NotebookRun(cmd, env)
            if p.returncode == -1 and not args.only:  # asked for all: without Jupyter, the notebook is skipped
                print(f"skip {name}: {p.stderr}")
                skipped += 1
                continue
        else:
            with tempfile.TemporaryDirectory() as scratch:
                p = subprocess.run(cmd, cwd=scratch, capture_output=True, text=True, env=env)
        answer = os.path.join(HERE, "answers", name + ".out")
        if p.returncode != 0:
            print(f"FAIL {name}: exit {p.returncode}\n{p.stderr}")
            failed += 1
            continue
        if args.update:
            with open(answer, "w") as f:
                f.write(p.stdout)
            print(f"wrote {answer}")
            continue
        expected = open(answer).read() if os.path.exists(answer) else ""
        if same(expected, p.stdout):
            print(f"ok   {name}")
        else:
            failed += 1
            print(f"FAIL {name}: its output differs from {answer}:")
            sys.stdout.writelines(difflib.unified_diff(expected.splitlines(True), p.stdout.splitlines(True), answer, "now"))
    print(f"{len(jobs) - failed - skipped} examples agree with their answers, {failed} do not")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
