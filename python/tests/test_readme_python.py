"""The Python examples of README.md run as written (from the repository's
top folder, as a reader of the README runs them), each block in a fresh namespace."""
import os
import re
import shutil

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def python_blocks(path):
    text = open(os.path.join(ROOT, path), encoding="utf-8").read()
    return [(path, m.start(), m.group(1)) for m in re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M)]


BLOCKS = python_blocks("README.md")


@pytest.mark.slow
@pytest.mark.parametrize("path,offset,code", BLOCKS, ids=["%s@%d" % (p, o) for p, o, _ in BLOCKS])
def test_readme_python_block(path, offset, code, tmp_path, monkeypatch):
    # a copy of what the examples read, so that what they write stays out of the source tree
    for folder in ("examples", "tests/data", "data"):
        if os.path.isdir(os.path.join(ROOT, folder)):
            shutil.copytree(os.path.join(ROOT, folder), tmp_path / folder)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "%s (block at offset %d)" % (path, offset), "exec"), {})


def test_readme_has_python_examples():
    assert BLOCKS, "README.md has no python block"
