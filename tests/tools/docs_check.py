#!/usr/bin/python3
"""The man page (docs/frep.1) and the bash completion (deploy/completion/frep.bash) against the
binaries: every verb and every option that `frep VERB --help` and `frep-worker --help` list is
described in the man page and offered by the completion; the man page renders without warnings;
docs/mesh.md has every option, file extension and --format value of `frep mesh --help`.

usage: docs_check.py SOURCE_DIR FREP FREP_WORKER  (run from ctest; exit 0 = pass)"""
import os
import re
import subprocess
import sys

SRC, FREP, WORKER = (os.path.abspath(a) for a in sys.argv[1:4])
MAN = SRC + "/docs/frep.1"
COMPLETION = SRC + "/deploy/completion/frep.bash"
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def help_text(*args):
    return subprocess.run(list(args) + ["--help"], capture_output=True, text=True, check=True).stdout


def options(text):
    """The options of a CLI11 help text: the first column of its option lines."""
    found = set()
    for line in text.splitlines():
        m = re.match(r"^\s+(-[^\s]+)", line)
        if m:
            found.update(o for o in m.group(1).split(",") if o.startswith("-"))
    return found


def complete(*words):
    """What _frep (or _frep_worker) offers for the command line `words` (the last is completed)."""
    func = "_frep_worker" if words[0] == "frep-worker" else "_frep"
    quoted = " ".join("'%s'" % w for w in words)
    script = 'source "%s"; COMP_WORDS=(%s); COMP_CWORD=%d; %s; printf "%%s\\n" "${COMPREPLY[@]}"' % (
        COMPLETION, quoted, len(words) - 1, func)
    r = subprocess.run(["bash", "-c", script], capture_output=True, text=True, cwd="/")
    return set(r.stdout.split())


man = open(MAN).read().replace("\\-", "-")
top = help_text(FREP)
verbs = re.findall(r"^  ([a-z]+) {2,}", top.split("Subcommands:")[1], re.M)
check(len(verbs) >= 8, "verbs from frep --help: " + " ".join(verbs))
check(set(verbs) <= complete("frep", ""), "completion offers every verb")
for verb in verbs:
    check(re.search(r"^\.B %s$" % verb, man, re.M) is not None, "man page describes the verb " + verb)
    opts = options(help_text(FREP, verb))
    missing_man = sorted(o for o in opts if not re.search(r"(?<![\w-])%s(?![\w-])" % re.escape(o), man))
    check(not missing_man, "man page has the options of %s%s" % (verb, ": missing " + " ".join(missing_man) if missing_man else ""))
    offered = complete("frep", verb, "-")
    missing = sorted(opts - offered)
    check(not missing, "completion offers the options of %s%s" % (verb, ": missing " + " ".join(missing) if missing else ""))
for o in options(top):
    check(o in man and o in complete("frep", "-"), "global option " + o)

worker_opts = options(help_text(WORKER))
check("--version" in worker_opts, "frep-worker --help lists --version")
missing = sorted(worker_opts - complete("frep-worker", "-"))
check(not missing, "completion offers frep-worker's options" + (": missing " + " ".join(missing) if missing else ""))
missing_man = sorted(o for o in worker_opts if o not in man)
check(not missing_man, "man page has frep-worker's options" + (": missing " + " ".join(missing_man) if missing_man else ""))
version = subprocess.run([WORKER, "--version"], capture_output=True, text=True)
check(version.returncode == 0 and version.stdout.startswith("frep-worker "), "frep-worker --version: " + version.stdout.strip())

# Values: --store, --log-level, --axis; a model path completes to .hf files.
check(complete("frep", "sample", "--store", "") == {"sdf", "sdf-exact", "raw", "fog"}, "completion of --store values")
check("debug" in complete("frep", "--log-level", "d"), "completion of --log-level values")
check(complete("frep", "slice", "m.hf", "--axis", "") == {"x", "y", "z"}, "completion of --axis values")

# docs/mesh.md against frep mesh --help: every option (in one of its spellings), every -O
# extension and every --format value, and no feature that exists called "planned".
mesh_help = help_text(FREP, "mesh")
mesh_doc = open(SRC + "/docs/mesh.md").read()
for line in mesh_help.splitlines():
    m = re.match(r"^\s+(-[^\s]+)", line)
    spellings = [o for o in m.group(1).split(",") if o.startswith("-")] if m else []
    if spellings and "--help" not in spellings:
        check(any(re.search(r"(?<![\w-])%s(?![\w-])" % re.escape(o), mesh_doc) for o in spellings),
              "docs/mesh.md has frep mesh's option " + "/".join(spellings))
out_line = next(l for l in mesh_help.splitlines() if "-O,--out" in l)
extensions = re.findall(r"(?<![\w.])\.([a-z0-9]+)\b", out_line)
check(len(extensions) >= 9, "-O's extensions from frep mesh --help: " + " ".join(extensions))
missing = [e for e in extensions if "`.%s`" % e not in mesh_doc]
check(not missing, "docs/mesh.md names every mesh file extension" + (": missing " + " ".join(missing) if missing else ""))
format_line = next(l for l in mesh_help.splitlines() if l.strip().startswith("--format"))
formats = [f.strip() for f in format_line.split(":", 1)[1].split(",")]
missing = [f for f in formats if not re.search(r"(?<![\w-])%s(?![\w-])" % re.escape(f), mesh_doc)]
check(len(formats) >= 9 and not missing, "docs/mesh.md names every --format value" + (": missing " + " ".join(missing) if missing else ""))
planned = [l for l in mesh_doc.splitlines() if "planned" in l and "--" in l]
check(not planned, "docs/mesh.md calls no existing option planned" + (": " + " | ".join(planned) if planned else ""))

r = subprocess.run(["groff", "-man", "-Tutf8", "-ww", "-z", MAN], capture_output=True, text=True)
check(r.returncode == 0 and r.stderr == "", "groff renders the man page without warnings" + (": " + r.stderr if r.stderr else ""))
check("SPDLOG_LEVEL" in man and "EXIT STATUS" in man, "man page documents SPDLOG_LEVEL and the exit codes")

print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
