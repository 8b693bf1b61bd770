#!/usr/bin/env bash
# The papers' experiments on this machine's GPU, in one command (docs/cluster.md, "The GPU suite"):
#   scripts/gpu-suite.sh [FRAMES [EXPERIMENT ...]]
# runs lodbench probe (the adapter's ceilings) and lodbench overhead (the harness against a bare draw), then scenes/experiments/aa-gpu.toml (the A/A check the suite's ratios are read against, then
# scripts/aa_check.py), then {fsi-fig8,sheliemietiev-fig5,sheliemietiev-fig6,trees-sorting,unified-lod,
# terrain-equal-error,frontier}.toml, or only the EXPERIMENTs named (file names without .toml), at
# the papers' scenes, instance counts and viewports, with FRAMES timed frames (default 150; the papers' 3,600
# would take hours) and 10 warm-up frames per block, into results/gpu/<adapter>/<experiment>/, draws the
# figures (scripts/plot.py), writes each experiment's wall time to results/gpu/<adapter>/times.txt and prints
# the claims that need a GPU (docs/claims.md) to read the figures against. terrain-equal-error runs twice, with
# the GPU clock's warm-up before each timed segment (--clock-warmup, on by default on a GPU) and without it
# (terrain-equal-error-no-warmup/), and scripts/clock_drops.py lists the blocks whose speed changed in each
# (clock_drops.md): whether the warm-up prevents the H200's slow pixel-error-0.5 block. It stops at once when the
# best adapter is a software one. LODBENCH names a lodbench binary to use instead of building one.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-${FRAMES:-150}}
shift || true
all=(aa-gpu fsi-fig8 sheliemietiev-fig5 sheliemietiev-fig6 trees-sorting unified-lod terrain-equal-error frontier)
experiments=("${@:-${all[@]}}")
for exp in "${experiments[@]}"; do
    if [[ ! -f scenes/experiments/$exp.toml ]]; then
        echo "error: no experiment '$exp' (scenes/experiments/$exp.toml); the suite's are: ${all[*]}" >&2
        exit 2
    fi
done
case $frames in
    '' | *[!0-9]*) echo "error: FRAMES must be a whole number, not '$frames'" >&2; exit 2 ;;
esac
lodbench=${LODBENCH:-}
if [[ -z $lodbench ]]; then
    cargo build --release --quiet
    lodbench=target/release/lodbench
fi
# The first adapter `lodbench list` prints (index 0) is the one the runs use; the index is left out of the line.
best=$("$lodbench" list | sed -n '/^adapters/{n;s/^ *[0-9][0-9]*  //;p;q;}')
case $best in
    '' | *", Cpu,"*)
        echo "error: the best adapter is a software one (${best:-none found}): the GPU suite needs a GPU" >&2
        exit 2
        ;;
esac
name=$(printf '%s' "${best%%[*}" | sed 's/^ *//; s/ *$//' | tr -c 'A-Za-z0-9._-' '_')
out=results/gpu/$name
mkdir -p "$out"
echo "adapter: $best" | tee -a "$out/times.txt"
# The adapter's ceilings first (lodbench probe: triangle, vertex, fill, depth and read rates with their scaling
# checks; seconds on a GPU, 15 s on lavapipe), so the experiments' costs can be read against them.
start=$(date +%s)
"$lodbench" probe --rounds 20 --out "$out/probe"
echo "probe: $(($(date +%s) - start)) s" | tee -a "$out/times.txt"
# The harness's overhead against a bare instanced draw of the same meshes (lodbench overhead), at the paper's
# bunny-grid counts and 400 trees (37 M triangles a frame at LOD0; the paper's 4,000 would be 372 M, about a second
# a frame at the H200's measured 0.3-0.5 G triangles a second); FRAMES timed frames each, 20 rounds. Expected on a
# GPU: under a minute for 60 frames (5 contenders x 60 frames x 4 blocks, the largest 7 to 37 M triangles a frame).
start=$(date +%s)
"$lodbench" overhead --scene bunny-grid --profile paper --count 50,500,2000 --frames "$frames" --rounds 20 \
    --out "$out/overhead/bunny-grid"
"$lodbench" overhead --scene trees --profile paper --count 400 --frames "$frames" --rounds 20 \
    --out "$out/overhead/trees"
echo "overhead: $(($(date +%s) - start)) s ($frames frames)" | tee -a "$out/times.txt"
for exp in "${experiments[@]}"; do
    extra=()
    if [[ $exp == trees-sorting ]]; then
        extra=(--set dump-every=50)
    fi
    start=$(date +%s)
    "$lodbench" experiment "scenes/experiments/$exp.toml" --set "frames=$frames" --set warmup=10 \
        "${extra[@]}" --out "$out/$exp"
    if [[ $exp == aa-gpu ]]; then
        python3 scripts/aa_check.py "$out/$exp" | tee "$out/$exp/aa_check.md"
    else
        python3 scripts/plot.py "$out/$exp"
    fi
    if [[ $exp == terrain-equal-error ]]; then
        python3 scripts/equal_error.py "$out/$exp"
    fi
    echo "$exp: $(($(date +%s) - start)) s ($frames frames)" | tee -a "$out/times.txt"
    if [[ $exp == terrain-equal-error ]]; then
        # The same without the clock's warm-up (each warm-up takes at most a quarter of a second, one per method
        # and round; run.json's clock_warmup_ms says what they took), then the blocks whose rate changed in each.
        start=$(date +%s)
        "$lodbench" experiment "scenes/experiments/$exp.toml" --set "frames=$frames" --set warmup=10 \
            --set clock-warmup=off --out "$out/$exp-no-warmup"
        python3 scripts/clock_drops.py "$out/$exp" "$out/$exp-no-warmup" | tee "$out/clock_drops.md"
        echo "$exp without the clock warm-up: $(($(date +%s) - start)) s ($frames frames)" | tee -a "$out/times.txt"
    fi
done
echo
echo "The claims that need a GPU (docs/claims.md); read them against the figures in $out:"
grep -F '**needs a GPU**' docs/claims.md | cut -d '|' -f 2,3
