#!/usr/bin/env bash
# The papers' experiments on this machine's GPU, in one command (docs/cluster.md, "The GPU suite"):
#   scripts/gpu-suite.sh [--budget-s S] [--out ROOT] [--software] [FRAMES [EXPERIMENT ...]]
# The probe, the overhead, the A/A check at the paper's size, FSI's Fig. 8, Sheliemietiev's Fig. 5, then the rest,
# into results/gpu/<adapter>/ with each step's time in times.txt; with --budget-s S it sizes each step's frames from
# the probe's rates so the suite ends within S seconds, and says in times.txt and budget.json what ran, what was
# cut at the deadline and what was left. scripts/gpu_suite.py is the suite; this name is what the recipes call.
# LODBENCH names a lodbench binary to use instead of building one.
set -euo pipefail
exec python3 "$(dirname "$0")/gpu_suite.py" "$@"
