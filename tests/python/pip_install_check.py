#!/usr/bin/python3
"""`pip install .` into fresh virtual environments without network, then docs/python.md's
examples run from the installed package (ctest python_pip_install).

    pip_install_check.py SOURCE_DIR BUILD_DIR

Two venvs, each installed with pip's --no-index, no find-links and no configuration file, inside
an empty network namespace (`unshare -n`) where that is allowed (root), so nothing can come from
the network:
- a bare one (no system site packages: no numpy, no pyopenvdb, no pytest). NumPy is an extra
  (frepfarm[numpy]), so the install needs nothing but the source tree; the examples that import
  neither numpy nor pyopenvdb run there (exec'd as written, each in an empty directory), and the
  calls that return arrays must raise ModuleNotFoundError naming the extra;
- one with --system-site-packages (Debian's numpy, pyopenvdb, pytest), where every example runs
  (tests/python/test_docs_examples.py).
The build backend packs the extension already built in BUILD_DIR (build-dir and prebuilt=1: a
test never builds), which makes each install seconds. The installed files are checked against
the wheel's RECORD by uninstalling them at the end.
Exit 77 (skipped) when the venv module or pip is missing.
"""
import os
import shutil
import subprocess
import sys
import tempfile


def run(cmd, **kw):
    print("+ " + " ".join(cmd), flush=True)
    return subprocess.run(cmd, **kw)


# Runs in the bare venv: every ```python block of docs/python.md that imports neither numpy nor
# pyopenvdb, as test_docs_examples.py runs them (there is no pytest there); then the array calls.
BARE_RUNNER = r"""
import os, re, sys, tempfile, traceback
doc = sys.argv[1]
text = open(doc, encoding="utf-8").read()
ran = failed = 0
for m in re.finditer(r"^```python\n(.*?)^```$", text, re.S | re.M):
    code, line = m.group(1), text.count("\n", 0, m.start()) + 2
    if re.search(r"^\s*(import|from)\s+(numpy|pyopenvdb)\b", code, re.M):
        continue
    with tempfile.TemporaryDirectory() as d:
        os.chdir(d)
        try:
            exec(compile("\n" * (line - 1) + code, doc, "exec"), {"__name__": "__docs__"})
            print("ok   python.md:%d" % line)
            ran += 1
        except Exception:
            traceback.print_exc()
            print("FAIL python.md:%d" % line)
            failed += 1
        os.chdir("/")
import frepfarm
from frepfarm import shapes as fs
ball = fs.ball(1.0)
calls = {"Model.eval": lambda: ball.eval([0.0, 0.0, 0.0]),
         "Mesh.vertices": lambda: ball.mesh((-2,) * 3, (2,) * 3, res=8).vertices,
         "Mesh.triangles": lambda: ball.mesh((-2,) * 3, (2,) * 3, res=8).triangles,
         "grid": lambda: ball.grid((-1,) * 3, (1,) * 3, res=5)}
for name, call in calls.items():
    try:
        call()
        print("FAIL %s worked without numpy?" % name)
        failed += 1
    except ModuleNotFoundError as e:
        ok = name in str(e) and "frepfarm[numpy]" in str(e)
        print(("ok   " if ok else "FAIL ") + "%s without numpy: %s" % (name, e))
        failed += 0 if ok else 1
print("%d examples ran, %d failed" % (ran, failed))
sys.exit(1 if failed or ran < 2 else 0)
"""


def install(venv, source, build, env, offline, tmp):
    """pip install offline into venv; returns the venv's python or None (the reason printed)."""
    py, pip = os.path.join(venv, "bin", "python"), os.path.join(venv, "bin", "pip")
    r = run(offline + [pip, "install", "--no-index", "--config-settings", "build-dir=" + build,
                       "--config-settings", "prebuilt=1", source],
            env=env, cwd=tmp)
    if r.returncode != 0:
        print("FAIL: pip install exited %d" % r.returncode)
        return None
    where = subprocess.run([py, "-c", "import frepfarm, frepfarm.shapes; print(frepfarm.__file__)"],
                           env=env, cwd=tmp, capture_output=True, text=True)
    if where.returncode != 0 or not where.stdout.strip().startswith(os.path.join(venv, "lib")):
        print("FAIL: frepfarm is not imported from the venv: %s%s" % (where.stdout, where.stderr))
        return None
    print("imported from " + where.stdout.strip())
    return py


def uninstall(venv, env, tmp):
    """Uninstalling removes exactly what RECORD lists: nothing of the package may remain."""
    site = os.path.join(venv, "lib")
    r = run([os.path.join(venv, "bin", "pip"), "uninstall", "-y", "frepfarm"], env=env, cwd=tmp)
    left = [os.path.join(d, n) for d, _, names in os.walk(site) for n in names + [""]
            if "frepfarm" in os.path.relpath(os.path.join(d, n), site)]
    if r.returncode != 0 or left:
        print("FAIL: pip uninstall (exit %d) left %s" % (r.returncode, left[:5]))
        return False
    return True


def main():
    source, build = (os.path.abspath(a) for a in sys.argv[1:3])
    tmp = tempfile.mkdtemp(prefix="frep-pip-")
    try:
        bare, site = os.path.join(tmp, "bare"), os.path.join(tmp, "site")
        for venv, flags in ((bare, []), (site, ["--system-site-packages"])):
            if run(["/usr/bin/python3", "-m", "venv"] + flags + [venv]).returncode != 0:
                print("skipped: python3 -m venv failed (python3-venv not installed?)")
                return 77
            if not os.path.exists(os.path.join(venv, "bin", "pip")):
                print("skipped: the venv has no pip")
                return 77
        env = {k: v for k, v in os.environ.items() if not k.startswith("PIP_") and k != "PYTHONPATH"}
        env.update(PIP_CONFIG_FILE=os.devnull, PIP_DISABLE_PIP_VERSION_CHECK="1")
        offline = ["unshare", "-n"] if run(["unshare", "-n", "true"]).returncode == 0 else []
        print("network: " + ("none (unshare -n) and --no-index" if offline else
                             "--no-index only (unshare -n not permitted here)"), flush=True)
        doc = os.path.join(source, "docs", "python.md")

        # The bare venv: no numpy can be there, nor fetched.
        py = install(bare, source, build, env, offline, tmp)
        if py is None:
            return 1
        if subprocess.run([py, "-c", "import numpy"], env=env, cwd=tmp, capture_output=True).returncode == 0:
            print("FAIL: the bare venv can import numpy: it is not bare")
            return 1
        r = run(offline + [py, "-c", BARE_RUNNER, doc], env=env, cwd=tmp)
        if r.returncode != 0:
            print("FAIL: docs/python.md's examples without numpy, or the array calls' errors, from the bare venv")
            return 1
        if not uninstall(bare, env, tmp):
            return 1

        # The venv with Debian's numpy, pyopenvdb and pytest: every example.
        py = install(site, source, build, env, offline, tmp)
        if py is None:
            return 1
        docs = os.path.join(source, "tests", "python", "test_docs_examples.py")
        r = run(offline + [py, "-m", "pytest", "-q", "-p", "no:cacheprovider", docs], env=env, cwd=tmp)
        if r.returncode != 0:
            print("FAIL: the examples of docs/python.md failed from the installed package")
            return 1
        if not uninstall(site, env, tmp):
            return 1
        print("OK: installed offline into a bare venv and a system-site one, examples passed, uninstalled cleanly")
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
