"""The Kubernetes API of one release as the npm package cdk8s-plus-<minor> ships it, and a strict
check of manifests against it (tests/deploy/check_schemas.py).

cdk8s-plus-31 ... -34 each bundle lib/imports/k8s.{js,d.ts}, generated from the JSON schema of
Kubernetes 1.31 ... 1.34 (the last `k8s@1.NN.0` of the package's cdk8s.yaml). For every object
type, k8s.js has a toJson_<Type> function naming each field's JSON key and how its value is
converted (another type, a list or a map of one, or a plain value), and k8s.d.ts declares each
field's TypeScript type and whether it is optional. From these this module rebuilds, per release,
the fields of every type, their value types and the required ones.

The check is stricter than the OpenAPI schemas (which set no additionalProperties: false): a
field the release does not know is an error, as `kubectl apply` makes it since 1.27 (server-side
field validation, strict by default); so is a missing required field or a value of the wrong
type. Enums and formats are left to the Ajv validators of kubernetes-models (k8s_validate.mjs).
"""
import os
import re

_CONVERSIONS = [  # (pattern over the toJson expression, what the value is)
    (re.compile(r"^toJson_(\w+)\(obj\.\w+\)$"), "struct"),
    (re.compile(r"^obj\.\w+\?\.map\(y => toJson_(\w+)\(y\)\)$"), "struct[]"),
    (re.compile(r"reduce\(.*\[i\[0\]\]: toJson_(\w+)\(i\[1\]\) \}\), \{\}\)\)$"), "struct{}"),
]


def _leaf_ok(ts_type, value):
    """A plain value against its TypeScript type in k8s.d.ts."""
    t = ts_type.strip()
    if t.endswith("[]"):
        return isinstance(value, list) and all(_leaf_ok(t[:-2], v) for v in value)
    if t.startswith("{"):  # a map: { [key: string]: string } (or Quantity, string[])
        return isinstance(value, dict)
    if t == "number":
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if t == "boolean":
        return isinstance(value, bool)
    if t in ("string", "Date"):
        return isinstance(value, str)
    if t in ("IntOrString", "Quantity"):
        return isinstance(value, (str, int, float)) and not isinstance(value, bool)
    return True  # any (e.g. JSON): nothing to check


class Release:
    """One Kubernetes release's types: .fields[type][json_key] = (kind, type_name, ts_type,
    required); .kinds[(apiVersion, kind)] = the props type of that top-level object."""

    def __init__(self, package_dir):
        imports = os.path.join(package_dir, "lib", "imports")
        with open(os.path.join(package_dir, "cdk8s.yaml")) as f:
            self.version = re.findall(r"k8s@(\d+\.\d+)\.\d+", f.read())[-1]
        with open(os.path.join(imports, "k8s.js")) as f:
            js = f.read()
        with open(os.path.join(imports, "k8s.d.ts")) as f:
            dts = f.read()
        props = {}  # type -> {ts_name: (ts_type, required)}
        for m in re.finditer(r"^export interface (\w+) \{\n(.*?)^\}", dts, re.S | re.M):
            props[m.group(1)] = {p.group(1): (p.group(3), p.group(2) != "?")
                                 for p in re.finditer(r"^    readonly (\w+)(\??): (.+?);?$", m.group(2), re.M)}
        self.fields = {}
        for m in re.finditer(r"^function toJson_(\w+)\(obj\) \{.*?const result = \{\n(.*?)\n    \};", js, re.S | re.M):
            name, fields = m.group(1), {}
            for line in m.group(2).splitlines():
                e = re.match(r"\s*'([^']+)': (.*),$", line)
                if not e:
                    continue
                key, expr = e.groups()
                ts = re.search(r"obj\.(\w+)", expr)
                ts_type, required = props.get(name, {}).get(ts.group(1) if ts else "", ("any", False))
                kind, type_name = "leaf", None
                for pattern, what in _CONVERSIONS:
                    c = pattern.search(expr)
                    if c:
                        kind, type_name = what, c.group(1)
                        break
                fields[key] = (kind, type_name, ts_type, required)
            self.fields[name] = fields
        self.kinds = {}
        for m in re.finditer(r"^class (Kube\w+) extends [\w.]+ \{.*?GVK = \{\s*apiVersion: '([^']+)',\s*kind: '([^']+)'",
                             js, re.S | re.M):
            self.kinds[(m.group(2), m.group(3))] = m.group(1) + "Props"
        if not self.fields or not self.kinds:
            raise ValueError(f"{package_dir}: no types found in lib/imports/k8s.js (another layout?)")

    def errors(self, doc):
        """Every field of a manifest object this release would refuse, as 'path: why'."""
        key = (doc.get("apiVersion"), doc.get("kind"))
        if key not in self.kinds:
            return [f"{key[0]} {key[1]}: no such kind in Kubernetes {self.version}"]
        out = []
        top = dict(doc)
        top.pop("apiVersion"), top.pop("kind")
        self._walk(self.kinds[key], top, "", out)
        return out

    def _walk(self, type_name, value, path, out):
        if not isinstance(value, dict):
            out.append(f"{path or '/'}: expected an object ({type_name})")
            return
        fields = self.fields.get(type_name)
        if fields is None:
            return  # a type without fields of its own (e.g. RawExtension): anything goes
        for key, (_, _, _, required) in fields.items():
            if required and key not in value:
                out.append(f"{path}/{key}: required by {type_name} in Kubernetes {self.version}")
        for key, v in value.items():
            where = f"{path}/{key}"
            if key not in fields:
                out.append(f"{where}: unknown field of {type_name} in Kubernetes {self.version}")
                continue
            kind, sub, ts_type, _ = fields[key]
            if kind == "struct":
                self._walk(sub, v, where, out)
            elif kind == "struct[]":
                if not isinstance(v, list):
                    out.append(f"{where}: expected a list of {sub}")
                else:
                    for i, item in enumerate(v):
                        self._walk(sub, item, f"{where}/{i}", out)
            elif kind == "struct{}":
                if not isinstance(v, dict):
                    out.append(f"{where}: expected a map of {sub}")
                else:
                    for k, item in v.items():
                        self._walk(sub, item, f"{where}/{k}", out)
            elif not _leaf_ok(ts_type, v):
                out.append(f"{where}: {v!r} is not a {ts_type}")
