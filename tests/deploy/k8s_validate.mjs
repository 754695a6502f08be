// Validates Kubernetes objects against the JSON schemas of the npm package kubernetes-models
// (generated from the Kubernetes OpenAPI; compiled Ajv validators): types, enums, required
// fields. Unknown fields pass, as the OpenAPI schemas allow them (tests/deploy/check_schemas.py).
//   node k8s_validate.mjs MODELS_DIR < objects.json     ([{file, doc}, ...])
import { readFileSync } from "node:fs";
import path from "node:path";
import { pathToFileURL } from "node:url";

const modelsDir = process.argv[2];
const objects = JSON.parse(readFileSync(0, "utf8"));
let failures = 0;
for (const { file, doc } of objects) {
  const what = `${file}: ${doc.kind} ${doc.metadata?.name ?? "?"} (${doc.apiVersion})`;
  const group = doc.apiVersion.includes("/") ? doc.apiVersion : `v1`;
  const modulePath = path.join(modelsDir, group === "v1" ? "v1" : group, `${doc.kind}.js`);
  let Model;
  try {
    const mod = await import(pathToFileURL(modulePath).href);
    Model = mod[doc.kind] ?? mod.default?.[doc.kind]; // 5.x is ESM; 4.x CommonJS
    if (!Model) throw new Error(`${modulePath} exports no ${doc.kind}`);
  } catch (e) {
    console.log(`FAIL ${what}: no schema for this apiVersion/kind in kubernetes-models (${e.message})`);
    failures++;
    continue;
  }
  try {
    new Model(doc).validate();
    console.log(`ok   ${what}`);
  } catch (e) {
    console.log(`FAIL ${what}: ${e.message}`);
    failures++;
  }
}
process.exit(failures ? 1 : 0);
