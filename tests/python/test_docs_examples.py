"""Every ```python block of docs/python.md, run as written (each on its own, in an empty
directory); a failure points at the block's line in the page. The pip install test
(pip_install_check.py) runs this file with the package installed into a fresh venv."""
import os
import re

import pytest

DOC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "python.md")


def blocks():
    with open(DOC, encoding="utf-8") as f:
        text = f.read()
    found = []
    for m in re.finditer(r"^```python\n(.*?)^```$", text, re.S | re.M):
        line = text.count("\n", 0, m.start()) + 2  # the block's first code line
        found.append(pytest.param(line, m.group(1), id="python.md:%d" % line))
    return found


def test_the_page_has_its_examples():
    assert len(blocks()) >= 6


@pytest.mark.parametrize("line,code", blocks())
def test_example(line, code, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    # Padded so that tracebacks give the line in docs/python.md.
    exec(compile("\n" * (line - 1) + code, os.path.abspath(DOC), "exec"), {"__name__": "__docs__"})
