#!/usr/bin/env bash
# Remakes every folder of results/cpu/ from the code at HEAD, in the order below, one folder at a time:
#   scripts/regenerate-results.sh [--list] [--stale] [--force] [--out ROOT] [NAME ...]
# Each folder is made in results/cpu/.regen/NAME, then pruned to what the committed folder keeps (a file whose name
# it has, and figures/ and clips/ where it has them: frames.csv and frame dumps go unless it kept them) and moved
# into place;
# a top-level subfolder of the committed folder that the command does not make is kept. Resumable:
# a folder already made by this build (results/cpu/.regen/done lists NAME and the build's commit) is skipped
# unless --force; an interrupted folder is made again from its start. Prints each folder's time and the total.
# --stale prints each folder's build (the commits its manifests name) and whether the sources (src, shaders, scenes,
# Cargo.toml, Cargo.lock, build.rs) changed since: `current` when they did not, else how many later commits
# changed them (a folder made from an uncommitted tree says `dirty`).
# --out ROOT makes the folders in ROOT instead, whole, leaving results/cpu/ alone (the test that the committed
# results are today's, scripts/tests/test_results_today.py, compares such a remake with the committed folder).
#
# Inputs from outside the repository, by environment variable (a folder that needs one that is unset is
# skipped, named at the end, and the script exits 3):
#   GSA    a copy of the Khronos glTF sample assets (github DRx3D/glTF-Sample-Assets-OLD: the folder holding Models/)
#   AG     the glTF Asset-Generator's output (github YuuuZhang/glTF-Asset-Generator: the folder holding Output/)
#   SCAN   the Stanford scan as OBJ (alecjacobson/common-3d-test-models, data/stanford-bunny.obj)
#   TOOLS  a folder where `npm install gltfpack@1.3.0 @gltf-transform/cli@4.5.1 three@0.187.0` was run (npx runs there)
# LODBENCH names a lodbench binary to use instead of building one.
set -euo pipefail
cd "$(dirname "$0")/.."
root=results/cpu
work=$root/.regen
list=0
stale=0
force=0
into=
only=()
while (($#)); do
    case $1 in
        --list) list=1 ;;
        --stale) stale=1 ;;
        --force) force=1 ;;
        --out)
            [[ -n ${2:-} ]] || { echo "error: --out needs a folder" >&2; exit 2; }
            into=$2
            shift
            ;;
        -*) echo "error: unknown option '$1' (--list, --stale, --force, --out ROOT, or folder names)" >&2; exit 2 ;;
        *) only+=("$1") ;;
    esac
    shift
done

LB=${LODBENCH:-}
if [[ -z $LB && $list == 0 && $stale == 0 ]]; then
    cargo build --release --quiet
    LB=target/release/lodbench
fi
# Absolute, for commands that run elsewhere (npx finds gltfpack from the tools' folder only).
[[ -z $LB || $LB == /* ]] || LB=$PWD/$LB
build=$(git describe --always --dirty --abbrev=12)
mkdir -p "$work" ${into:+"$into"}
E=scenes/experiments/cpu
PLOT="python3 scripts/plot.py"

# NAME|MINUTES|NEEDS|COMMANDS ($LB the binary, $D the folder being made; the needs: GSA, AG, SCAN, TOOLS).
# MINUTES: the folder's time on the 2-core development machine (lavapipe) the last time this script made it, rounded
# up (results/cpu/README.md: the folders that quote times were made with nothing else running), to plan a run.
folders=(
"probe-lavapipe|1||\$LB probe --rounds 20 --out \$D"
"ceilings-ci|14||\$LB run --scene simple,windmills,trees,bunny-sweep,bunny-grid,terrain --profile ci --frames 120 --out \$D"
"overhead-ci|29||\$LB overhead --scene bunny-grid --count 50,500,2000 --profile ci --frames 120 --rounds 20 --out \$D/bunny-grid && \$LB overhead --scene trees --profile ci --count 6,100 --rounds 20 --out \$D/trees"
"fsi-fig8-cpu|2||\$LB experiment $E/fsi-fig8-cpu.toml --out \$D && $PLOT \$D"
"fsi-check-cpu|1||\$LB experiment $E/fsi-check-cpu.toml --out \$D && $PLOT \$D"
"sheliemietiev-fig5-cpu|14||\$LB experiment $E/sheliemietiev-fig5-cpu.toml --out \$D && $PLOT \$D"
"sheliemietiev-fig5-cpu-fsi|5||\$LB run --scene bunny-grid --profile paper --count 50,250,500,1000,2000 --width 800 --height 600 --frames 8 --warmup 2 --quality-schedule after --method discrete,fsi --out \$D"
"sheliemietiev-fig6-cpu|3||\$LB experiment $E/sheliemietiev-fig6-cpu.toml --out \$D && $PLOT \$D"
"trees-sorting-cpu|3||\$LB experiment $E/trees-sorting-cpu.toml --out \$D && $PLOT \$D"
"unified-lod-cpu|1||\$LB experiment $E/unified-lod-cpu.toml --out \$D && $PLOT \$D"
"unified-terrain-ci|1||\$LB run --scene terrain --profile ci --method reference,blocks,blocks-noseams,blocks-discrete,clusterlod,blocks-discrete --out \$D && $PLOT \$D"
"unified-bunny-halves-ci|1||\$LB run --scene bunny-halves --profile ci --out \$D && $PLOT \$D"
"timing-aa-bunny-sweep-ci|6||\$LB experiment $E/aa-bunny-sweep-ci.toml --out \$D"
"timing-aa-bunny-grid-ci|11||\$LB experiment $E/aa-bunny-grid-ci.toml --out \$D"
"timing-ratios-ci|3||\$LB run --scene bunny-sweep,windmills --method discrete,alpha,fsi --profile ci --out \$D/ratios-sweep-windmills && \$LB run --scene bunny-grid --method discrete,alpha,fsi --profile ci --count 50,500 --out \$D/ratios-grid"
"timing-quality-cost|2||\$LB run --scene bunny-sweep --method reference,discrete,alpha,fsi --profile ci --out \$D/after && \$LB run --scene bunny-sweep --method reference,discrete,alpha,fsi --profile ci --metrics rmse,pop,de2000 --out \$D/after-de2000 && \$LB run --scene bunny-sweep --method reference,discrete,alpha,fsi --profile ci --metric-reduction workgroup --out \$D/after-workgroup"
"quality-cost-ci|6||\$LB run --scene bunny-sweep,simple --profile ci --out \$D/run-n && \$LB run --scene bunny-sweep,simple --profile ci --out \$D/run-o"
"lodpop-bunny-sweep-ci|8||\$LB run --scene bunny-sweep --profile ci --dump-frames --dump-transitions --out \$D && \$LB perceptual \$D && $PLOT \$D"
"lodpop-trees-ci|5||\$LB run --scene trees --profile ci --dump-frames --dump-transitions --out \$D && \$LB perceptual \$D && $PLOT \$D"
"lodpop-bunny-sweep-paper|12||\$LB run --scene bunny-sweep --profile paper --out \$D && $PLOT \$D"
"windmills-closeup-ci|1||\$LB run --scene windmills --profile ci --frames 240 --camera-path scenes/paths/windmills-closeup.csv --method reference,discrete,alpha,alpha-2pass,alpha-linear,alpha-zwrite,dither,geomorph,fsi --out \$D && $PLOT \$D"
"windmills-walk-quick|1||\$LB export --scene windmills --out \$D/windmills.glb && \$LB run --scene \$D/windmills.glb --camera-path scenes/paths/windmills-walk.csv --method reference,discrete,alpha,dither,geomorph,fsi --frames 120 --out \$D && rm \$D/windmills.glb && $PLOT \$D"
"fox-walk-quick|1||\$LB run --scene tests/data/gltf/Fox.glb --animation Walk --frames 600 --out \$D && $PLOT \$D"
"report-fox-quick|1||\$LB run --scene tests/data/gltf/Fox.glb --out \$D && $PLOT \$D"
"report-bunny-sweep-quick|1||\$LB run --scene bunny-sweep --out \$D && $PLOT \$D"
"geomorph-normal-term-ci|2||\$LB run --scene bunny-sweep --profile ci --method discrete,geomorph --correspondence nearest --out \$D/nearest && \$LB run --scene bunny-sweep --profile ci --method discrete,geomorph --correspondence nearest-position --out \$D/nearest-position"
"fsi-reprojection-orbit-ci|1||\$LB run --scene bunny-sweep --profile ci --camera orbit --method reference,discrete,fsi,fsi-noreproject --out \$D && $PLOT \$D"
"engine-effects-taa-ci|5||\$LB experiment $E/engine-effects-cpu.toml --out \$D && $PLOT \$D"
"engine-effects-dither-fixed-ci|7||\$LB experiment $E/engine-effects-dither-cpu.toml --out \$D && $PLOT \$D"
"engine-effects-dither-moving-ci|5||\$LB experiment $E/engine-effects-dither-cpu.toml --out \$D --set noise-temporal=true --set 'method=[\"reference\",\"dither\"]' && $PLOT \$D"
"engine-effects-shadows-ci|6||\$LB run --scene bunny-sweep --profile ci --shadows on --shadow-size 512 --method reference,discrete,alpha,alpha-2pass,alpha-zwrite,dither,geomorph,fsi --out \$D && $PLOT \$D"
"dither-noise-no-taa-ci|2||\$LB experiment $E/engine-effects-dither-cpu.toml --set taa=off --out \$D"
"simple-perceptual-ci|2||\$LB run --scene simple --profile ci --method discrete,alpha,dither,geomorph,fsi --dump-frames --dump-transitions --out \$D && \$LB perceptual \$D && $PLOT \$D"
"fsi-border-ci|1||\$LB run --scene windmills --profile ci --frames 60 --width 256 --height 256 --method discrete,fsi,fsi-sameframe --dump-frames --out \$D && python3 scripts/pop_regions.py \$D > \$D/pop_regions.csv"
"max-transitions-ci|1||\$LB experiment $E/max-transitions-ci.toml --out \$D"
"dither-skip-ci|1||\$LB experiment $E/dither-skip-ci.toml --out \$D"
"pixel-error-ci|2||\$LB experiment $E/pixel-error-ci.toml --out \$D"
"vis-texture-ci|2||\$LB experiment $E/vis-texture-ci.toml --out \$D"
"vis-space-ci|2||\$LB experiment $E/vis-space-ci.toml --out \$D"
"fsi-blend-ci|4||\$LB experiment $E/fsi-blend-ci.toml --out \$D"
"shader-work-ci|1||\$LB experiment $E/shader-work-ci.toml --out \$D"
"terrain-equal-error-ci|2||\$LB experiment $E/terrain-equal-error-ci.toml --out \$D && python3 scripts/equal_error.py \$D && $PLOT \$D"
"sort-error-trees-ci|4||\$LB run --scene trees --profile ci --method discrete,alpha,alpha-sorted --dump-frames --dump-transitions --out \$D && python3 scripts/sort_error.py \$D"
"frontier-ci|14||\$LB experiment $E/frontier-ci.toml --out \$D && $PLOT \$D"
"frontier-perceptual-ci|16||\$LB experiment $E/frontier-perceptual-ci.toml --out \$D && for r in \$D/runs/*/; do \$LB perceptual \$r; done && $PLOT \$D"
"clips-ci|4||\$LB run --scene bunny-sweep,trees --profile ci --method reference,discrete,alpha,alpha-2pass,alpha-zwrite,dither,geomorph,fsi --dump-frames --dump-transitions --out \$D && \$LB clips \$D --max-frames 20 --transitions 0,1,2 --mp4 only && $PLOT \$D"
"materials-damagedhelmet|1|GSA|\$LB run --scene \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb --method reference,discrete,alpha,dither,geomorph,fsi --frames 600 --dump-frames --dump-transitions --out \$D && \$LB clips \$D --max-frames 16 --mp4 only --methods discrete,alpha,dither,geomorph,fsi && $PLOT \$D"
"materials-waterbottle|1|GSA|\$LB run --scene \$GSA/Models/WaterBottle/glTF/WaterBottle.gltf --method reference,discrete,alpha,dither,geomorph,fsi --frames 600 --out \$D && $PLOT \$D"
"materials-scifihelmet|1|GSA|scifi_available && \$LB run --scene \$GSA/Models/SciFiHelmet/glTF/SciFiHelmet-available.gltf --method reference,discrete,alpha,dither,geomorph,fsi --frames 600 --dump-frames --dump-transitions --out \$D && \$LB clips \$D --max-frames 16 --mp4 only --methods discrete,alpha,dither,geomorph,fsi && $PLOT \$D"
"materials-scifihelmet-flat|1|GSA|scifi_available && \$LB run --scene \$GSA/Models/SciFiHelmet/glTF/SciFiHelmet-available.gltf --materials flat --method reference,discrete,alpha,dither,geomorph,fsi --frames 600 --out \$D && $PLOT \$D"
"materials-damagedhelmet-flat|1|GSA|\$LB run --scene \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb --materials flat --method reference,discrete,alpha,dither,geomorph,fsi --frames 600 --out \$D && $PLOT \$D"
"materials-waterbottle-flat|1|GSA|\$LB run --scene \$GSA/Models/WaterBottle/glTF/WaterBottle.gltf --materials flat --method reference,discrete,alpha,dither,geomorph,fsi --frames 600 --out \$D && $PLOT \$D"
"materials-cost-damagedhelmet-ci|1|GSA|\$LB run --scene \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb --method reference,reference-flat,reference --baseline reference --quality off --profile ci --frames 600 --width 640 --height 480 --out \$D"
"materials-cost-waterbottle-ci|1|GSA|\$LB run --scene \$GSA/Models/WaterBottle/glTF/WaterBottle.gltf --method reference,reference-flat,reference --baseline reference --quality off --profile ci --frames 600 --width 640 --height 480 --out \$D"
"flighthelmet-quick|1|GSA|\$LB run --scene \$GSA/Models/FlightHelmet/glTF/FlightHelmet.gltf --materials flat --dump-frames --dump-every 59 --out \$D"
"tune-bunny-export|1||\$LB export --scene bunny-sweep --out \$D/bunny.glb && \$LB tune --scene \$D/bunny.glb --budget-lodpop 0.004 --speed 2 --views 8 --out \$D && rm \$D/bunny.glb && $PLOT \$D && python3 scripts/tune_rules.py \$D --frames 240"
"tune-damagedhelmet|2|GSA|\$LB tune --scene \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb --budget-lodpop 0.004 --speed 2 --views 8 --out \$D && $PLOT \$D && python3 scripts/tune_rules.py \$D --frames 240"
"tune-stanford-scan|8|SCAN|\$LB tune --scene bunny-sweep --mesh \$SCAN --budget-lodpop 0.004 --speed 2 --views 8 --out \$D && $PLOT \$D && python3 scripts/tune_rules.py \$D --frames 240"
"three-fidelity|2|GSA TOOLS|scifi_available && PATH=\$TOOLS/node_modules/.bin:\$PATH python3 scripts/three_fidelity.py --lodbench \$LB --out \$D \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb \$GSA/Models/BoomBoxWithAxes/glTF/BoomBoxWithAxes.gltf \$GSA/Models/Avocado/glTF/Avocado.gltf \$GSA/Models/WaterBottle/glTF/WaterBottle.gltf \$GSA/Models/AlphaBlendModeTest/glTF/AlphaBlendModeTest.gltf \$GSA/Models/VertexColorTest/glTF/VertexColorTest.gltf \$GSA/Models/TextureCoordinateTest/glTF/TextureCoordinateTest.gltf \$GSA/Models/NormalTangentMirrorTest/glTF/NormalTangentMirrorTest.gltf \$GSA/Models/MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf \$GSA/Models/TextureSettingsTest/glTF/TextureSettingsTest.gltf \$GSA/Models/MultiUVTest/glTF/MultiUVTest.gltf \$GSA/Models/TextureTransformMultiTest/glTF/TextureTransformMultiTest.gltf \$GSA/Models/SciFiHelmet/glTF/SciFiHelmet-available.gltf"
"chain-vs-gltfpack|1|GSA TOOLS|here=\$PWD && cd \$TOOLS && python3 \$here/scripts/chain_vs_gltfpack.py --lodbench \$LB --out \$here/\$D/chains.csv \$GSA/Models/SciFiHelmet/glTF/SciFiHelmet.gltf \$GSA/Models/Fox/glTF-Binary/Fox.glb \$GSA/Models/Suzanne/glTF/Suzanne.gltf \$here/tests/data/gltf/faceted-sphere.gltf"
"chain-pop-vs-gltfpack|2|GSA TOOLS|scifi_available && python3 scripts/chain_pop_vs_gltfpack.py --lodbench \$LB --tools \$TOOLS --out \$D \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb \$GSA/Models/WaterBottle/glTF/WaterBottle.gltf \$GSA/Models/SciFiHelmet/glTF/SciFiHelmet-available.gltf"
"gltf-read-check|3|GSA AG|read_check"
"calibration-simulated|57|GSA|\$LB calibrate --scene bunny-sweep,\$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb --out \$D/cal && mv \$D/cal/stimuli.json \$D/ && rm -r \$D/cal && python3 scripts/calibration.py simulate \$D/stimuli.json --metric lodpop --threshold 0.0012 --slope 3 --lapse 0.02 --seed 1 --out \$D/responses-simulated.json && python3 scripts/calibration.py fit \$D/stimuli.json \$D/responses-simulated.json --out \$D && python3 scripts/calibration.py trials \$D/stimuli.json --metric lodpop --threshold 0.0012 --slope 3 --lapse 0.02 --trials 20,40,60,80 --seeds 40 --bootstrap 200 --out \$D"
"tune-jnd-bunny-export|5||\$LB export --scene bunny-sweep --out \$D/bunny.glb && \$LB tune --scene \$D/bunny.glb --calibration results/cpu/calibration-simulated/calibration.json --budget-jnd 1 --views 8 --out \$D && \$LB run --scene \$D/tuned.glb --method discrete --width 1920 --height 1080 --frames 240 --rounds 2 --calibration results/cpu/calibration-simulated/calibration.json --out \$D/run && rm \$D/bunny.glb"
"tune-1080-bunny-export|5||\$LB export --scene bunny-sweep --out \$D/bunny.glb && \$LB tune --scene \$D/bunny.glb --budget-lodpop 0.004 --width 1920 --height 1080 --views 8 --out \$D && rm \$D/bunny.glb"
"engine-check|26|GSA|W=\$(mktemp -d) && \$LB export --scene bunny-sweep --out \$W/bunny-sweep.glb && \$LB tune --scene \$W/bunny-sweep.glb --budget-lodpop 0.004 --speed 2 --views 8 --out \$W/tune-bunny && \$LB tune --scene \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb --budget-lodpop 0.004 --speed 2 --views 8 --out \$W/tune-damagedhelmet && \$LB tune --scene \$GSA/Models/WaterBottle/glTF/WaterBottle.gltf --budget-lodpop 0.004 --speed 2 --views 8 --out \$W/tune-waterbottle && python3 scripts/engine_check.py \$W/tune-bunny \$W/tune-damagedhelmet \$W/tune-waterbottle --out \$D --frames 240 --binary \$LB && rm -rf \$W"
"tune-jnd-damagedhelmet|10|GSA|\$LB tune --scene \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb --calibration results/cpu/calibration-simulated/calibration.json --budget-jnd 1 --views 8 --out \$D && \$LB run --scene \$D/tuned.glb --method discrete --width 1920 --height 1080 --frames 240 --rounds 2 --calibration results/cpu/calibration-simulated/calibration.json --out \$D/run"
"tune-1080-damagedhelmet|10|GSA|\$LB tune --scene \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb --budget-lodpop 0.004 --width 1920 --height 1080 --views 8 --out \$D"
"impostors|13||python3 scripts/impostor_sweep.py \$D --lodbench \$LB --orbit"
"impostor-trees-ci|3||\$LB run --scene trees --profile ci --impostor --method discrete,dither,alpha,alpha-2pass,alpha-zwrite,fsi --out \$D"
"impostors-tune-trees|1||\$LB tune --scene trees --impostor --budget-lodpop 0.004 --views 8 --out \$D"
"impostor-damagedhelmet|1|GSA|\$LB run --scene \$GSA/Models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb --impostor --impostor-distance 18 --method discrete,dither,alpha,alpha-2pass --out \$D"
"visible-pops-ci|20||\$LB experiment \$E/visible-pops-ci.toml --out \$D && $PLOT \$D"
)

for name in "${only[@]}"; do
    found=0
    for entry in "${folders[@]}"; do
        [[ ${entry%%|*} == "$name" ]] && found=1
    done
    ((found)) || { echo "error: no folder '$name' in the list (--list prints it)" >&2; exit 2; }
done

# SciFiHelmet with the textures the sample assets' copy lacks left out (docs/findings/materials.md), made beside
# SciFiHelmet.gltf once.
scifi_available() {
    local dir=$GSA/Models/SciFiHelmet/glTF
    [[ -f $dir/SciFiHelmet-available.gltf ]] && return 0
    python3 - "$dir" <<'EOF'
import json, os, sys
here = sys.argv[1]
d = json.load(open(os.path.join(here, 'SciFiHelmet.gltf')))
keep = [i for i, im in enumerate(d['images']) if os.path.exists(os.path.join(here, im['uri']))]
img = {o: n for n, o in enumerate(keep)}
tex_keep = [i for i, t in enumerate(d['textures']) if t['source'] in img]
tex = {o: n for n, o in enumerate(tex_keep)}
d['images'] = [d['images'][i] for i in keep]
d['textures'] = [dict(d['textures'][i], source=img[d['textures'][i]['source']]) for i in tex_keep]
for m in d['materials']:
    pbr = m.get('pbrMetallicRoughness', {})
    for holder, k in [(pbr, 'baseColorTexture'), (pbr, 'metallicRoughnessTexture'), (m, 'normalTexture'),
                      (m, 'occlusionTexture'), (m, 'emissiveTexture')]:
        if k in holder:
            if holder[k]['index'] in tex:
                holder[k]['index'] = tex[holder[k]['index']]
            else:
                del holder[k]
json.dump(d, open(os.path.join(here, 'SciFiHelmet-available.gltf'), 'w'))
EOF
}
export -f scifi_available

# The two sets of glTF files checked against scripts/check_gltf.py's own decoder, one report each, their files
# named as the committed reports name them (glTF-Sample-Assets/Models/..., glTF-Asset-Generator/Output/Positive/...),
# through a tree of links to the sample assets' files (a file written into $GSA by hand is checked too).
# A mismatch (exit status 1) is a finding the report records, not a failure of the command.
read_check() {
    local here lb out t status set files report
    here=$PWD
    lb=$(realpath "$LB")
    out=$(realpath "$D")
    t=$(mktemp -d)
    mkdir "$t/glTF-Sample-Assets"
    cp -rs "$(realpath "$GSA")/Models" "$t/glTF-Sample-Assets/"
    # Not one of the sample assets: scifi_available writes it beside SciFiHelmet.gltf.
    rm -f "$t/glTF-Sample-Assets/Models/SciFiHelmet/glTF/SciFiHelmet-available.gltf"
    ln -s "$(realpath "$AG")" "$t/glTF-Asset-Generator"
    status=0
    for set in "glTF-Sample-Assets/Models khronos-sample-assets.txt" \
        "glTF-Asset-Generator/Output/Positive asset-generator-positive.txt"; do
        read -r files report <<<"$set"
        (cd "$t" && python3 "$here/scripts/check_gltf.py" run --lodbench "$lb" --frames 0,30 "$files" \
            >"$out/$report") || status=$?
        ((status <= 1)) || break
    done
    rm -rf "$t"
    ((status <= 1)) || return "$status"
}
export -f read_check

# Keeps in $1 (the new folder) what the committed folder $2 keeps: a file whose name the committed folder has
# (anywhere in it: a new run of an experiment keeps what the other runs keep), events.csv where it has
# transitions.csv, and figures/ where it has figures.
prune() {
    local new=$1 old=$2 rel
    local -A kept=()
    local figures=0 clips=0
    while IFS= read -r rel; do
        kept[${rel##*/}]=1
        [[ $rel == figures/* || $rel == */figures/* ]] && figures=1
        [[ $rel == clips/* ]] && clips=1
    done < <(git ls-files -- "$old" | sed "s|^$old/||")
    # events.csv is newer than most committed folders: kept wherever the run's transitions.csv is.
    [[ -n ${kept[transitions.csv]:-} ]] && kept[events.csv]=1
    while IFS= read -r rel; do
        rel=${rel#./}
        [[ -n ${kept[${rel##*/}]:-} ]] && continue
        [[ $figures == 1 && ($rel == figures/* || $rel == */figures/*) ]] && continue
        [[ $clips == 1 && $rel == clips/* ]] && continue
        rm -f -- "$new/$rel"
    done < <(cd "$new" && find . -type f)
    find "$new" -mindepth 1 -type d -empty -delete
}

total=0
skipped=()
for entry in "${folders[@]}"; do
    IFS='|' read -r name minutes needs cmd <<<"$entry"
    if ((${#only[@]})) && [[ ! " ${only[*]} " == *" $name "* ]]; then
        continue
    fi
    if [[ $list == 1 ]]; then
        printf '%-34s %4s min  %-10s %s\n' "$name" "$minutes" "${needs:--}" "$cmd"
        continue
    fi
    if [[ $stale == 1 ]]; then
        builds=$(find "$root/$name" -name '*.json' -print0 2>/dev/null | xargs -0 -r grep -ho '"git_commit": *"[^"]*"' \
            | sed 's/.*"\([^"]*\)"$/\1/' | sort -u)
        [[ -n $builds ]] || { printf '%-34s %s\n' "$name" "no manifest names a build"; continue; }
        for b in $builds; do
            c=${b%-dirty}
            if ! git cat-file -e "$c^{commit}" 2>/dev/null; then
                state="not a commit of this repository"
            else
                n=$(git rev-list --count "$c..HEAD" -- src shaders scenes Cargo.toml Cargo.lock build.rs)
                state=$([[ $n == 0 ]] && echo current || echo "sources changed by $n later commits")
                [[ $b == *-dirty ]] && state="$state, dirty"
            fi
            printf '%-34s %-20s %s\n' "$name" "$b" "$state"
        done
        continue
    fi
    missing=()
    for v in $needs; do
        [[ -n ${!v:-} ]] || missing+=("$v")
    done
    if ((${#missing[@]})); then
        skipped+=("$name (set ${missing[*]})")
        echo "skip $name: needs ${missing[*]}"
        continue
    fi
    if [[ -z $into && $force == 0 ]] && grep -qx "$name $build" "$work/done" 2>/dev/null; then
        echo "done $name (made by $build)"
        continue
    fi
    D=${into:-$work}/$name
    rm -rf "$D"
    mkdir -p "$D"
    echo "make $name (about $minutes min on the development machine): $cmd"
    start=$(date +%s)
    # shellcheck disable=SC2034 # LB, D, GSA, AG, SCAN and TOOLS are read by the command.
    log=${into:-$work}/$name.log
    (export LB D GSA AG SCAN TOOLS; eval "$cmd") >"$log" 2>&1 || {
        echo "error: $name failed (its output: $log)" >&2
        tail -5 "$log" >&2
        exit 1
    }
    secs=$(($(date +%s) - start))
    total=$((total + secs))
    if [[ -z $into ]]; then
        prune "$D" "$root/$name"
        # A top-level folder the committed one has and this command does not make (a run of an earlier build that
        # a page quotes, quality-cost-ci's run-a to run-m) is kept; --stale then names both builds.
        for old in "$root/$name"/*/; do
            [[ -d $old ]] || continue
            sub=$(basename "$old")
            [[ -e $D/$sub ]] || cp -a "$old" "$D/$sub"
        done
        rm -rf "${root:?}/$name"
        mv "$D" "$root/$name"
        echo "$name $build" >>"$work/done"
    fi
    echo "made $name in $secs s"
done
[[ $list == 1 ]] && exit 0
echo "total: $total s this invocation (build $build)"
if ((${#skipped[@]})); then
    printf 'not made (inputs missing): %s\n' "${skipped[@]}" >&2
    exit 3
fi
