"""The deployment files' topologies run end to end as local processes (check_deploy.py): the
compose and Kubernetes commands of a master and two workers, and the sbatch script itself."""
import glob
import os
import re
import shlex
import subprocess
import tempfile
import time

from deploy_util import (MASTER_DELAY, RUN_TIMEOUT, SPHERE, WORKER_LEAVE_TIMEOUT, WORKER_TEST_ENV, Check,
                         check_outputs, flag_value, free_port, kill_group, require, set_flag, tail)

# Set by check_deploy.main: the source tree and the directory of frep and frep-worker.
SRC = BIN_DIR = None


def localize_master(argv, model, out_vdb, port):
    """The master's command line with the test's model, output, size and a local port."""
    argv = list(argv)
    require(len(argv) >= 3 and argv[1] == "sample", f"master command is not `frep sample MODEL ...`: {argv}")
    argv[0] = os.path.join(BIN_DIR, "frep")
    argv[2] = model
    argv = set_flag(argv, "--out", out_vdb)
    argv = set_flag(argv, "--res", "32")
    argv = set_flag(argv, "-b", "1.5")
    argv = set_flag(argv, "--listen", f"tcp://127.0.0.1:{port}")
    argv = set_flag(argv, "--expect-workers", "2")
    return argv


def local_endpoint(endpoint, port):
    m = re.fullmatch(r"tcp://([^:/]+):(\d+)", endpoint or "")
    require(m is not None, f"worker endpoint {endpoint!r} is not tcp://HOST:PORT")
    return f"tcp://127.0.0.1:{port}"


def run_topology(what, master_argv, worker_argvs, worker_env, tmp, out_vdb):
    """Starts the master and the workers as local processes; checks outputs and exit codes."""
    procs = []
    logs = []
    try:
        # Workers first, as a cluster often does: they queue their hello until the master binds,
        # so both are seen even if one could compute this small job alone. (The master starts
        # computing as soon as the first worker joins.)
        workers = []
        for i, argv in enumerate(worker_argvs):
            wlog = os.path.join(tmp, f"worker{i}.log")
            logs.append((f"worker {i}", wlog))
            env = dict(os.environ)
            env.pop("FREP_MASTER", None)
            env.update(WORKER_TEST_ENV)
            env.update(worker_env)
            with open(wlog, "w") as f:
                w = subprocess.Popen(argv, stdout=f, stderr=subprocess.STDOUT, cwd=tmp, env=env,
                                     start_new_session=True)
            workers.append(w)
            procs.append(w)
        time.sleep(MASTER_DELAY)
        mlog = os.path.join(tmp, "master.log")
        logs.append(("master", mlog))
        with open(mlog, "w") as f:
            master = subprocess.Popen(master_argv, stdout=f, stderr=subprocess.STDOUT, cwd=tmp,
                                      start_new_session=True)
        procs.append(master)
        deadline = time.time() + RUN_TIMEOUT
        while master.poll() is None:
            require(time.time() < deadline, f"{what}: the master did not finish within {RUN_TIMEOUT} s")
            codes = [w.poll() for w in workers]
            require(None in codes or codes == [0] * len(codes),
                    f"{what}: every worker exited (codes {codes}) while the master still runs")
            time.sleep(0.1)
        rc = master.returncode
        require(rc == 0, f"{what}: master exited with {rc}")
        deadline = time.time() + WORKER_LEAVE_TIMEOUT
        for i, w in enumerate(workers):
            try:
                wrc = w.wait(timeout=max(0.1, deadline - time.time()))
            except subprocess.TimeoutExpired:
                raise AssertionError(f"{what}: worker {i} still running {WORKER_LEAVE_TIMEOUT} s after the master finished")
            require(wrc == 0, f"{what}: worker {i} exited with {wrc}")
        check_outputs(out_vdb, what)
    except AssertionError as e:
        detail = "\n".join(f"--- {name} ({shlex.join(p.args) if hasattr(p, 'args') else ''}):\n{tail(log)}"
                           for (name, log), p in zip(logs, procs))
        raise AssertionError(f"{e}\n{detail}")
    finally:
        for p in procs:
            if p.poll() is None:
                kill_group(p)
                p.wait()



def run_local_recipe(name, spec, model_name, out_dir, point_workers):
    """A recipe's master and two workers as local processes on a free port: the master's argv
    localized, the workers' pointed at it by point_workers(argv, env, port) (a flag or FREP_MASTER)."""
    with tempfile.TemporaryDirectory(prefix="frep-%s-" % name) as tmp:
        model = os.path.join(tmp, model_name)
        with open(model, "w") as f:
            f.write(SPHERE)
        port = free_port()
        out_vdb = os.path.join(tmp, out_dir, os.path.splitext(model_name)[0] + ".vdb")
        os.makedirs(os.path.dirname(out_vdb))
        margv = localize_master(spec["master"], model, out_vdb, port)
        wargv = list(spec["worker"])
        wargv[0] = os.path.join(BIN_DIR, "frep-worker")
        env = dict(spec.get("env", {}))
        wargv = point_workers(wargv, env, port)
        run_topology(name, margv, [wargv, wargv], env, tmp, out_vdb)


def e2e_compose(c):
    with Check("docker-compose topology as local processes (master + 2 workers)"):
        require(c, "the compose file did not pass its structure check")
        run_local_recipe("compose", c, "sphere.hf", "out", lambda argv, env, port: set_flag(
            argv, "--connect", local_endpoint(flag_value(argv, "--connect"), port)))


def e2e_k8s(k):
    def point_workers(argv, env, port):
        env["FREP_MASTER"] = local_endpoint(env.get("FREP_MASTER"), port)
        return argv

    with Check("Kubernetes topology as local processes (master + 2 workers, FREP_MASTER)"):
        require(k, "the manifests did not pass their structure check")
        run_local_recipe("k8s", k, "model.hf", "output", point_workers)


SRUN_STUB = r"""#!/usr/bin/env bash
# Test stub for srun: starts --ntasks copies of the command on this machine with SLURM_PROCID
# set, each writing to --output (with %j and %t expanded), and exits with task 0's status.
n=1; out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --ntasks=*) n="${1#*=}"; shift ;;
    -n) n="$2"; shift 2 ;;
    --output=*) out="${1#*=}"; shift ;;
    -*) shift ;;
    *) break ;;
  esac
done
echo "srun-stub: $n tasks" >&2
# Tasks 1..n-1 first and task 0 DELAY s later (a real srun starts them in any order; this
# order makes sure every worker has joined before the small test job is over).
pids=()
for i in $(seq 1 $((n - 1))) 0; do
  [ "$i" -eq 0 ] && sleep DELAY
  log="${out:-/dev/stderr}"; log="${log//%j/${SLURM_JOB_ID:-0}}"; log="${log//%t/$i}"
  SLURM_PROCID=$i SLURM_LOCALID=$i SLURM_NODEID=0 SLURM_STEP_ID=0 "$@" >"$log" 2>&1 &
  pids[$i]=$!
done
# Task 0 (the master) first; then the workers get LEAVE seconds to leave, as the test's other
# topologies do, and are killed (status 1) if they are still there.
wait "${pids[0]}"; rc=$?
echo "srun-stub: task 0 exited $rc" >&2
for ((t = 0; t < LEAVE * 10; t++)); do
  alive=0
  for p in "${pids[@]:1}"; do kill -0 "$p" 2>/dev/null && alive=1; done
  [ $alive -eq 0 ] && break
  sleep 0.1
done
for i in "${!pids[@]}"; do
  [ "$i" -eq 0 ] && continue
  if kill -0 "${pids[$i]}" 2>/dev/null; then
    echo "srun-stub: task $i still running LEAVE s after task 0 ended: killed" >&2
    kill -KILL "${pids[$i]}"; wait "${pids[$i]}"
    [ $rc -eq 0 ] && rc=1
  else
    wait "${pids[$i]}"; r=$?
    echo "srun-stub: task $i exited $r" >&2
    [ $r -ne 0 ] && [ $rc -eq 0 ] && rc=$r
  fi
done
exit $rc
""".replace("LEAVE", str(WORKER_LEAVE_TIMEOUT)).replace("DELAY", str(MASTER_DELAY))

SCONTROL_STUB = r"""#!/usr/bin/env bash
# Test stub for scontrol: `scontrol show hostnames LIST` prints LIST's hosts one per line
# (plain comma-separated lists only).
if [ "$1" = show ] && [ "$2" = hostnames ]; then
  tr ',' '\n' <<< "${3:-$SLURM_JOB_NODELIST}"
  exit 0
fi
echo "scontrol stub: unsupported: $*" >&2
exit 1
"""


def e2e_sbatch(curve=False):
    name = "frep.sbatch run with stub srun/scontrol (task 0 master, tasks 1-2 workers)"
    with Check(name + (", FREP_CURVE_DIR" if curve else "")):
        script = os.path.join(SRC, "deploy", "slurm", "frep.sbatch")
        with tempfile.TemporaryDirectory(prefix="frep-slurm-") as tmp:
            stubs = os.path.join(tmp, "stubs")
            os.makedirs(stubs)
            for name, body in (("srun", SRUN_STUB), ("scontrol", SCONTROL_STUB)):
                with open(os.path.join(stubs, name), "w") as f:
                    f.write(body)
                os.chmod(os.path.join(stubs, name), 0o755)
            model = os.path.join(tmp, "sphere.hf")
            with open(model, "w") as f:
                f.write(SPHERE)
            out_vdb = os.path.join(tmp, "sphere.vdb")
            env = {k: v for k, v in os.environ.items() if not k.startswith(("SLURM_", "FREP_"))}
            env.update({
                "PATH": stubs + os.pathsep + BIN_DIR + os.pathsep + env.get("PATH", "/usr/bin:/bin"),
                "SLURM_JOB_ID": "4242", "SLURM_JOB_NODELIST": "localhost", "SLURM_NTASKS": "3",
                "SLURM_NNODES": "1", "SLURM_CPUS_PER_TASK": "1", "SLURM_SUBMIT_DIR": tmp,
                "FREP_PORT": str(free_port()), "FREP_LOG_DIR": os.path.join(tmp, "logs"),
            })
            env.update(WORKER_TEST_ENV)  # the master ignores it
            if curve:
                keys = os.path.join(tmp, "keys")
                k = subprocess.run([os.path.join(BIN_DIR, "frep"), "keygen", keys], stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True, timeout=30)
                require(k.returncode == 0, f"frep keygen failed: {k.stdout.strip()}")
                env["FREP_CURVE_DIR"] = keys
            log = os.path.join(tmp, "sbatch.log")
            with open(log, "w") as f:
                p = subprocess.Popen(["bash", script, model, out_vdb, "--res", "32", "-b", "1.5"], cwd=tmp, env=env,
                                     stdout=f, stderr=subprocess.STDOUT, start_new_session=True)
            try:
                try:
                    rc = p.wait(timeout=RUN_TIMEOUT + WORKER_LEAVE_TIMEOUT + 10)
                except subprocess.TimeoutExpired:
                    raise AssertionError(f"the job did not finish within {RUN_TIMEOUT + WORKER_LEAVE_TIMEOUT} s")
                require(rc == 0, f"the batch script exited with {rc}")
                check_outputs(out_vdb, "sbatch")
            except AssertionError as e:
                detail = f"--- batch script:\n{tail(log)}"
                for t in sorted(glob.glob(os.path.join(tmp, "logs", "*.log"))):
                    detail += f"\n--- {os.path.basename(t)}:\n{tail(t)}"
                raise AssertionError(f"{e}\n{detail}")
            finally:
                if p.poll() is None:
                    kill_group(p)
                    p.wait()
                else:
                    kill_group(p)  # stray tasks of the stub srun
