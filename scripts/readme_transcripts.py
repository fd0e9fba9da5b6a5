#!/usr/bin/python3
"""README transcripts: every block of README.md and docs/*.md that follows a marker

    <!-- transcript -->
    ```
    $ build/apps/rfem modes cases/kane_beam.toml --count 6
    …the output…
    ```

is the real output of its command (stdout; run from the repository root with the given rfem). Checks
them (exit 1 with a diff on a mismatch) or, with --update, rewrites them. Numbers match when they
agree to 1e-7 relative (or 1e-12 absolute): builds for different CPUs differ in
the last digits of the 13 printed (a dense eigen-solution of n = 80: 1e-8 between two builds), not in anything a reader
of the README relies on; any other difference in text or digits is a mismatch.

    /usr/bin/python3 scripts/readme_transcripts.py [--rfem build/apps/rfem] [--update]
"""
import argparse
import difflib
import glob
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BLOCK = re.compile(r"(<!-- transcript -->\n```\n\$ (?P<cmd>[^\n]+)\n)(?P<out>.*?)(```)", re.S)


def run(cmd, rfem, scratch):
    args = shlex.split(cmd)
    if args[0] == "build/apps/rfem":
        args[0] = rfem
    # In a scratch directory that sees the repository's cases/: results files land there.
    env = dict(os.environ, OMP_WAIT_POLICY="PASSIVE")
    p = subprocess.run(args, cwd=scratch, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"readme_transcripts: `{cmd}` exited {p.returncode}: {p.stderr.strip()}")
    return p.stdout


NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def same(expected, got):
    """Text equal, numbers equal to 1e-7 relative (1e-12 absolute)."""
    a, b = NUMBER.split(expected), NUMBER.split(got)
    if a != b:
        return False
    for x, y in zip(NUMBER.findall(expected), NUMBER.findall(got)):
        if x == y:
            continue
        u, v = float(x), float(y)
        if abs(u - v) > max(1e-7 * max(abs(u), abs(v)), 1e-12):
            return False
    return True


def check(path, rfem, scratch, update):
    """Checks (or rewrites) the transcripts of one Markdown file; returns (blocks, differing)."""
    text = open(path).read()
    name = os.path.relpath(path, ROOT)
    bad = 0
    out = []
    pos = 0
    for m in BLOCK.finditer(text):
        got = run(m.group("cmd"), rfem, scratch)
        out.append(text[pos:m.start("out")])
        differs = not same(m.group("out"), got)
        out.append(got if update and differs else m.group("out"))  # round-off stays as written
        pos = m.end("out")
        if differs:
            bad += 1
            if not update:
                sys.stdout.writelines(difflib.unified_diff(m.group("out").splitlines(True), got.splitlines(True),
                                                           name, m.group("cmd")))
    out.append(text[pos:])
    if update and bad:
        open(path, "w").write("".join(out))
    return len(BLOCK.findall(text)), bad


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rfem", default=os.path.join(ROOT, "build", "apps", "rfem"))
    ap.add_argument("--update", action="store_true")
    args = ap.parse_args()
    scratch = tempfile.mkdtemp(prefix="rfem-readme-")
    os.symlink(os.path.join(ROOT, "cases"), os.path.join(scratch, "cases"))
    files = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))
    n = bad = 0
    for path in files:
        k, b = check(path, os.path.abspath(args.rfem), scratch, args.update)
        n, bad = n + k, bad + b
    shutil.rmtree(scratch, ignore_errors=True)
    if args.update:
        print(f"readme_transcripts: {n} transcripts, {bad} updated")
        return 0
    print(f"readme_transcripts: {n} transcripts, {bad} differ" + ("" if bad == 0 else ": run with --update"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
