#!/usr/bin/python3
"""`pip install .` into a fresh virtual environment without network, then docs/python.md's
examples run from the installed package (ctest python_pip_install).

    pip_install_check.py SOURCE_DIR BUILD_DIR

The venv sees Debian's packages (--system-site-packages: numpy, pyopenvdb, pytest) but holds no
frepfarm; pip runs with --no-index, no find-links and no configuration file, inside an empty
network namespace (`unshare -n`) where that is allowed (root), so nothing can come from the
network. The build backend packs the extension already built in BUILD_DIR (build-dir and
prebuilt=1: a test never builds), which makes the install seconds. The installed files are
checked against the wheel's RECORD by uninstalling them at the end.
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


def main():
    source, build = (os.path.abspath(a) for a in sys.argv[1:3])
    tmp = tempfile.mkdtemp(prefix="frep-pip-")
    try:
        venv = os.path.join(tmp, "venv")
        if run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", venv]).returncode != 0:
            print("skipped: python3 -m venv failed (python3-venv not installed?)")
            return 77
        py, pip = os.path.join(venv, "bin", "python"), os.path.join(venv, "bin", "pip")
        if not os.path.exists(pip):
            print("skipped: the venv has no pip")
            return 77
        env = {k: v for k, v in os.environ.items() if not k.startswith("PIP_") and k != "PYTHONPATH"}
        env.update(PIP_CONFIG_FILE=os.devnull, PIP_DISABLE_PIP_VERSION_CHECK="1")
        offline = ["unshare", "-n"] if run(["unshare", "-n", "true"]).returncode == 0 else []
        print("network: " + ("none (unshare -n) and --no-index" if offline else
                             "--no-index only (unshare -n not permitted here)"), flush=True)

        r = run(offline + [pip, "install", "--no-index", "--config-settings", "build-dir=" + build,
                           "--config-settings", "prebuilt=1", source],
                env=env, cwd=tmp)
        if r.returncode != 0:
            print("FAIL: pip install exited %d" % r.returncode)
            return 1

        where = subprocess.run([py, "-c", "import frepfarm, frepfarm.shapes; print(frepfarm.__file__)"],
                               env=env, cwd=tmp, capture_output=True, text=True)
        site = os.path.join(venv, "lib")
        if where.returncode != 0 or not where.stdout.strip().startswith(site):
            print("FAIL: frepfarm is not imported from the venv: %s%s" % (where.stdout, where.stderr))
            return 1
        print("imported from " + where.stdout.strip())

        docs = os.path.join(source, "tests", "python", "test_docs_examples.py")
        r = run(offline + [py, "-m", "pytest", "-q", "-p", "no:cacheprovider", docs], env=env, cwd=tmp)
        if r.returncode != 0:
            print("FAIL: the examples of docs/python.md failed from the installed package")
            return 1

        # Uninstalling removes exactly what RECORD lists: nothing of the package may remain.
        r = run([pip, "uninstall", "-y", "frepfarm"], env=env, cwd=tmp)
        left = [os.path.join(d, n) for d, _, names in os.walk(site) for n in names + [""]
                if "frepfarm" in os.path.relpath(os.path.join(d, n), site)]
        if r.returncode != 0 or left:
            print("FAIL: pip uninstall (exit %d) left %s" % (r.returncode, left[:5]))
            return 1
        print("OK: installed offline, examples passed, uninstalled cleanly")
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
