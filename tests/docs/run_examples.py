#!/usr/bin/env python3
"""Runs every shell and Python example of README.md and docs/**/*.md as written.

Convention (what an example may assume):

- Every fenced block whose info string is ``sh``, ``bash`` or ``shell`` is a shell example. It runs
  under ``bash -e -o pipefail`` in a fresh temporary folder, with the built ``geardiag`` first on
  PATH (as after ``export PATH="$PWD/build:$PATH"``), and with ``testdata`` in that folder a link
  to the repository's ``testdata/``; ``python3`` is the interpreter given by ``--python``
  (Debian's ``/usr/bin/python3``, with numpy, scipy and h5py). So an example written to be run from the repository's root
  (``geardiag info --gearbox testdata/gearbox/three_shaft.json``) runs here unchanged, and the files
  it writes land in the temporary folder. ``GEARDIAG_REPO`` holds the repository's root.
- Every ``python`` block runs the same way with ``/usr/bin/python3`` and ``PYTHONPATH`` set to the
  built module's folder (``build/python``); when the module was not built, Python blocks are
  skipped with a message.
- An HTML comment on the line just before the fence changes that:
    ``<!-- example: continues -->``    run in the folder of the previous block of the same file,
                                       after it (a tour split into steps);
    ``<!-- example: needs-data -->``   needs data the user brings (not shipped): skipped, listed;
    ``<!-- example: skip: REASON -->`` not run here (it builds or installs the project, or runs
                                       for minutes): skipped, listed with its reason.
  A ``sh-needs-data`` (or ``bash-needs-data``) fence is the same as the needs-data comment.
- A shell example must be fenced and labelled: an indented code block whose first line calls
  ``geardiag``, or a fence without a language holding a ``geardiag`` command, fails the run, so
  that no example escapes this test. Synopses and output go in ``text`` fences.

A failing block is reported with its file and line, its exit code and the end of its output;
the script exits 1 when any block failed, 0 otherwise. Blocks run one at a time, each with a time
limit (``--timeout``); examples keep their durations short: the whole run costs about 105 s of
CPU (under two minutes on two idle cores). Each block's wall and CPU time is printed.

Usage: run_examples.py --geardiag BUILD/geardiag [--repo DIR] [--python-dir BUILD/python]
                       [--only PATH_SUBSTRING] [--keep] [--list]
"""
import argparse
import os
import pathlib
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

SHELL_LANGS = {"sh", "bash", "shell"}
NEEDS_DATA_LANGS = {"sh-needs-data", "bash-needs-data"}
MARKER = re.compile(r"^\s*<!--\s*example:\s*(continues|needs-data|skip\s*:\s*(.+?))\s*-->\s*$")
FENCE = re.compile(r"^(\s*)(```+|~~~+)\s*([\w+-]*)")


class Block:
    def __init__(self, path, line, lang, text, marker, reason):
        self.path = path
        self.line = line  # 1-based line of the opening fence
        self.lang = lang
        self.text = text
        self.marker = marker  # None, "continues", "needs-data" or "skip"
        self.reason = reason

    def where(self, repo):
        return f"{self.path.relative_to(repo)}:{self.line}"


def extract(path):
    """The fenced blocks of one Markdown file, and the unfenced shell examples (errors)."""
    lines = path.read_text(encoding="utf-8").split("\n")
    blocks, unfenced = [], []
    i = 0
    in_fence = False
    while i < len(lines):
        m = FENCE.match(lines[i])
        if m and not in_fence:
            indent, fence, lang = m.group(1), m.group(2), m.group(3).lower()
            start = i
            body = []
            i += 1
            while i < len(lines) and not lines[i].strip().startswith(fence):
                body.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i])
                i += 1
            marker, reason = None, ""
            prev = lines[start - 1] if start > 0 else ""
            mm = MARKER.match(prev)
            if mm:
                marker = "skip" if mm.group(1).startswith("skip") else mm.group(1)
                reason = mm.group(2) or ""
            if lang in NEEDS_DATA_LANGS:
                marker, lang = "needs-data", "sh"
            if not lang and any(re.match(r"\s*(\$\s*)?geardiag\s", row) for row in body):
                unfenced.append(start + 1)
            if lang in SHELL_LANGS or lang == "python":
                blocks.append(Block(path, start + 1, "python" if lang == "python" else "sh",
                                    "\n".join(body) + "\n", marker, reason))
            i += 1
            continue
        # An indented code block (after a blank line, outside a list item's text) that calls
        # geardiag: a shell example this script would not see.
        if (lines[i].startswith("    ") and lines[i].strip().startswith("geardiag ")
                and i > 0 and lines[i - 1].strip() == ""):
            unfenced.append(i + 1)
        i += 1
    return blocks, unfenced


def tail(text, n=25):
    rows = text.strip().split("\n")
    return "\n".join(("    " + r) for r in rows[-n:])


def main():
    here = pathlib.Path(__file__).resolve().parent
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--geardiag", required=True, help="the built geardiag binary")
    ap.add_argument("--repo", default=str(here.parent.parent), help="the repository's root")
    ap.add_argument("--python-dir", default=None,
                    help="folder holding the built Python package geardiag (build/python)")
    ap.add_argument("--python", default="/usr/bin/python3")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per block")
    ap.add_argument("--only", default=None, help="run only files whose path contains this")
    ap.add_argument("--keep", action="store_true", help="keep the temporary folders")
    ap.add_argument("--list", action="store_true", help="list the blocks and exit")
    args = ap.parse_args()

    repo = pathlib.Path(args.repo).resolve()
    geardiag = pathlib.Path(args.geardiag).resolve()
    if not geardiag.is_file() or not os.access(geardiag, os.X_OK):
        print(f"run_examples: --geardiag {geardiag}: not an executable file", file=sys.stderr)
        return 2
    files = [repo / "README.md"] + sorted((repo / "docs").rglob("*.md"))
    if args.only:
        files = [f for f in files if args.only in str(f.relative_to(repo))]

    python_ok = False
    python_why = "no --python-dir given"
    if args.python_dir:
        pkg = pathlib.Path(args.python_dir) / "geardiag"
        if pkg.is_dir() and any(pkg.glob("_geardiag*.so")):
            python_ok = True
        else:
            python_why = f"the module is not built ({pkg} holds no _geardiag*.so)"

    # python3 in an example is the interpreter of --python (Debian's, with numpy, scipy, h5py).
    shims = pathlib.Path(tempfile.mkdtemp(prefix="geardiag-example-bin-"))
    (shims / "python3").symlink_to(args.python)
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(geardiag.parent), str(shims), env.get("PATH", "")])
    env["GEARDIAG_REPO"] = str(repo)
    if python_ok:
        env["PYTHONPATH"] = str(pathlib.Path(args.python_dir).resolve())
    env.setdefault("MPLBACKEND", "Agg")

    failures, skipped, ran, cpu_all = [], [], 0, 0.0
    all_blocks = []
    for f in files:
        blocks, unfenced = extract(f)
        for line in unfenced:
            failures.append((f"{f.relative_to(repo)}:{line}",
                             "a shell example outside a ```sh fence: fence and label it (or use ```text for output)"))
        all_blocks.extend(blocks)
    if args.list:
        for b in all_blocks:
            print(f"{b.where(repo)}\t{b.lang}\t{b.marker or 'run'}\t{b.reason}")
        return 0

    # Tools the examples call besides geardiag and the shell's own (scripts/install-deps installs
    # them): a missing one is named once rather than failing every block that uses it.
    for tool in ("jq", "awk"):
        used = [b for b in all_blocks if b.lang == "sh" and b.marker in (None, "continues")
                and re.search(rf"\b{tool}\b", b.text)]
        if used and shutil.which(tool) is None:
            print(f"run_examples: {tool} is not on PATH (scripts/install-deps installs it); "
                  f"{len(used)} examples need it, e.g. {used[0].where(repo)}", file=sys.stderr)
            return 1

    start_all = time.monotonic()
    folder, folder_file, folder_ok = None, None, True
    made = []
    for b in all_blocks:
        where = b.where(repo)
        if b.marker == "needs-data":
            skipped.append((where, "needs data the user brings"))
            continue
        if b.marker == "skip":
            skipped.append((where, b.reason))
            continue
        if b.lang == "python" and not python_ok:
            skipped.append((where, f"Python example: {python_why}"))
            continue
        if b.marker == "continues":
            if folder is None or folder_file != b.path:
                failures.append((where, "marked 'continues' but no earlier block of this file ran"))
                continue
            if not folder_ok:
                failures.append((where, "not run: the block it continues failed"))
                continue
        else:
            folder = pathlib.Path(tempfile.mkdtemp(prefix="geardiag-example-"))
            made.append(folder)
            (folder / "testdata").symlink_to(repo / "testdata")
            folder_file, folder_ok = b.path, True
        if b.lang == "sh":
            cmd = ["bash", "-e", "-o", "pipefail", "-c", b.text]
        else:
            cmd = [args.python, "-c", b.text]
        t0 = time.monotonic()
        c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        try:
            r = subprocess.run(cmd, cwd=folder, env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, timeout=args.timeout)
            code, out = r.returncode, r.stdout
        except subprocess.TimeoutExpired as e:
            code = f"timeout after {args.timeout:.0f} s"
            out = e.stdout.decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
        dt = time.monotonic() - t0
        c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)
        cpu_all += cpu
        ran += 1
        if code == 0:
            print(f"ok    {where} ({b.lang}, {dt:.1f} s, CPU {cpu:.1f} s)", flush=True)
        else:
            folder_ok = False
            failures.append((where, f"exit {code}\n  block:\n{tail(b.text, 40)}\n  output:\n"
                                    f"{tail(out)}"))
            print(f"FAIL  {where} ({b.lang}, {dt:.1f} s): exit {code}", flush=True)

    shutil.rmtree(shims, ignore_errors=True)
    if not args.keep:
        for d in made:
            shutil.rmtree(d, ignore_errors=True)

    print(f"\n{ran} examples run in {time.monotonic() - start_all:.1f} s ({cpu_all:.1f} s of CPU), "
          f"{len(skipped)} skipped, "
          f"{len(failures)} failed")
    for where, why in skipped:
        print(f"skipped {where}: {why}")
    for where, why in failures:
        print(f"\nFAILED {where}: {why}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
