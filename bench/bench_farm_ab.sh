#!/bin/sh
# The master's throughput against a baseline build, alternated on the same machine in one run:
# bench_farm --master-only of BASE and of NEW (their bin/ directories), ROUNDS times each in
# turn (default 3), then the medians of the "decoding on all cores" runs (bricks/s wall, master
# CPU per brick, peak RSS) and NEW/BASE ratios. NEW_LINE (default the same) names the runs of
# NEW to compare, e.g. "streaming into a sink" (the merge streamed to a consumer, not built;
# "streaming into a sink, 256 in flight": the same with 64 fake workers).
# The fake workers share the machine, so wall rates follow the load; master CPU per brick is
# the steadier figure. BASE_LINE (default "decoding on all cores") names the runs of BASE, e.g.
# "streaming into a sink" to compare the streamed runs of both.
#   bench/bench_farm_ab.sh /tmp/main-build/bin build/bin [ROUNDS] [NEW_LINE] [BASE_LINE]
set -eu
BASE=$1 NEW=$2 ROUNDS=${3:-3} NEW_LINE=${4:-decoding on all cores} BASE_LINE=${5:-decoding on all cores}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
i=0
while [ "$i" -lt "$ROUNDS" ]; do
  for which in base new; do
    if [ "$which" = base ]; then bin=$BASE line=$BASE_LINE; else bin=$NEW line=$NEW_LINE; fi
    echo "round $((i + 1)) $which (load $(cut -d' ' -f1 /proc/loadavg))"
    "$bin/bench_farm" --master-only 2>/dev/null | grep "$line:" | tee -a "$out/$which"
  done
  i=$((i + 1))
done
# Fields of a run line: "... = R bricks/s wall; master CPU C us/brick, loop L us/brick; process peak RSS M MiB[; fake workers' CPU F us/brick]"
median() { sort -n | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }
stat() { sed -n "s/.*= \([0-9]*\) bricks\/s wall; master CPU \([0-9]*\) us\/brick.*peak RSS \([0-9]*\) MiB.*/\1 \2 \3/p" "$out/$1" | awk -v f="$2" '{print $f}' | median; }
# The fake workers' own CPU a brick (printed by builds since 2026-12-03; "-" for older ones).
fakes() { sed -n "s/.*fake workers' CPU \([0-9]*\) us\/brick.*/\1/p" "$out/$1" | median; }
for which in base new; do
  echo "$which: median $(stat "$which" 1) bricks/s wall, $(stat "$which" 2) us master CPU per brick, peak RSS $(stat "$which" 3) MiB, fake workers' CPU $(fakes "$which" | grep . || echo -) us per brick"
done
awk -v rb="$(stat base 1)" -v rn="$(stat new 1)" -v cb="$(stat base 2)" -v cn="$(stat new 2)" -v mb="$(stat base 3)" -v mn="$(stat new 3)" \
  'BEGIN {printf "new/base: %.2fx bricks/s wall, %.2fx bricks per CPU-second (%.0f -> %.0f), %.2fx peak RSS\n", rn / rb, cb / cn, 1e6 / cb, 1e6 / cn, mn / mb}'
