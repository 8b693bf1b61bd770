#!/usr/bin/env bash
# Regenerates the glTF fixtures in tests/data/tools/ from scenes/bunny.obj with real tools
# (obj2gltf, gltfpack, glTF-Transform), then prints what each file holds (expect.py).
#
# Usage, from anywhere:  bash tests/data/tools/make.sh
# Environment:
#   GLTF_TOOLS  directory whose node_modules holds the npm tools (default /tmp/gltftools).
#               Install them once, at the versions the committed files were made with:
#                 mkdir -p /tmp/gltftools && cd /tmp/gltftools && npm init -y &&
#                 npm install obj2gltf@3.2.0 gltfpack@1.3.0 @gltf-transform/cli@4.5.1 \
#                   @gltf-transform/core@4.5.1 @gltf-transform/functions@4.5.1 meshoptimizer@1.3.0
# Needs node (tested with 20) and python3. Other versions of the tools may write other bytes.
set -euo pipefail

GLTF_TOOLS="${GLTF_TOOLS:-/tmp/gltftools}"
export GLTF_TOOLS
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
src="$root/scenes/bunny.obj"
bin="$GLTF_TOOLS/node_modules/.bin"

for tool in obj2gltf gltfpack gltf-transform; do
	if [[ ! -x "$bin/$tool" ]]; then
		echo "make.sh: $bin/$tool not found; install the tools (see the top of $0)" >&2
		exit 1
	fi
done

version() {
	node -p "require(process.argv[1]).version" "$GLTF_TOOLS/node_modules/$1/package.json"
}
echo "tools: obj2gltf $(version obj2gltf), gltfpack $(version gltfpack)," \
	"@gltf-transform/cli $(version @gltf-transform/cli), meshoptimizer $(version meshoptimizer), node $(node --version)"

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cd "$here"

# 1. the plain source every other file is made from (positions + indices, no normals)
"$bin/obj2gltf" -i "$src" -o bunny-obj2gltf.glb --binary
base=bunny-obj2gltf.glb

# 2. gltfpack
"$bin/gltfpack" -i "$base" -o bunny-gltfpack.glb
"$bin/gltfpack" -i "$base" -o bunny-gltfpack-noq.glb -noq
"$bin/gltfpack" -i "$base" -o bunny-gltfpack-c.glb -c
"$bin/gltfpack" -i "$base" -o bunny-gltfpack-c-khr.glb -c -ce khr

# 3. glTF-Transform
"$bin/gltf-transform" quantize "$base" bunny-gt-quantize.glb
"$bin/gltf-transform" meshopt "$base" bunny-gt-meshopt.glb
"$bin/gltf-transform" draco "$base" bunny-gt-draco.glb
node six.mjs nodes "$base" bunny-six-nodes.glb
node camera.mjs bunny-six-nodes.glb bunny-six-camera.glb
"$bin/gltf-transform" instance bunny-six-nodes.glb "$tmp/instanced.glb"
node six.mjs required "$tmp/instanced.glb" bunny-six-instanced-required.glb
node six.mjs optional "$tmp/instanced.glb" bunny-six-instanced-optional.glb

# 4. LOD chains (glTF-Transform simplifyPrimitive + meshoptimizer)
node lod.mjs "$base" .

python3 expect.py
