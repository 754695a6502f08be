"""The PEP 517 build backend of `pip install .` (pyproject.toml; docs/python.md).

Debian 12 has no scikit-build-core, so this backend drives CMake itself, with only the
standard library: it builds the one target frepfarm_python (the extension; pybind11 and CMake
from Debian) and packs it with python/frepfarm/*.py into a wheel, a zip archive with
METADATA, WHEEL and RECORD (PEP 427, PEP 376's RECORD hashes).

Build directory: the config setting `build-dir` (pip -C build-dir=build) or the environment
variable FREPFARM_BUILD_DIR. A directory that is already configured for this source tree is
reused as it is (only the target is brought up to date, its cache is not touched); an empty or
new one is configured there; with neither, a temporary directory is configured and removed.
`prebuilt=1` (or FREPFARM_PREBUILT=1) with a build directory packs the extension already built
there and runs no build at all (the ctest does: tests never build).
"""
import base64
import csv
import hashlib
import io
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from importlib.machinery import EXTENSION_SUFFIXES

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TARGET = "frepfarm_python"


class BuildError(RuntimeError):
    pass


def _project():
    """[project] of pyproject.toml, with the version from CMakeLists.txt's project()."""
    import tomllib  # Python 3.11 and later (Debian 12 has 3.11)
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as f:
        meta = tomllib.load(f)["project"]
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        m = re.search(r"project\(\s*frepfarm\s+VERSION\s+([0-9.]+)", f.read())
    if not m:
        raise BuildError("CMakeLists.txt: no 'project(frepfarm VERSION x.y.z)' to take the version from")
    meta["version"] = m.group(1)
    return meta


def _metadata(meta):
    lines = ["Metadata-Version: 2.1", "Name: " + meta["name"], "Version: " + meta["version"],
             "Summary: " + meta.get("description", "")]
    if "requires-python" in meta:
        lines.append("Requires-Python: " + meta["requires-python"])
    lines += ["Requires-Dist: " + d for d in meta.get("dependencies", [])]
    for extra, deps in sorted(meta.get("optional-dependencies", {}).items()):  # core metadata 2.1
        lines.append("Provides-Extra: " + extra)
        lines += ['Requires-Dist: %s; extra == "%s"' % (d, extra) for d in deps]
    lines += ["License: " + meta["license"]["text"]] if "text" in meta.get("license", {}) else []
    return "\n".join(lines) + "\n"


def _tag():
    interp = "cp%d%d" % sys.version_info[:2]
    if sys.implementation.name != "cpython":
        raise BuildError("the frepfarm extension is built for CPython only")
    platform = re.sub(r"[-.]", "_", sysconfig.get_platform())
    return "%s-%s%s-%s" % (interp, interp, sys.abiflags, platform)


def _wheel_text(tag):
    return "Wheel-Version: 1.0\nGenerator: frepfarm_build (in-tree)\nRoot-Is-Purelib: false\nTag: %s\n" % tag


def _dist_info(meta):
    return "%s-%s.dist-info" % (meta["name"].replace("-", "_"), meta["version"])


def _run(cmd):
    print("frepfarm_build: " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, stdout=sys.stdout, stderr=sys.stderr)
    if r.returncode != 0:
        raise BuildError("command failed (exit %d): %s" % (r.returncode, " ".join(cmd)))


def _cache_home(build_dir):
    """The source directory a configured build directory belongs to, or None."""
    try:
        with open(os.path.join(build_dir, "CMakeCache.txt")) as f:
            for line in f:
                if line.startswith("CMAKE_HOME_DIRECTORY:"):
                    return line.split("=", 1)[1].strip()
    except FileNotFoundError:
        return None
    return None


def _build_extension(build_dir, jobs, prebuilt):
    """Configures build_dir when it is not yet, builds the target, returns the extension's path."""
    home = _cache_home(build_dir)
    if prebuilt and home is None:
        raise BuildError("prebuilt: %s is not a configured build directory" % build_dir)
    if home is None:
        _run(["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release", "-DFREP_BUILD_TESTS=OFF",
              "-DFREP_BUILD_BENCH=OFF", "-DPython3_EXECUTABLE=" + sys.executable])
    elif os.path.realpath(home) != os.path.realpath(ROOT):
        raise BuildError("build directory %s is configured for %s, not %s" % (build_dir, home, ROOT))
    if not prebuilt:
        _run(["cmake", "--build", build_dir, "--target", TARGET, "-j", str(jobs)])
    package = os.path.join(build_dir, "python", "frepfarm")
    suffix = EXTENSION_SUFFIXES[0]
    path = os.path.join(package, "frepfarm" + suffix)
    if not os.path.isfile(path):
        found = [n for n in os.listdir(package) if n.endswith(".so")] if os.path.isdir(package) else []
        raise BuildError("%s: no frepfarm%s after the build (found %s); the build directory's Python is not "
                         "this interpreter (%s)" % (package, suffix, found or "nothing", sys.executable))
    return path


def _record_row(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return [name, "sha256=" + digest, str(len(data))]


def _write_wheel(path, files):
    """files: [(archive name, bytes, mode)]; RECORD last, as PEP 427 recommends."""
    rows = []
    record_name = [n for n, _, _ in files if n.endswith(".dist-info/WHEEL")][0].replace("WHEEL", "RECORD")
    tmp = path + ".part"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data, mode in files:
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = (0o100000 | mode) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)
            rows.append(_record_row(name, data))
        out = io.StringIO()
        csv.writer(out, lineterminator="\n").writerows(rows + [[record_name, "", ""]])
        info = zipfile.ZipInfo(record_name, date_time=(1980, 1, 1, 0, 0, 0))
        info.external_attr = 0o100644 << 16
        z.writestr(info, out.getvalue(), compress_type=zipfile.ZIP_DEFLATED)
    os.replace(tmp, path)


def _setting(config_settings, key, env):
    v = (config_settings or {}).get(key)
    return v if v else os.environ.get(env) or None


# --- PEP 517 hooks ------------------------------------------------------------------------------

def get_requires_for_build_wheel(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    meta = _project()
    d = os.path.join(metadata_directory, _dist_info(meta))
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "METADATA"), "w") as f:
        f.write(_metadata(meta))
    with open(os.path.join(d, "WHEEL"), "w") as f:
        f.write(_wheel_text(_tag()))
    return os.path.basename(d)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    meta = _project()
    tag = _tag()
    jobs = int(_setting(config_settings, "jobs", "CMAKE_BUILD_PARALLEL_LEVEL") or os.cpu_count() or 1)
    build_dir = _setting(config_settings, "build-dir", "FREPFARM_BUILD_DIR")
    prebuilt = (_setting(config_settings, "prebuilt", "FREPFARM_PREBUILT") or "0") not in ("0", "false", "no")
    if prebuilt and build_dir is None:
        raise BuildError("prebuilt: give the build directory (build-dir or FREPFARM_BUILD_DIR)")
    scratch = None
    if build_dir is None:
        scratch = build_dir = tempfile.mkdtemp(prefix="frepfarm-wheel-")
    try:
        build_dir = os.path.abspath(os.path.join(ROOT, build_dir))
        extension = _build_extension(build_dir, jobs, prebuilt)
        with open(extension, "rb") as f:
            files = [("frepfarm/" + os.path.basename(extension), f.read(), 0o755)]
    finally:
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)
    source = os.path.join(ROOT, "python", "frepfarm")
    for name in sorted(os.listdir(source)):
        if name.endswith(".py"):
            with open(os.path.join(source, name), "rb") as f:
                files.append(("frepfarm/" + name, f.read(), 0o644))
    info = _dist_info(meta)
    files += [(info + "/METADATA", _metadata(meta).encode(), 0o644),
              (info + "/WHEEL", _wheel_text(tag).encode(), 0o644),
              (info + "/top_level.txt", b"frepfarm\n", 0o644)]
    name = "%s-%s-%s.whl" % (meta["name"].replace("-", "_"), meta["version"], tag)
    _write_wheel(os.path.join(wheel_directory, name), files)
    return name
