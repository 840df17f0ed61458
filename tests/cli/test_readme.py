#!/usr/bin/env python3
"""Every shell example of the README and of the user guides runs as written in a fresh copy of
the repository.

Usage: test_readme.py SOURCE_DIR DDEMAP_BINARY [FILE.md ...]

Which files: README.md, every docs/guide/*.md, and any other Markdown file under docs/ that
contains the line `<!-- test_readme: run -->` (the opt-in marker for a page whose examples are
meant to be run). Given FILE.md arguments (paths relative to SOURCE_DIR), only those run.

Which lines: the lines after "$ " in plain code blocks (a fence with no language; the lines
without "$ " there are the printed output and are not checked) and every line of sh, bash and
shell blocks; a trailing "# comment" is dropped and a trailing backslash continues a command.
Blocks marked console, text, json, python and so on are shown, not run: use console for a command
that needs something the fresh copy does not have (the Python module, mpirun, data that is not in
the repository).

How: each file runs on its own, its commands in order with bash, in a temporary copy of the
source tree (without build*/, out/ or .git) in which build/ddemap is the binary under test and
`ddemap` is on PATH, so that a file an example needs must be in the repository or made by an
earlier example of the same file. Left out, and said so: scripts/*.sh and cmake/ctest lines (they
install, build and run the whole suite; the ctest run itself covers them).
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

SKIP = re.compile(r"^(scripts/|cmake |ctest )")


def examples(readme):
    out = []
    block = None  # None outside a code block, else its language
    pending = None  # (line number, text) of a command continued with a trailing backslash
    for number, line in enumerate(readme.splitlines(), 1):
        if pending is not None and block is not None and not line.startswith("```"):
            text = pending[1] + " " + line.strip()
            if text.endswith("\\"):
                pending = (pending[0], text[:-1].rstrip())
            else:
                out.append((pending[0], text))
                pending = None
            continue
        fence = re.match(r"^```\s*(\S*)", line)
        if fence:
            block = None if block is not None else fence.group(1)
            continue
        if block is None:
            continue
        if block == "":
            if not line.startswith("$ "):
                continue
            command = line[2:]
        elif block in ("sh", "bash", "shell"):
            command = line
        else:
            continue
        command = re.sub(r"\s+#\s.*$", "", command).strip()
        if not command or command.startswith("#"):
            continue
        if command.endswith("\\"):
            pending = (number, command[:-1].rstrip())
            continue
        out.append((number, command))
    return out


MARKER = "<!-- test_readme: run -->"


def documents(source, only):
    """The Markdown files whose examples run, relative to source, README.md first."""
    if only:
        return list(only)
    files = ["README.md"]
    guide = os.path.join(source, "docs", "guide")
    if os.path.isdir(guide):
        files += sorted(os.path.join("docs", "guide", n) for n in os.listdir(guide) if n.endswith(".md"))
    for root, dirs, names in os.walk(os.path.join(source, "docs")):
        dirs.sort()
        for n in sorted(names):
            rel = os.path.relpath(os.path.join(root, n), source)
            if n.endswith(".md") and rel not in files:
                with open(os.path.join(root, n), encoding="utf-8") as f:
                    if MARKER in f.read():
                        files.append(rel)
    return files


def fresh_copy(source, binary, tmp):
    """A copy of the source tree in tmp with build/ddemap and `ddemap` on PATH: (folder, environment)."""
    work = os.path.join(tmp, "clone")
    shutil.copytree(source, work, symlinks=True,
                    ignore=lambda d, names: [n for n in names if d == source and (n.startswith("build") or n in (".git", "out"))])
    os.makedirs(os.path.join(work, "build"))
    os.symlink(binary, os.path.join(work, "build", "ddemap"))
    bindir = os.path.join(tmp, "bin")
    os.makedirs(bindir)
    os.symlink(binary, os.path.join(bindir, "ddemap"))
    env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
    return work, env


def main():
    source, binary = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    total = failures = 0
    for doc in documents(source, sys.argv[3:]):
        with open(os.path.join(source, doc), encoding="utf-8") as f:
            cases = examples(f.read())
        if doc == "README.md":
            assert len(cases) >= 5, "too few README examples found: %d" % len(cases)
        total += len(cases)
        with tempfile.TemporaryDirectory() as tmp:
            work, env = fresh_copy(source, binary, tmp)
            for number, command in cases:
                if SKIP.match(command):
                    print("skip  %s:%d: %s" % (doc, number, command))
                    continue
                start = time.time()
                r = subprocess.run(["bash", "-c", command], cwd=work, env=env, capture_output=True, text=True, timeout=600)
                took = time.time() - start
                if r.returncode != 0:
                    failures += 1
                    print("FAIL  %s:%d: %s (exit %d, %.1f s)\n      %s" % (doc, number, command, r.returncode, took, r.stderr.strip()[:500]))
                else:
                    print("ok    %s:%d: %s (%.1f s)" % (doc, number, command, took))
                sys.stdout.flush()
    assert total >= 10, "too few examples found: %d" % total
    print("%d examples, %d failed" % (total, failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
