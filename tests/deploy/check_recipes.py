#!/usr/bin/env python3
"""The batch recipes for the other verbs, run as local processes (ctest deploy_recipes).

usage: check_recipes.py SOURCE_DIR BIN_DIR

- compose: docker-compose.yml with deploy/compose/{mesh,render,measure}.yml on top, merged by
  Debian's docker-compose 1.29 itself (`config`, no engine): the master command it resolves;
- Kubernetes: deploy/k8s/verbs/{mesh,render,measure}.yaml with the workers of deploy/k8s/ (and
  the label selector deploy/README.md gives, which must leave out exactly the sample Job);
- Slurm: deploy/slurm/frep.sbatch with FREP_VERB=mesh, render, measure, under the stub
  srun/scontrol of check_deploy.py.
mesh and render run as a master and two workers on a sphere, small, and their output must be
byte-identical to the same command in-process (--workers 0); measure's JSON must hold the
in-process numbers (all but `seconds`), and a model error must leave no output. Each command is
also checked against its verb's --help. Exit 0 when every check passed.
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import deploy_e2e as e2e  # noqa: E402 (the runner of the sample topologies)
import deploy_util as du  # noqa: E402 (the checks' helpers)
from deploy_util import Check, require  # noqa: E402

VERBS = {"mesh": ".ply", "render": ".png"}  # the farm verbs besides sample, and their outputs
FARM_ONLY = {"--listen": 1, "--expect-workers": 1, "--insecure": 0, "--resume": 0, "--json": 0, "--curve": 1}
BROKEN = "my_model(x[3], a[1]) { my_model = 1 - x[1]^2 - ; }\n"


def frep(*args):
    return [os.path.join(e2e.BIN_DIR, "frep"), *args]


def small(argv, model, out):
    """The recipe's command for the test: the sphere, a local output, a small job."""
    argv = list(argv)
    argv[2] = model
    argv = du.set_flag(argv, "--out", out)
    argv = du.set_flag(argv, "-b", "1.5")
    if du.flag_value(argv, "--res"):
        argv = du.set_flag(argv, "--res", "32")
    if du.flag_value(argv, "--size"):
        argv = du.set_flag(argv, "--size", "128x128")
    return argv


def in_process(argv, out):
    """The same command without the farm's options, computed in-process."""
    local, i = [], 0
    while i < len(argv):
        n = FARM_ONLY.get(argv[i].split("=", 1)[0])
        if n is None:
            local.append(argv[i])
            i += 1
        else:
            i += 1 + (n if "=" not in argv[i] else 0)
    return du.set_flag(local, "--out", out) + ["--workers", "0", "--no-progress"]


def same_bytes(out, ref, what):
    require(os.path.isfile(out), f"{what}: {out} was not written")
    with open(out, "rb") as a, open(ref, "rb") as b:
        got, want = a.read(), b.read()
    require(got == want, f"{what}: {os.path.basename(out)} ({len(got)} bytes) differs from the in-process "
                         f"output ({len(want)} bytes)")


def farm_run(what, master_argv, worker_argv, worker_env, tmp):
    """Master + 2 workers as local processes; the output byte-identical to --workers 0."""
    model = os.path.join(tmp, "sphere.hf")
    with open(model, "w") as f:
        f.write(du.SPHERE)
    ext = os.path.splitext(du.flag_value(master_argv, "--out"))[1]
    out, ref = os.path.join(tmp, "out", "model" + ext), os.path.join(tmp, "ref" + ext)
    os.makedirs(os.path.dirname(out))
    port = du.free_port()
    margv = small(master_argv, model, out)
    margv[0] = frep()[0]
    margv = du.set_flag(margv, "--listen", f"tcp://127.0.0.1:{port}")
    margv = du.set_flag(margv, "--expect-workers", "2")
    p = subprocess.run(in_process(margv, ref), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       cwd=tmp, timeout=120)
    require(p.returncode == 0, f"{what}: the in-process reference failed ({p.returncode}): {p.stdout[-500:]}")
    wargv = [os.path.join(e2e.BIN_DIR, "frep-worker")] + list(worker_argv[1:])
    env = dict(worker_env)
    if du.flag_value(wargv, "--connect"):
        wargv = du.set_flag(wargv, "--connect", e2e.local_endpoint(du.flag_value(wargv, "--connect"), port))
    else:
        env["FREP_MASTER"] = e2e.local_endpoint(env.get("FREP_MASTER"), port)
    # run_topology checks OUT.report.json's workers_seen; render writes no report, so for it
    # the check is that both workers ran to the end (exit 0) and the bytes.
    report = out + ".report.json"
    try:
        e2e.run_topology(what, margv, [wargv, wargv], env, tmp, out)
    except AssertionError as e:
        if os.path.exists(report) or "was not written" not in str(e) or not os.path.isfile(out):
            raise
    same_bytes(out, ref, what)


def measure_run(what, script_argv, env_extra, tmp):
    """The recipe's `sh -c SCRIPT NAME MODEL OUT [options]` with frep from BIN_DIR: the JSON must
    hold the in-process numbers; a model error gives exit 1 and no file at all."""
    require(script_argv[:2] == ["sh", "-c"] and len(script_argv) >= 6, f"{what}: not sh -c SCRIPT NAME MODEL OUT: {script_argv}")
    env = dict(os.environ)
    env["PATH"] = e2e.BIN_DIR + os.pathsep + env.get("PATH", "/usr/bin:/bin")
    env.update(env_extra)
    opts = du.set_flag(script_argv[6:], "-b", "1.5")
    for name, text, rc_want in (("sphere", du.SPHERE, 0), ("broken", BROKEN, 1)):
        model = os.path.join(tmp, name + ".hf")
        with open(model, "w") as f:
            f.write(text)
        outdir = os.path.join(tmp, "out-" + name)
        os.makedirs(outdir)
        out = os.path.join(outdir, "model.json")
        argv = script_argv[:4] + [model, out] + opts
        p = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env, cwd=tmp,
                           timeout=300)
        require(p.returncode == rc_want, f"{what} ({name}): exit {p.returncode}, expected {rc_want}: {p.stdout[-500:]}")
        left = sorted(os.listdir(outdir))
        if rc_want:
            require(left == [], f"{what}: a model error left {left} in the output directory")
            continue
        require(left == ["model.json"], f"{what}: the output directory holds {left}, expected model.json only")
        ref = subprocess.run(frep("measure", model, *opts, "--json", "--no-progress"), stdout=subprocess.PIPE,
                             stderr=subprocess.DEVNULL, text=True, timeout=300)
        require(ref.returncode == 0, f"{what}: the in-process frep measure failed ({ref.returncode})")
        got, want = json.load(open(out)), json.loads(ref.stdout)
        for d in (got, want):
            d.pop("seconds", None)
        require(got == want, f"{what}: the JSON differs from the in-process numbers: "
                             f"{sorted(k for k in want if got.get(k) != want[k])}")


# ---------------------------------------------------------------------------------------------
# compose

def compose_resolved(verb):
    tool = shutil.which("docker-compose")
    require(tool, "docker-compose is not installed (deploy/install-deps.sh installs Debian's docker-compose)")
    override = os.path.join(e2e.SRC, "deploy", "compose", verb + ".yml")
    require(os.path.isfile(override), f"deploy/compose/{verb}.yml is missing")
    env = {k: v for k, v in os.environ.items() if not k.startswith("FREP_")}
    p = subprocess.run([tool, "-f", os.path.join(e2e.SRC, "docker-compose.yml"), "-f", override, "config"], cwd=e2e.SRC,
                       env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=60)
    require(p.returncode == 0, f"docker-compose config with {verb}.yml exited {p.returncode}: {p.stderr.strip()}")
    services = du.interpolate(yaml.safe_load(p.stdout)["services"], {})  # $$ -> $, as the engine does
    master, worker = services["master"], services["worker"]
    # The model and output volumes are the base file's.
    require(any(str(v).endswith(":/models:ro") or "/models" in str(v) for v in master.get("volumes", [])),
            f"{verb}: the master mounts no /models")
    return (du.as_argv(master.get("entrypoint")) + du.as_argv(master.get("command")),
            du.as_argv(worker.get("entrypoint")) + du.as_argv(worker.get("command")))


def check_compose_verbs(helps):
    for verb in VERBS:
        with Check(f"compose {verb}.yml: master + 2 workers as local processes, output = --workers 0"):
            margv, wargv = compose_resolved(verb)
            require(margv[:2] == ["frep", verb], f"the merged master runs {margv}")
            require(du.flag_value(margv, "--expect-workers") == "2", "--expect-workers is not ${FREP_WORKERS:-2}")
            du.check_flags(margv[2:], helps[verb], f"frep {verb}")
            with tempfile.TemporaryDirectory(prefix=f"frep-compose-{verb}-") as tmp:
                farm_run(f"compose {verb}", margv, wargv, {}, tmp)
    with Check("compose measure.yml: the master's sh -c runs frep measure, JSON = in-process, no output on error"):
        margv, _ = compose_resolved("measure")
        require(re.search(r"\bfrep measure\b", margv[2]) if len(margv) > 2 else False, f"the merged master runs {margv}")
        du.check_flags(margv[6:] + ["--json", "--no-progress"], helps["measure"], "frep measure")
        with tempfile.TemporaryDirectory(prefix="frep-compose-measure-") as tmp:
            measure_run("compose measure", margv, {}, tmp)


# ---------------------------------------------------------------------------------------------
# Kubernetes

def kube_expand(s, env):
    """Kubernetes' expansion of command and args: $(VAR) from the container's env (unknown names
    stay as written), $$ is one $."""
    out, i = [], 0
    while i < len(s):
        if s[i] == "$" and i + 1 < len(s) and s[i + 1] == "$":
            out.append("$")
            i += 2
        elif s.startswith("$(", i) and ")" in s[i:]:
            j = s.index(")", i)
            name = s[i + 2:j]
            out.append(env[name] if name in env else s[i:j + 1])
            i = j + 1
        else:
            out.append(s[i])
            i += 1
    return "".join(out)


def selected(labels, selector):
    """A label selector of `key!=value` and `key=value` terms, as kubectl -l reads it."""
    for term in selector.split(","):
        key, neq, value = re.match(r"([\w./-]+)(!?=)(.*)", term).groups()
        if (labels.get(key) == value) == (neq == "!="):
            return False
    return True


def job_container(doc):
    c = doc["spec"]["template"]["spec"]["containers"][0]
    env = {e["name"]: e.get("value", "") for e in c.get("env", [])}
    return [kube_expand(a, env) for a in du.as_argv(c.get("command")) + du.as_argv(c.get("args"))], env


def check_k8s_verbs(helps):
    base = [d for f in sorted(glob.glob(os.path.join(e2e.SRC, "deploy", "k8s", "*.yaml")))
            for d in yaml.safe_load_all(open(f)) if d]
    with Check("k8s: -l 'app.kubernetes.io/component!=master' applies all of deploy/k8s but the sample Job"):
        readme = open(os.path.join(e2e.SRC, "deploy", "README.md")).read()
        m = re.search(r"kubectl apply -f deploy/k8s/ -l '([^']+)'", readme)
        require(m, "deploy/README.md gives no `kubectl apply -f deploy/k8s/ -l '...'` for the other verbs")
        left_out = [d for d in base if not selected(d["metadata"].get("labels", {}), m.group(1))]
        require([(d["kind"], d["metadata"]["name"]) for d in left_out] == [("Job", "frep-master")],
                f"the selector leaves out {[(d['kind'], d['metadata']['name']) for d in left_out]}, "
                f"expected the sample Job frep-master only")
    workers = [d for d in base if d["kind"] == "Job" and job_container(d)[0][:1] == ["frep-worker"]]
    services = [d for d in base if d["kind"] == "Service"]
    for verb in VERBS:
        with Check(f"k8s verbs/{verb}.yaml: Service selects it; master + 2 workers locally, output = --workers 0"):
            path = os.path.join(e2e.SRC, "deploy", "k8s", "verbs", verb + ".yaml")
            require(os.path.isfile(path), f"deploy/k8s/verbs/{verb}.yaml is missing")
            docs = [d for d in yaml.safe_load_all(open(path)) if d]
            require(len(docs) == 1 and docs[0]["kind"] == "Job", f"{verb}.yaml should hold one Job")
            job = docs[0]
            labels = job["spec"]["template"]["metadata"]["labels"]
            require(services and all(labels.get(k) == v for k, v in services[0]["spec"]["selector"].items()),
                    f"the Service's selector does not match the {verb} pod's labels {labels}")
            margv, _ = job_container(job)
            require(margv[:2] == ["frep", verb], f"the Job runs {margv}")
            du.check_flags(margv[2:], helps[verb], f"frep {verb}")
            require(workers, "deploy/k8s has no worker Job")
            wargv, wenv = job_container(workers[0])
            with tempfile.TemporaryDirectory(prefix=f"frep-k8s-{verb}-") as tmp:
                farm_run(f"k8s {verb}", margv, wargv, wenv, tmp)
    with Check("k8s verbs/measure.yaml: sh -c runs frep measure, JSON = in-process, no output on error"):
        docs = [d for d in yaml.safe_load_all(open(os.path.join(e2e.SRC, "deploy", "k8s", "verbs", "measure.yaml"))) if d]
        argv, env = job_container(docs[0])
        labels = docs[0]["spec"]["template"]["metadata"]["labels"]
        require(not any(all(labels.get(k) == v for k, v in s["spec"]["selector"].items()) for s in services),
                "the Service selects the measure pod")
        du.check_flags(argv[6:] + ["--json", "--no-progress"], helps["measure"], "frep measure")
        with tempfile.TemporaryDirectory(prefix="frep-k8s-measure-") as tmp:
            measure_run("k8s measure", argv, env, tmp)


# ---------------------------------------------------------------------------------------------
# Slurm (stub srun/scontrol, as check_deploy.py's sample run)

def sbatch_verb(verb, ext):
    with Check(f"frep.sbatch FREP_VERB={verb} with stub srun/scontrol: output = in-process"):
        with tempfile.TemporaryDirectory(prefix=f"frep-slurm-{verb}-") as tmp:
            stubs = os.path.join(tmp, "stubs")
            os.makedirs(stubs)
            for name, body in (("srun", e2e.SRUN_STUB), ("scontrol", e2e.SCONTROL_STUB)):
                with open(os.path.join(stubs, name), "w") as f:
                    f.write(body)
                os.chmod(os.path.join(stubs, name), 0o755)
            model = os.path.join(tmp, "sphere.hf")
            with open(model, "w") as f:
                f.write(du.SPHERE)
            out, ref = os.path.join(tmp, "out" + ext), os.path.join(tmp, "ref" + ext)
            opts = {"mesh": ["--res", "32", "-b", "1.5"], "render": ["--size", "128x128", "-b", "1.5"],
                    "measure": ["-b", "1.5"]}[verb]
            env = {k: v for k, v in os.environ.items() if not k.startswith(("SLURM_", "FREP_"))}
            env.update({
                "PATH": stubs + os.pathsep + e2e.BIN_DIR + os.pathsep + env.get("PATH", "/usr/bin:/bin"),
                "SLURM_JOB_ID": "4243", "SLURM_JOB_NODELIST": "localhost", "SLURM_NNODES": "1",
                "SLURM_NTASKS": "1" if verb == "measure" else "3", "SLURM_CPUS_PER_TASK": "1",
                "SLURM_SUBMIT_DIR": tmp, "FREP_PORT": str(du.free_port()), "FREP_LOG_DIR": os.path.join(tmp, "logs"),
                "FREP_VERB": verb,
            })
            env.update(du.WORKER_TEST_ENV)
            p = subprocess.run(["bash", os.path.join(e2e.SRC, "deploy", "slurm", "frep.sbatch"), model, out, *opts],
                               cwd=tmp, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               timeout=du.RUN_TIMEOUT + du.WORKER_LEAVE_TIMEOUT + 60, start_new_session=True)
            logs = "".join(f"\n--- {os.path.basename(t)}:\n{du.tail(t)}"
                           for t in sorted(glob.glob(os.path.join(tmp, "logs", "*.log"))))
            require(p.returncode == 0, f"the batch script exited {p.returncode}:\n{p.stdout[-800:]}{logs}")
            if verb == "measure":
                r = subprocess.run(frep("measure", model, *opts, "--json", "--no-progress"), stdout=subprocess.PIPE,
                                   stderr=subprocess.DEVNULL, text=True, timeout=300)
                got, want = json.load(open(out)), json.loads(r.stdout)
                got.pop("seconds", None), want.pop("seconds", None)
                require(got == want, "out.json differs from the in-process numbers")
                return
            r = subprocess.run(frep(verb, model, "--out", ref, *opts, "--workers", "0", "--no-progress"),
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=120)
            require(r.returncode == 0, f"in-process frep {verb} failed: {r.stdout[-500:]}")
            same_bytes(out, ref, f"sbatch {verb}")
            if verb == "mesh":
                seen = json.load(open(out + ".report.json")).get("workers_seen")
                require(seen == 2, f"the report says workers_seen={seen!r}, expected 2")


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    e2e.SRC, e2e.BIN_DIR = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    helps = {v: du.help_text(os.path.join(e2e.BIN_DIR, "frep"), v) for v in ("mesh", "render", "measure")}
    check_compose_verbs(helps)
    check_k8s_verbs(helps)
    for verb, ext in (("mesh", ".ply"), ("render", ".png"), ("measure", ".json")):
        sbatch_verb(verb, ext)
    if du.failures:
        print(f"\n{len(du.failures)} check(s) failed")
        return 1
    print("\nall recipe checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
