// manifold-3d's Minkowski sum for bench/bench_minkowski_general.py: one job as JSON on argv[2]
// ({"a": operand, "b": operand, "op": "sum"}; an operand is {"stl": path, "scale": s} or
// {"sphere": r, "segments": n, "centre": [x, y, z]} or {"cube": [lx, ly, lz], "corner": [...],
// "scale": s}); prints {"seconds", "volume", "triangles"} with the time of the operation alone
// (loading and WASM start-up excluded; the caller also times the whole process).
import fs from 'node:fs';
import Module from 'manifold-3d';

const wasm = await Module();
wasm.setup();
const { Manifold, Mesh } = wasm;

function readStl(path) {
  const buf = fs.readFileSync(path);
  const n = buf.readUInt32LE(80);
  const vert = new Float32Array(9 * n);
  for (let t = 0; t < n; ++t)
    for (let k = 0; k < 9; ++k) vert[9 * t + k] = buf.readFloatLE(84 + 50 * t + 12 + 4 * k);
  const tri = new Uint32Array(3 * n);
  for (let i = 0; i < 3 * n; ++i) tri[i] = i;
  const mesh = new Mesh({ numProp: 3, vertProperties: vert, triVerts: tri });
  mesh.merge();
  return new Manifold(mesh);
}

function operand(o) {
  let m;
  if (o.stl) m = readStl(o.stl);
  else if (o.sphere) m = Manifold.sphere(o.sphere, o.segments).translate(o.centre || [0, 0, 0]);
  else if (o.cube) m = Manifold.cube(o.cube, false).translate(o.corner || [0, 0, 0]);
  else throw new Error('unknown operand ' + JSON.stringify(o));
  if (o.scale && o.scale !== 1) m = m.scale(o.scale);
  return m;
}

const job = JSON.parse(process.argv[2]);
const a = operand(job.a), b = operand(job.b);
const t0 = process.hrtime.bigint();
const r = a.minkowskiSum(b);
const volume = r.volume();
const seconds = Number(process.hrtime.bigint() - t0) / 1e9;
if (job.out) {
  const m = r.getMesh();
  const n = m.triVerts.length / 3;
  const out = Buffer.alloc(84 + 50 * n);
  out.writeUInt32LE(n, 80);
  for (let t = 0; t < n; ++t)
    for (let c = 0; c < 3; ++c)
      for (let k = 0; k < 3; ++k)
        out.writeFloatLE(m.vertProperties[m.numProp * m.triVerts[3 * t + c] + k], 84 + 50 * t + 12 + 12 * c + 4 * k);
  fs.writeFileSync(job.out, out);
}
console.log(JSON.stringify({ seconds, volume, triangles: r.numTri() }));
