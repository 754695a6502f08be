#!/usr/bin/env bash
# deploy/slurm/frep.sbatch on a real single-node Slurm: munged, slurmctld and slurmd (Debian's
# slurm-wlm and munge) started here as local daemons on loopback, with a slurm.conf in a temporary
# directory, then four jobs submitted with sbatch --wait:
#   1. a sphere at res 32 with 2 workers: job exit 0, output equal to `frep sample --workers 0`;
#   2. the same with workers that abort after 3 bricks (FREP_TEST_DIE_AFTER=3): the
#      slots restart them, exit 0, same output;
#   3. a model with a syntax error: exit 1 (the master's code, not 75), no step started;
#   4. a bad option (--band 0) that only the master sees: exit 2, workers stopped, no hold.
# Exit 77 (ctest SKIP_RETURN_CODE) when Slurm is not installed or cannot start here (not root,
# no daemons).
#   slurm_e2e.sh SOURCE_DIR BIN_DIR
set -uo pipefail
src="$(cd "$1" && pwd)"; bin="$(cd "$2" && pwd)"
skip() { echo "SKIP: $*"; exit 77; }
[ "$(id -u)" -eq 0 ] || skip "needs root to start slurmd/slurmctld/munged"
for p in munged slurmctld slurmd sbatch sinfo scontrol srun; do
  command -v "$p" >/dev/null || [ -x "/usr/sbin/$p" ] || skip "$p not installed (apt-get install slurm-wlm munge)"
done
export PATH="$bin:/usr/sbin:$PATH"

tmp="$(mktemp -d /tmp/frep-slurm-e2e.XXXXXX)"
chmod 755 "$tmp"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null; done
  sleep 0.5
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null; wait "$p" 2>/dev/null; done
  [ -n "${FREP_E2E_KEEP:-}" ] && echo "kept $tmp" || rm -rf "$tmp"
}
trap cleanup EXIT
port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }

# munge: a fresh key and a private socket, nothing of the system's own installation touched.
mkdir -p "$tmp/munge" "$tmp/state" "$tmp/spool" "$tmp/jobs"
dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$tmp/munge"; chmod 400 "$tmp/munge/munge.key"
munged --foreground --force --key-file="$tmp/munge/munge.key" --socket="$tmp/munge/munge.sock" \
  --pid-file="$tmp/munge/munged.pid" --log-file="$tmp/munge/munged.log" --seed-file="$tmp/munge/seed" \
  >"$tmp/munge/out.log" 2>&1 &
pids+=($!)
for ((t = 0; t < 50; t++)); do [ -S "$tmp/munge/munge.sock" ] && break; sleep 0.1; done
[ -S "$tmp/munge/munge.sock" ] || { cat "$tmp/munge/out.log" "$tmp/munge/munged.log" 2>/dev/null; skip "munged did not start"; }

cat >"$tmp/slurm.conf" <<EOF
ClusterName=frepci
SlurmctldHost=localhost
SlurmctldPort=$(port)
SlurmdPort=$(port)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/munge.sock
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SlurmdParameters=config_overrides
ReturnToService=2
SchedulerType=sched/builtin
KillWait=5
MinJobAge=30
NodeName=localhost NodeAddr=127.0.0.1 CPUs=4 State=UNKNOWN
PartitionName=ci Nodes=localhost Default=YES MaxTime=10 State=UP
EOF
export SLURM_CONF="$tmp/slurm.conf"
slurmctld -D -f "$SLURM_CONF" >"$tmp/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N localhost -f "$SLURM_CONF" >"$tmp/slurmd.out" 2>&1 &
pids+=($!)
up=0
for ((t = 0; t < 300; t++)); do
  if sinfo -h -N -o '%T' 2>/dev/null | grep -qx idle; then up=1; break; fi
  sleep 0.1
done
if [ $up -eq 0 ]; then
  tail -n 20 "$tmp"/slurmctld.log "$tmp"/slurmd.log "$tmp"/*.out 2>/dev/null
  skip "the single-node Slurm did not come up within 30 s"
fi
echo "slurm: $(sinfo -V), node $(sinfo -h -N -o '%N %T %c')"

failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
model="$tmp/sphere.hf"
echo 'my_model(x[3], a[1]) { my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2; }' >"$model"
job_args=(-g 32 -b 1.6 --brick 32)  # 33³ points on the world lattice, 8 bricks: the churn job's workers die on their fourth
frep sample "$model" "${job_args[@]}" --workers 0 --out "$tmp/reference.vdb" >/dev/null 2>&1 || fail "--workers 0 run failed"

# One sbatch --wait job in its own directory; prints its exit code.
run_job() {  # name model [env assignments...]
  local name="$1" m="$2"; shift 2
  local dir="$tmp/jobs/$name"
  mkdir -p "$dir"
  local rc=0
  (cd "$dir" && env "$@" FREP_PORT="$(port)" timeout 150 sbatch --wait --quiet --nodes=1 --ntasks=3 --cpus-per-task=1 \
     --time=5 --output="$dir/batch.log" "$src/deploy/slurm/frep.sbatch" "$m" "$dir/out.vdb" "${job_args[@]}") \
     >"$dir/sbatch.out" 2>&1 || rc=$?
  echo "$rc"
}
show_logs() { for f in "$tmp/jobs/$1"/*.log "$tmp/jobs/$1/sbatch.out"; do echo "--- $f"; tail -n 15 "$f"; done; }
same_output() {  # job name: the .vdb must be byte for byte the in-process one
  cmp "$tmp/reference.vdb" "$tmp/jobs/$1/out.vdb" && echo "$1: out.vdb identical to --workers 0 (bytes)"
}

start=$SECONDS
rc=$(run_job sphere "$model" FREP_TEST_SLOW_MS=200)
echo "job sphere: exit $rc in $((SECONDS - start)) s"
if [ "$rc" != 0 ]; then fail "sphere job exited $rc"; show_logs sphere
else same_output sphere || { fail "sphere: output differs from --workers 0"; show_logs sphere; }
     grep -q '"workers_seen": *[12]' "$tmp/jobs/sphere/out.vdb.report.json" || fail "sphere: report has no workers"
fi

start=$SECONDS
rc=$(run_job churn "$model" FREP_TEST_DIE_AFTER=3 FREP_TEST_SLOW_MS=200)
echo "job churn (workers abort after 3 bricks): exit $rc in $((SECONDS - start)) s"
if [ "$rc" != 0 ]; then fail "churn job exited $rc"; show_logs churn
else same_output churn || { fail "churn: output differs from --workers 0"; show_logs churn; }
     grep -q "restart 1 of" "$tmp"/jobs/churn/frep-*-worker-*.log || fail "churn: no worker was restarted"
fi

# The other verbs (FREP_VERB): mesh and render on the farm, measure on one task; each output
# byte for byte (measure: the same JSON) what the verb writes in-process.
verb_job() {  # name verb out ntasks [args...]
  local name="$1" verb="$2" out="$3" ntasks="$4"; shift 4
  local dir="$tmp/jobs/$name" rc=0
  mkdir -p "$dir"
  (cd "$dir" && env FREP_VERB="$verb" FREP_PORT="$(port)" timeout 150 sbatch --wait --quiet --nodes=1 \
     --ntasks="$ntasks" --cpus-per-task=1 --time=5 --output="$dir/batch.log" "$src/deploy/slurm/frep.sbatch" \
     "$model" "$dir/$out" "$@") >"$dir/sbatch.out" 2>&1 || rc=$?
  echo "$rc"
}
frep mesh "$model" -g 32 -b 1.6 --brick 32 --workers 0 --out "$tmp/reference.ply" >/dev/null 2>&1 || fail "mesh --workers 0 failed"
frep render "$model" -b 1.6 --size 96x96 --workers 0 --out "$tmp/reference.png" >/dev/null 2>&1 || fail "render --workers 0 failed"
frep measure "$model" -b 1.6 --json --no-progress --threads 1 >"$tmp/reference.json" 2>/dev/null || fail "measure failed"
for spec in "mesh out.ply 3 -g 32 -b 1.6 --brick 32" "render out.png 3 -b 1.6 --size 96x96" \
            "measure out.json 1 -b 1.6"; do
  read -r verb out ntasks args <<<"$spec"
  start=$SECONDS
  # shellcheck disable=SC2086
  rc=$(verb_job "$verb" "$verb" "$out" "$ntasks" $args)
  echo "job $verb (FREP_VERB=$verb): exit $rc in $((SECONDS - start)) s"
  if [ "$rc" != 0 ]; then fail "$verb job exited $rc"; show_logs "$verb"; continue; fi
  ref="$tmp/reference.${out##*.}"
  if [ "$verb" = measure ]; then  # the wall time differs run to run: compare the numbers
    python3 -c 'import json,sys; a,b=(json.load(open(f)) for f in sys.argv[1:]); [d.pop(k,None) for d in (a,b) for k in ("seconds","wall_seconds","time")]; sys.exit(a!=b)' \
      "$ref" "$tmp/jobs/$verb/$out" && echo "measure: out.json has the in-process numbers" \
      || { fail "measure: out.json differs from the in-process run"; show_logs measure; }
  else
    cmp "$ref" "$tmp/jobs/$verb/$out" && echo "$verb: $out identical to --workers 0 (bytes)" \
      || { fail "$verb: output differs from --workers 0"; show_logs "$verb"; }
  fi
done

bad="$tmp/bad.hf"
printf 'my_model(x[3], a[1]) {\n  my_model = 1 - x[1]^2 +;\n}\n' >"$bad"
start=$SECONDS
rc=$(run_job bad "$bad")
took=$((SECONDS - start))
echo "job bad model: exit $rc in $took s"
[ "$rc" = 1 ] || { fail "bad model: job exited $rc, expected 1 (model error)"; show_logs bad; }
# No step started: no worker waited for a master (times are printed, not judged: shared machine).
! ls "$tmp"/jobs/bad/frep-*-worker-*.log >/dev/null 2>&1 || fail "bad model: worker steps were started"
grep -q "bad.hf:2:" "$tmp/jobs/bad/batch.log" || { fail "bad model: no file:line diagnostic in the job's output"; show_logs bad; }

# An error the master finds after the steps started (a bad option): its code 2, not a
# worker's 75 after minutes of waiting for a master that is gone.
job_args=(--res 32 -b 1.5 --band 0)
start=$SECONDS
rc=$(run_job badargs "$model")
took=$((SECONDS - start))
echo "job bad option (--band 0): exit $rc in $took s"
[ "$rc" = 2 ] || { fail "bad option: job exited $rc, expected 2 (the master's bad-arguments code)"; show_logs badargs; }
# The workers were stopped by the script, not by their own --master-timeout (exit 75, 300 s).
grep -q "master exited 2" "$tmp/jobs/badargs/batch.log" || fail "bad option: the script did not report the master's 2"
! grep -q "exited 75" "$tmp"/jobs/badargs/frep-*-worker-*.log 2>/dev/null || fail "bad option: a worker timed out waiting"

[ $failures -eq 0 ] && echo "slurm e2e: all passed" && exit 0
echo "slurm e2e: $failures failure(s)"
exit 1
