#!/usr/bin/env python3
"""Checks the deployment files without a container engine or a cluster.

usage: check_deploy.py SOURCE_DIR BIN_DIR

- every YAML file (docker-compose.yml, deploy/k8s/*.yaml) parses and has the expected structure;
- every flag the deploy files pass to frep / frep-worker appears in that program's --help;
- deploy/Dockerfile: debian:12, COPY sources and RUN scripts exist, exec-form ENTRYPOINT;
- docker-compose.yml is accepted by the real docker-compose 1.29 (`config`, no engine needed);
- deploy/slurm/frep.sbatch passes `bash -n`;
- then each topology runs as local processes on a tiny sphere (res 32): the compose master and
  two workers with the compose commands, the same for the Kubernetes manifests, and the sbatch
  script itself with stub `srun`/`scontrol` and a fake Slurm environment. Each must write the
  .vdb and its report, and the report must say 2 workers were seen.

Exit status 0 when every check passed; each failure is printed with what was expected.
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

import deploy_e2e
from deploy_util import (Check, as_argv, check_flags, failures, flag_value, help_text, interpolate,
                         program_name, require, set_flag)


try:
    import yaml
except ImportError:  # python3-yaml is in deploy/install-deps.sh
    print("FAIL: python3 cannot import yaml (install python3-yaml: deploy/install-deps.sh)")
    sys.exit(1)

# ---------------------------------------------------------------------------------------------
# checks

def check_yaml_files():
    files = [os.path.join(SRC, "docker-compose.yml")] + sorted(glob.glob(os.path.join(SRC, "deploy", "k8s", "*.yaml")) +
                                                           glob.glob(os.path.join(SRC, "deploy", "k8s", "*.yml")))
    docs = {}
    for path in files:
        rel = os.path.relpath(path, SRC)
        with Check(f"YAML parses: {rel}"):
            require(os.path.isfile(path), "missing")
            with open(path) as f:
                docs[rel] = [d for d in yaml.safe_load_all(f) if d is not None]
            require(docs[rel], "no document")
    return docs


def check_dockerfile(compose_programs):
    path = os.path.join(SRC, "deploy", "Dockerfile")
    with Check("Dockerfile: base, COPY sources, RUN scripts, exec-form ENTRYPOINT"):
        require(os.path.isfile(path), "deploy/Dockerfile is missing")
        with open(path) as f:
            text = f.read()
        # Logical instructions: join continuation lines, drop comments.
        lines, cur = [], ""
        for raw in text.splitlines():
            s = raw.strip()
            if not cur and (not s or s.startswith("#")):
                continue
            if s.startswith("#"):
                continue
            if s.endswith("\\"):
                cur += s[:-1] + " "
                continue
            lines.append(cur + s)
            cur = ""
        instr = [(l.split(None, 1)[0].upper(), l.split(None, 1)[1] if len(l.split(None, 1)) > 1 else "") for l in lines]
        froms = [a.split()[0] for k, a in instr if k == "FROM"]
        require(froms and all(f == "debian:12" for f in froms), f"FROM must be debian:12, got {froms}")
        copied = set()
        for k, a in instr:
            if k in ("COPY", "ADD"):
                parts = [p for p in a.split() if not p.startswith("--")]
                if "--from" in a:
                    continue
                for src in parts[:-1]:
                    require(os.path.exists(os.path.join(SRC, src)), f"COPY source {src} does not exist")
                    copied.add(os.path.normpath(src))
        # Every source folder the top-level CMakeLists.txt adds must be in the image (tests and
        # bench only when the Dockerfile does not switch them off).
        with open(os.path.join(SRC, "CMakeLists.txt")) as f:
            top = f.read()
        subdirs = re.findall(r"add_subdirectory\(\s*([\w./-]+)", top)
        # Files the top level include()s from the checkout (cmake/FrepInstall.cmake): their folder.
        subdirs += sorted({p.split("/")[0] for p in re.findall(r"include\(\s*([\w.-]+/[\w./-]+)\s*\)", top)})
        run_text = " ".join(a for k, a in instr if k == "RUN")
        for d in subdirs:
            if d == "tests" and "FREP_BUILD_TESTS=OFF" in run_text:
                continue
            if d == "bench" and "FREP_BUILD_BENCH=OFF" in run_text:
                continue
            require(d in copied or "." in copied, f"add_subdirectory({d}) but the Dockerfile does not COPY {d}")
        require("CMakeLists.txt" in copied or "." in copied, "the top-level CMakeLists.txt is not copied")
        # Scripts the RUN lines call must exist in the checkout (as /src/<path> or <path>).
        scripts = re.findall(r"(?:/src/|\./)?(deploy/[\w./-]+\.sh)", run_text)
        require(any(s.endswith("install-deps.sh") for s in scripts), "no RUN line runs deploy/install-deps.sh")
        for s in scripts:
            require(os.path.isfile(os.path.join(SRC, s)), f"RUN uses {s}, which does not exist")
            require(os.access(os.path.join(SRC, s), os.X_OK), f"RUN uses {s}, which is not executable")
        require("CMAKE_BUILD_TYPE=Release" in run_text, "cmake is not run with -DCMAKE_BUILD_TYPE=Release")
        for prog in ("frep", "frep-worker"):
            require(re.search(r"/usr/local/bin/?\S*", text) and re.search(r"bin/" + re.escape(prog) + r"\b", text),
                    f"{prog} is not installed into /usr/local/bin")
        entry = [a for k, a in instr if k == "ENTRYPOINT"]
        require(entry, "no ENTRYPOINT")
        try:
            ep = json.loads(entry[-1])
        except ValueError:
            raise AssertionError(f"ENTRYPOINT is not in exec form (a JSON array): {entry[-1]}")
        require(isinstance(ep, list) and ep and os.path.basename(ep[0]) in ("frep", "frep-worker"),
                f"ENTRYPOINT should run frep or frep-worker: {ep}")
        for prog in compose_programs:
            require(prog in ("frep", "frep-worker", "/usr/local/bin/frep", "/usr/local/bin/frep-worker"),
                    f"an entrypoint runs {prog}, which the image does not install")

    # The runtime stage installs the packages that own the libraries the programs load: run the
    # Dockerfile's own pipeline on the binaries built here.
    m = re.search(r"RUN ((?:for lib in \$\()?ldd /usr/local/bin/frep[^\n]*(?:\\\n[^\n]*)*?> /runtime-packages\.txt)", text)
    if not m:
        print("skip Dockerfile: no runtime-package pipeline (single-stage image?)")
    elif subprocess.run(["which", "dpkg"], stdout=subprocess.DEVNULL).returncode == 0:
        with Check("Dockerfile: runtime-package pipeline finds the libraries' packages"):
            cmd = m.group(1).replace("\\\n", " ").replace("/usr/local/bin/", BIN_DIR + "/")
            cmd = cmd.replace("/usr/local/lib/frepfarm/", BIN_DIR + "/")  # the modules, next to them here
            cmd = cmd.replace("> /runtime-packages.txt", "")
            p = subprocess.run(["bash", "-o", "pipefail", "-c", cmd], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, timeout=300)
            pkgs = p.stdout.split()
            require(p.returncode == 0, f"pipeline failed: {p.stderr.strip()}")
            require(any(x.startswith("libzmq") for x in pkgs) and "libc6" in pkgs,
                    f"expected libzmq5 and libc6 among {pkgs}")
            # OpenVDB, lib3MF and cpp-httplib come in through the modules only (loaded when a job
            # needs them): every module's libraries must be among the packages.
            for lib in ("libopenvdb", "lib3mf", "libcpp-httplib"):
                require(any(x.startswith(lib) for x in pkgs), f"the modules' library {lib} is not among {pkgs}")


def check_compose(docs, frep_help, worker_help):
    compose = docs.get("docker-compose.yml", [None])[0]
    result = {}
    with Check("docker-compose.yml: master and worker services"):
        require(isinstance(compose, dict) and isinstance(compose.get("services"), dict), "no services")
        env = {}  # defaults only, as on a machine with no FREP_* variables set
        services = interpolate(compose["services"], env)
        require("master" in services and "worker" in services, f"services are {list(services)}")
        master, worker = services["master"], services["worker"]
        for name, svc in (("master", master), ("worker", worker)):
            b = svc.get("build")
            if b:
                ctx = b if isinstance(b, str) else b.get("context", ".")
                df = None if isinstance(b, str) else b.get("dockerfile")
                require(os.path.isdir(os.path.join(SRC, ctx)), f"{name}: build context {ctx} missing")
                if df:
                    require(os.path.isfile(os.path.join(SRC, ctx, df)), f"{name}: {df} missing")
            require("stop_grace_period" in svc, f"{name}: no stop_grace_period")
        margv = as_argv(master.get("entrypoint")) + as_argv(master.get("command"))
        wargv = as_argv(worker.get("entrypoint")) + as_argv(worker.get("command"))
        require(program_name(margv) == "frep" and margv[1:2] == ["sample"], f"master runs {margv}")
        for flag in ("--out", "--listen", "--expect-workers", "--json"):
            require(flag in margv, f"master command lacks {flag}")
        require(re.fullmatch(r"\d+", flag_value(margv, "--expect-workers") or ""),
                f"--expect-workers {flag_value(margv, '--expect-workers')!r} is not a number")
        require(program_name(wargv) == "frep-worker", f"worker runs {wargv}")
        listen = flag_value(margv, "--listen")
        port = re.fullmatch(r"tcp://\*:(\d+)", listen or "")
        require(port, f"master --listen {listen!r} is not tcp://*:PORT")
        connect = flag_value(wargv, "--connect") or worker.get("environment", {}).get("FREP_MASTER")
        require(connect == f"tcp://master:{port.group(1)}", f"worker connects to {connect!r}, expected tcp://master:{port.group(1)}")
        require(str(worker.get("restart", "")).startswith("on-failure"), f"worker restart is {worker.get('restart')!r}")
        # Volumes: the model comes from ./examples read-only, the output goes to a named volume.
        named = set((compose.get("volumes") or {}).keys())
        mounts = [str(v) for v in master.get("volumes", [])]
        out_dir = os.path.dirname(flag_value(margv, "--out"))
        out_mounts = [m for m in mounts if m.split(":")[1] == out_dir]
        require(out_mounts and out_mounts[0].split(":")[0] in named,
                f"--out is in {out_dir}, which is not a named volume (mounts {mounts}, volumes {sorted(named)})")
        model = margv[2]
        model_mounts = [m for m in mounts if model.startswith(m.split(":")[1].rstrip("/") + "/")]
        require(model_mounts, f"the model {model} is in no mounted directory")
        host_dir, cont_dir = model_mounts[0].split(":")[:2]
        require(model_mounts[0].endswith(":ro"), f"the model mount {model_mounts[0]} is not read-only")
        host_model = os.path.join(SRC, host_dir, os.path.relpath(model, cont_dir))
        require(os.path.isfile(host_model), f"the model {model} would be {host_model}, which does not exist")
        result = {"master": margv, "worker": wargv, "model": host_model}
    if result:
        with Check("docker-compose.yml: flags exist in frep / frep-worker --help"):
            check_flags(result["master"][2:], frep_help, "frep sample")
            check_flags(result["worker"][1:], worker_help, "frep-worker")
    return result


def check_compose_tool(parsed):
    """Debian 12's docker-compose 1.29 (Compose v1) reads the file: `config` needs no engine. Its
    resolved master command must be the one this script parsed, and FREP_WORKERS must reach both
    --expect-workers and deploy.replicas."""
    with Check("docker-compose.yml: accepted by docker-compose (v1) `config`, FREP_WORKERS interpolated"):
        tool = shutil.which("docker-compose")
        require(tool, "docker-compose is not installed (deploy/install-deps.sh installs Debian's docker-compose)")
        env = {k: v for k, v in os.environ.items() if not k.startswith("FREP_")}
        env["FREP_WORKERS"] = "5"
        p = subprocess.run([tool, "-f", os.path.join(SRC, "docker-compose.yml"), "config"], cwd=SRC, env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=60)
        require(p.returncode == 0, f"docker-compose config exited {p.returncode}: {p.stderr.strip()}")
        resolved = yaml.safe_load(p.stdout)
        master, worker = resolved["services"]["master"], resolved["services"]["worker"]
        margv = as_argv(master.get("entrypoint")) + as_argv(master.get("command"))
        require(flag_value(margv, "--expect-workers") == "5", f"--expect-workers is {flag_value(margv, '--expect-workers')!r}, expected 5")
        require(str(worker.get("deploy", {}).get("replicas")) == "5", f"worker replicas {worker.get('deploy')}")
        if parsed:
            expected = set_flag(list(parsed["master"]), "--expect-workers", "5")
            require(margv == expected, f"docker-compose resolves the master to {margv}, this check read {expected}")


def k8s_objects(docs):
    objs = []
    for rel, ds in docs.items():
        if rel.startswith("deploy"):
            for d in ds:
                if isinstance(d, dict) and d.get("kind") == "List":
                    objs += d.get("items", [])
                elif isinstance(d, dict):
                    objs.append(d)
    return objs


def check_k8s(docs, frep_help, worker_help):
    objs = k8s_objects(docs)
    result = {}
    with Check("deploy/k8s: master Job + Service, worker Job, ConfigMap, PVC"):
        by_kind = {}
        for o in objs:
            require("apiVersion" in o and "kind" in o and o.get("metadata", {}).get("name"),
                    f"object without apiVersion/kind/metadata.name: {str(o)[:80]}")
            by_kind.setdefault(o["kind"], []).append(o)
        jobs = by_kind.get("Job", [])

        def container(job):
            return job["spec"]["template"]["spec"]["containers"][0]

        def argv(c):
            return as_argv(c.get("command")) + as_argv(c.get("args"))

        masters = [j for j in jobs if program_name(argv(container(j))) == "frep"]
        workers = [j for j in jobs if program_name(argv(container(j))) == "frep-worker"]
        require(len(masters) == 1 and len(workers) == 1,
                f"expected one Job running frep and one running frep-worker, got {[j['metadata']['name'] for j in jobs]}")
        mjob, wjob = masters[0], workers[0]
        mc, wc = container(mjob), container(wjob)
        margv, wargv = argv(mc), argv(wc)
        require(margv[1:2] == ["sample"] and "--listen" in margv and "--expect-workers" in margv,
                f"master runs {margv}")
        port = re.fullmatch(r"tcp://\*:(\d+)", flag_value(margv, "--listen") or "")
        require(port, f"master --listen {flag_value(margv, '--listen')!r} is not tcp://*:PORT")
        port = int(port.group(1))
        # The Service selects the master pod and exposes the port.
        labels = mjob["spec"]["template"].get("metadata", {}).get("labels", {})
        services = [s for s in by_kind.get("Service", [])
                    if s["spec"].get("selector") and all(labels.get(k) == v for k, v in s["spec"]["selector"].items())]
        require(services, f"no Service selects the master pod labels {labels}")
        svc = services[0]
        sports = {p.get("port"): p.get("targetPort", p.get("port")) for p in svc["spec"].get("ports", [])}
        require(any(t == port for t in sports.values()), f"Service {svc['metadata']['name']} does not target port {port}")
        svc_port = [p for p, t in sports.items() if t == port][0]
        # Workers: parallelism, endpoint by env var, FailJob on 78.
        wspec = wjob["spec"]
        require(int(wspec.get("parallelism", 1)) >= 2, "worker Job parallelism should be >= 2")
        env = {e["name"]: e.get("value") for e in wc.get("env", [])}
        expected = f"tcp://{svc['metadata']['name']}:{svc_port}"
        require(env.get("FREP_MASTER") == expected, f"worker FREP_MASTER={env.get('FREP_MASTER')!r}, expected {expected}")
        require(wspec["template"]["spec"].get("restartPolicy") == "Never", "podFailurePolicy needs restartPolicy Never")
        rules = wspec.get("podFailurePolicy", {}).get("rules", [])
        require(any(r.get("action") == "FailJob" and 78 in r.get("onExitCodes", {}).get("values", [])
                    and r["onExitCodes"].get("operator") == "In"
                    and r["onExitCodes"].get("containerName", wc["name"]) == wc["name"] for r in rules),
                "worker Job has no podFailurePolicy rule FailJob on exit code 78")
        # Every onPodConditions pattern names its status: the schemas before 1.31 require it.
        for job_name, spec in (("worker", wspec), ("master", mjob["spec"])):
            for r in spec.get("podFailurePolicy", {}).get("rules", []):
                for c in r.get("onPodConditions", []):
                    require(c.get("status") == "True",
                            f"{job_name} Job podFailurePolicy onPodConditions {c.get('type')} has no status: \"True\"")
        # Volumes: the model from a ConfigMap, the output on a PVC.
        vols = {v["name"]: v for v in mjob["spec"]["template"]["spec"].get("volumes", [])}
        mounts = {m["mountPath"].rstrip("/"): m["name"] for m in mc.get("volumeMounts", [])}
        model = margv[2]
        mdir = os.path.dirname(model)
        require(mdir in mounts and "configMap" in vols.get(mounts[mdir], {}),
                f"the model {model} is not on a mounted ConfigMap")
        cm_name = vols[mounts[mdir]]["configMap"]["name"]
        cms = [c for c in by_kind.get("ConfigMap", []) if c["metadata"]["name"] == cm_name]
        require(cms and os.path.basename(model) in cms[0].get("data", {}),
                f"ConfigMap {cm_name} with key {os.path.basename(model)} is not in deploy/k8s")
        odir = os.path.dirname(flag_value(margv, "--out") or "")
        require(odir in mounts and "persistentVolumeClaim" in vols.get(mounts[odir], {}),
                f"--out is in {odir}, which is not a mounted PVC")
        claim = vols[mounts[odir]]["persistentVolumeClaim"]["claimName"]
        require(any(p["metadata"]["name"] == claim for p in by_kind.get("PersistentVolumeClaim", [])),
                f"PVC {claim} is not in deploy/k8s")
        result = {"master": margv, "worker": wargv, "env": env, "model_text": cms[0]["data"][os.path.basename(model)],
                  "parallelism": int(wspec.get("parallelism", 1))}
    if result:
        with Check("deploy/k8s: flags exist in frep / frep-worker --help"):
            check_flags(result["master"][2:], frep_help, "frep sample")
            check_flags(result["worker"][1:], worker_help, "frep-worker")
        with Check("deploy/k8s: the ConfigMap's model compiles (frep check)"):
            with tempfile.TemporaryDirectory() as tmp:
                path = os.path.join(tmp, "model.hf")
                with open(path, "w") as f:
                    f.write(result["model_text"])
                p = subprocess.run([os.path.join(BIN_DIR, "frep"), "check", path], stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True, timeout=30)
                require(p.returncode == 0, f"frep check failed ({p.returncode}): {p.stdout.strip()}")
    return result


def check_sbatch_syntax():
    path = os.path.join(SRC, "deploy", "slurm", "frep.sbatch")
    text = None
    with Check("frep.sbatch: bash -n, Slurm directives"):
        require(os.path.isfile(path), "deploy/slurm/frep.sbatch is missing")
        p = subprocess.run(["bash", "-n", path], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        require(p.returncode == 0, f"bash -n: {p.stdout.strip()}")
        with open(path) as f:
            text = f.read()
        require(re.search(r"^#SBATCH\s+--signal=", text, re.M), "no #SBATCH --signal= for a graceful stop")
        require("scontrol show hostnames" in text and "SLURM_JOB_NODELIST" in text, "master host not from the node list")
        require("master_task" in text and "worker_task" in text and "FREP_MASTER" in text,
                "no master step / worker step / FREP_MASTER")
        require(re.search(r'"\$\{FREP_BIN\}frep" check', text), "the model is not checked before the steps start")
        require(re.search(r"\bsrun\b", text), "no srun")
    return text


def sbatch_command_flags(text, program):
    """The options on the line(s) of the sbatch script that exec `program`."""
    m = re.search(r'(?:exec )?"\$\{FREP_BIN\}' + re.escape(program) + r'" (?!check)((?:[^\n]*\\\n)*[^\n]*)', text)
    require(m, f"the task script does not run \"${{FREP_BIN}}{program}\"")
    segment = m.group(1)
    flags = re.findall(r"(?<![\w$-])--?[A-Za-z][\w-]*", segment)
    # Options kept in bash arrays (curve=(--curve "$DIR")) and expanded as "${curve[@]}".
    for name in re.findall(r'"\$\{(\w+)\[@\]\}"', segment):
        flags += re.findall(r"\b" + name + r"=\((--?[A-Za-z][\w-]*)", text)
    return flags


def check_sbatch_flags(text, frep_help, worker_help):
    with Check("frep.sbatch: flags exist in frep / frep-worker --help"):
        require(text, "the script did not pass its syntax check")
        check_flags(sbatch_command_flags(text, "frep"), frep_help, "frep sample")
        check_flags(sbatch_command_flags(text, "frep-worker"), worker_help, "frep-worker")


def main():
    global SRC, BIN_DIR
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    SRC, BIN_DIR = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    deploy_e2e.SRC, deploy_e2e.BIN_DIR = SRC, BIN_DIR
    frep, worker = os.path.join(BIN_DIR, "frep"), os.path.join(BIN_DIR, "frep-worker")
    for b in (frep, worker):
        if not os.access(b, os.X_OK):
            print(f"FAIL: {b} is not an executable")
            return 1
    frep_help = help_text(frep, "sample")
    worker_help = help_text(worker)

    docs = check_yaml_files()
    c = check_compose(docs, frep_help, worker_help)
    check_compose_tool(c)
    compose_programs = [program_name(c[k]) for k in ("master", "worker")] if c else []
    check_dockerfile(compose_programs)
    k = check_k8s(docs, frep_help, worker_help)
    sbatch_text = check_sbatch_syntax()
    check_sbatch_flags(sbatch_text, frep_help, worker_help)

    deploy_e2e.e2e_compose(c)
    deploy_e2e.e2e_k8s(k)
    deploy_e2e.e2e_sbatch()
    deploy_e2e.e2e_sbatch(curve=True)

    if failures:
        print(f"\n{len(failures)} check(s) failed")
        return 1
    print("\nall deploy checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
