#!/usr/bin/env python3
"""Every shell example of README.md runs as written in a fresh copy of the repository.

Usage: test_readme.py SOURCE_DIR DDEMAP_BINARY

The examples are the lines after "$ " in plain code blocks and every line of ```sh blocks
(a trailing "# comment" is dropped). They run in order with bash in a temporary copy of the
source tree (without build/, out/ or .git) in which build/ddemap is the binary under test and
`ddemap` is on PATH, so that a file an example needs must be in the repository or made by an
earlier example. Left out, and said so: scripts/*.sh and cmake/ctest lines (they install,
build and run the whole suite; the ctest run itself covers them).
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


def main():
    source, binary = sys.argv[1], os.path.abspath(sys.argv[2])
    with open(os.path.join(source, "README.md"), encoding="utf-8") as f:
        cases = examples(f.read())
    assert len(cases) >= 10, "too few README examples found: %d" % len(cases)
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        work = os.path.join(tmp, "clone")
        shutil.copytree(source, work, symlinks=True,
                        ignore=lambda d, names: [n for n in names if d == source and (n.startswith("build") or n in (".git", "out"))])
        shared = os.path.join(source, "..", "shared")
        if os.path.isdir(shared):  # the data beside the clone, as in CI (../shared/data/acc)
            os.symlink(os.path.abspath(shared), os.path.join(tmp, "shared"))
        os.makedirs(os.path.join(work, "build"))
        os.symlink(binary, os.path.join(work, "build", "ddemap"))
        bindir = os.path.join(tmp, "bin")
        os.makedirs(bindir)
        os.symlink(binary, os.path.join(bindir, "ddemap"))
        env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
        for number, command in cases:
            if SKIP.match(command):
                print("skip  README.md:%d: %s" % (number, command))
                continue
            start = time.time()
            r = subprocess.run(["bash", "-c", command], cwd=work, env=env, capture_output=True, text=True, timeout=600)
            took = time.time() - start
            if r.returncode != 0:
                failures += 1
                print("FAIL  README.md:%d: %s (exit %d, %.1f s)\n      %s" % (number, command, r.returncode, took, r.stderr.strip()[:500]))
            else:
                print("ok    README.md:%d: %s (%.1f s)" % (number, command, took))
    print("%d examples, %d failed" % (len(cases), failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
