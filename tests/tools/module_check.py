#!/usr/bin/env python3
"""frep and frep-worker load OpenVDB only for .vdb work, frep lib3MF and tinygltf only to write a
.3mf or a .glb and cpp-httplib only for frep view (frep/io/program_module.h). Checks:
- neither program needs those libraries (readelf NEEDED) nor loads them or any module for a mesh
  job (LD_DEBUG=files);
- every frepfarm symbol a module leaves undefined is exported by each program that loads it
  (a missing one would fail only when a job first needs the module, e.g. in a worker);
- a .vdb, .3mf or .glb job loads its module and works; a program copied away from its modules
  fails with exit 4 and a message naming the paths tried, and writes no output, while a mesh job
  there still works.
  module_check.py BIN_DIR"""
import os
import shutil
import subprocess
import sys
import tempfile

BIN = os.path.abspath(sys.argv[1])
FREP, WORKER = (os.path.join(BIN, n) for n in ("frep", "frep-worker"))
# module -> (the programs that load it, the libraries it keeps out of them)
MODULES = {"libfrep_vdb.so": ((FREP, WORKER), ("libopenvdb",)),
           "libfrep_mesh_files.so": ((FREP,), ("lib3MF", "libtinygltf", "libzip", "libcrypto")),
           "libfrep_view.so": ((FREP,), ("libcpp-httplib", "libssl", "libcrypto"))}
BALL = "ball(x[3], a[1]) { ball = 1 - x[1]^2 - x[2]^2 - x[3]^2; }\n"
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def symbols(path, flag):
    out = subprocess.run(["nm", "-D", flag, path], capture_output=True, text=True, check=True).stdout
    return {line.split()[-1] for line in out.splitlines() if line.split()}


def demangled(names):
    out = subprocess.run(["c++filt"], input="\n".join(sorted(names)), capture_output=True, text=True).stdout
    return out.split("\n")


for module, (programs, libraries) in MODULES.items():
    undefined = sorted(symbols(os.path.join(BIN, module), "--undefined-only"))
    needed_by_module = {s for s, d in zip(undefined, demangled(undefined)) if "frep::" in d}
    for program in programs:
        name = os.path.basename(program)
        dyn = subprocess.run(["readelf", "-d", program], capture_output=True, text=True, check=True).stdout
        check(not any(lib in dyn for lib in libraries), "%s needs none of %s" % (name, ", ".join(libraries)))
        missing = needed_by_module - symbols(program, "--defined-only")
        check(not missing, "%s exports every frepfarm symbol %s needs (%d)" % (name, module, len(needed_by_module)) +
              ("; missing: " + ", ".join(demangled(missing)) if missing else ""))

with tempfile.TemporaryDirectory() as tmp:
    model = os.path.join(tmp, "ball.hf")
    with open(model, "w") as f:
        f.write(BALL)
    env = dict(os.environ, LD_DEBUG="files", LD_DEBUG_OUTPUT=os.path.join(tmp, "ld"))
    r = subprocess.run([FREP, "mesh", model, "-O", os.path.join(tmp, "ball.ply"), "--res", "16", "-b", "1.5", "--workers", "0"],
                       capture_output=True, text=True, env=env)
    loaded = "".join(open(os.path.join(tmp, f)).read() for f in os.listdir(tmp) if f.startswith("ld."))
    check(r.returncode == 0 and "libopenvdb" not in loaded and "libfrep_" not in loaded and "lib3MF" not in loaded
          and "libcrypto" not in loaded, "frep mesh of a .hf to a .ply loads no module nor their libraries (rc %d)" % r.returncode)
    for f in os.listdir(tmp):
        if f.startswith("ld."):
            os.remove(os.path.join(tmp, f))
    r = subprocess.run([FREP, "sample", model, "-O", os.path.join(tmp, "ball.vdb"), "--res", "16", "-b", "1.5", "--workers", "2"],
                       capture_output=True, text=True, env=env)
    loaded = "".join(open(os.path.join(tmp, f)).read() for f in os.listdir(tmp) if f.startswith("ld."))
    check(r.returncode == 0 and os.path.getsize(os.path.join(tmp, "ball.vdb")) > 0 and "libfrep_vdb" in loaded,
          "frep sample to a .vdb loads the module and writes the file (rc %d)" % r.returncode)
    r = subprocess.run([FREP, "mesh", os.path.join(tmp, "ball.vdb"), "-O", os.path.join(tmp, "from_vdb.ply")],
                       capture_output=True, text=True)
    check(r.returncode == 0 and "warning" not in r.stderr, "frep mesh of that .vdb (rc %d) %s" % (r.returncode, r.stderr[-300:]))
    # The .vdb as a primitive: the workers load the module too (frep-worker), same bytes as in-process.
    volume = os.path.join(tmp, "volume.hf")
    with open(volume, "w") as f:
        f.write('v(x[3], a[1]) { v = frVolume(x, "ball.vdb"); }\n')
    meshes = []
    for workers in ("0", "2"):
        out = os.path.join(tmp, "volume_%s.ply" % workers)
        r = subprocess.run([FREP, "mesh", volume, "-O", out, "--res", "24", "-b", "1.5", "--workers", workers],
                           capture_output=True, text=True, cwd=tmp)
        check(r.returncode == 0, "frVolume of the .vdb meshed with %s workers (rc %d) %s" % (workers, r.returncode, r.stderr[-300:]))
        meshes.append(open(out, "rb").read() if r.returncode == 0 else b"")
    check(meshes[0] == meshes[1] and len(meshes[0]) > 1000, "the same bytes in-process and on 2 workers")
    # .3mf (a ZIP archive) and .glb through the mesh file module.
    for ext, magic in ((".3mf", b"PK"), (".glb", b"glTF")):
        for f in os.listdir(tmp):
            if f.startswith("ld."):
                os.remove(os.path.join(tmp, f))
        out = os.path.join(tmp, "ball" + ext)
        r = subprocess.run([FREP, "mesh", model, "-O", out, "--res", "16", "-b", "1.5"], capture_output=True, text=True, env=env)
        loaded = "".join(open(os.path.join(tmp, f)).read() for f in os.listdir(tmp) if f.startswith("ld."))
        check(r.returncode == 0 and open(out, "rb").read(4).startswith(magic) and "libfrep_mesh_files" in loaded
              and "libfrep_vdb" not in loaded, "frep mesh to a %s loads the mesh file module only (rc %d)" % (ext, r.returncode))

    # A program without its module: a clear error, exit 4 (docs/cli.md), no output file.
    alone = os.path.join(tmp, "alone")
    os.mkdir(alone)
    shutil.copy(FREP, alone)
    shutil.copy(WORKER, alone)
    out = os.path.join(tmp, "never.vdb")
    r = subprocess.run([os.path.join(alone, "frep"), "sample", model, "-O", out, "--res", "16", "--workers", "0"],
                       capture_output=True, text=True)
    check(r.returncode == 4 and "OpenVDB module" in r.stderr and "libfrep_vdb.so: not found" in r.stderr
          and not os.path.exists(out), "without the module: exit 4, the paths tried named, no file (rc %d: %s)"
          % (r.returncode, r.stderr.strip()[-300:]))
    for ext in (".3mf", ".glb"):
        out = os.path.join(tmp, "never" + ext)
        r = subprocess.run([os.path.join(alone, "frep"), "mesh", model, "-O", out, "--res", "16", "-b", "1.5"],
                           capture_output=True, text=True)
        check(r.returncode == 4 and "mesh file module" in r.stderr and "libfrep_mesh_files.so: not found" in r.stderr
              and not os.path.exists(out) and "meshing" not in r.stderr,
              "without the module a %s: exit 4 before the job, the paths tried named, no file (rc %d: %s)"
              % (ext, r.returncode, r.stderr.strip()[-300:]))
    r = subprocess.run([os.path.join(alone, "frep"), "view", model, "--port", "0"], capture_output=True, text=True, timeout=60)
    check(r.returncode == 4 and "libfrep_view.so: not found" in r.stderr,
          "without the module frep view: exit 4, the paths tried named (rc %d: %s)" % (r.returncode, r.stderr.strip()[-300:]))
    r = subprocess.run([os.path.join(alone, "frep"), "mesh", model, "-O", os.path.join(tmp, "alone.ply"), "--res", "16", "-b", "1.5"],
                       capture_output=True, text=True)
    check(r.returncode == 0, "without the module a mesh job still runs (rc %d)" % r.returncode)

print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
