"""Shared pieces of the deployment checks (check_deploy.py, deploy_e2e.py): the run's limits,
the failure list and its reporting, and command-line helpers."""
import json
import os
import re
import shlex
import signal
import socket
import subprocess

RUN_TIMEOUT = 60  # seconds for one end-to-end topology
WORKER_LEAVE_TIMEOUT = 20  # seconds for workers to exit after the master finished
MASTER_DELAY = 1.0  # seconds between starting the workers and the master
# The master starts computing when the first worker joins (it does not wait for
# --expect-workers), and this test job is one brick of 0.1 s: a worker whose TCP reconnect
# comes a little later would find the job over. frep-worker's test hook FREP_TEST_SLOW_MS
# (docs/farm.md) makes each brick last long enough for both workers to join. It changes no
# command line.
WORKER_TEST_ENV = {"FREP_TEST_SLOW_MS": "500"}

SPHERE = "my_model(x[3], a[1]) { my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2; }\n"

failures = []


def fail(what, message):
    failures.append(f"{what}: {message}")
    print(f"FAIL {what}: {message}", flush=True)


def ok(what):
    print(f"ok   {what}", flush=True)


class Check:
    """with Check("name"): ...  -- an AssertionError inside is reported as a failure."""

    def __init__(self, name):
        self.name = name

    def __enter__(self):
        return self

    def __exit__(self, kind, value, tb):
        if kind is None:
            ok(self.name)
            return False
        if issubclass(kind, AssertionError):
            fail(self.name, str(value))
            return True
        if issubclass(kind, Exception):
            fail(self.name, f"{kind.__name__}: {value}")
            return True
        return False


def require(condition, message):
    if not condition:
        raise AssertionError(message)


# ---------------------------------------------------------------------------------------------
# helpers

def interpolate(value, env):
    """Compose variable interpolation: ${VAR}, ${VAR:-default}, ${VAR-default}, $VAR, $$."""

    def one(m):
        if m.group(0) == "$$":
            return "$"
        name = m.group(1) or m.group(4)
        op, default = m.group(2), m.group(3) or ""
        if op == ":-":
            return env.get(name) or default
        if op == "-":
            return env.get(name, default)
        return env.get(name, "")

    pattern = r"\$\$|\$\{([A-Za-z_][A-Za-z0-9_]*)(?:(:?-)([^}]*))?\}|\$([A-Za-z_][A-Za-z0-9_]*)"
    if isinstance(value, str):
        return re.sub(pattern, one, value)
    if isinstance(value, list):
        return [interpolate(v, env) for v in value]
    if isinstance(value, dict):
        return {k: interpolate(v, env) for k, v in value.items()}
    return value


def as_argv(value):
    if value is None:
        return []
    if isinstance(value, str):
        return shlex.split(value)
    return [str(v) for v in value]


def flag_value(argv, flag):
    for i, a in enumerate(argv):
        if a == flag and i + 1 < len(argv):
            return argv[i + 1]
        if a.startswith(flag + "="):
            return a.split("=", 1)[1]
    return None


def set_flag(argv, flag, value):
    out = list(argv)
    for i, a in enumerate(out):
        if a == flag and i + 1 < len(out):
            out[i + 1] = value
            return out
        if a.startswith(flag + "="):
            out[i] = f"{flag}={value}"
            return out
    return out + [flag, value]


def help_text(binary, *args):
    p = subprocess.run([binary, *args, "--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True, timeout=30)
    return p.stdout


def check_flags(argv, help_txt, program):
    """Every option in argv must be named in the program's --help."""
    missing = []
    for a in argv:
        if not a.startswith("-") or a == "-" or re.fullmatch(r"-[0-9.]+", a):
            continue
        flag = a.split("=", 1)[0]
        if not re.search(r"(?<![\w-])" + re.escape(flag) + r"(?![\w-])", help_txt):
            missing.append(flag)
    require(not missing, f"{program} --help does not mention {', '.join(missing)} (used in {shlex.join(argv)})")


def program_name(argv):
    return os.path.basename(argv[0]) if argv else ""


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def tail(path, n=15):
    try:
        with open(path, errors="replace") as f:
            return "".join(f.readlines()[-n:])
    except OSError:
        return "(no output)"


def kill_group(p, sig=signal.SIGKILL):
    try:
        os.killpg(p.pid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def check_outputs(out_vdb, what):
    report_path = out_vdb + ".report.json"
    require(os.path.isfile(out_vdb) and os.path.getsize(out_vdb) > 0, f"{what}: {out_vdb} was not written")
    require(os.path.isfile(report_path), f"{what}: {report_path} was not written")
    with open(report_path) as f:
        report = json.load(f)
    seen = report.get("workers_seen")
    require(seen == 2, f"{what}: report says workers_seen={seen!r}, expected 2")
