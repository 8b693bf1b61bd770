#!/usr/bin/env bash
# One machine, several GPUs: one shard of a lodbench experiment per adapter with GNU parallel, then the merge
# (docs/cluster.md).
#   scripts/cluster/parallel-shards.sh EXPERIMENT OUT ADAPTER [ADAPTER ...]
# ADAPTER is an adapter's index (0-based, as `lodbench list` prints them; it tells identical GPUs apart) or a
# part of its name; give one per shard (`0 1 2 3` on a node of four GPUs; the same one twice runs two shards on
# one adapter). LODBENCH names the binary (default target/release/lodbench).
set -euo pipefail
if (($# < 3)); then
    echo "usage: $0 EXPERIMENT OUT ADAPTER [ADAPTER ...]" >&2
    exit 2
fi
experiment=$1
out=$2
shift 2
n=$#
lodbench=${LODBENCH:-target/release/lodbench}
command -v parallel >/dev/null || { echo "error: GNU parallel is not installed" >&2; exit 2; }
seq 1 "$n" | parallel --will-cite --quote --jobs "$n" --halt now,fail=1 --link \
    "$lodbench" experiment "$experiment" --shard '{1}/'"$n" --adapter '{2}' --out "$out/shard-{1}" --resume \
    :::: - ::: "$@"
shards=()
for i in $(seq 1 "$n"); do
    shards+=("$out/shard-$i")
done
"$lodbench" merge "${shards[@]}" --out "$out/merged"
