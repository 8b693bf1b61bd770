// LOD-chain fixtures for make.sh. Usage (GLTF_TOOLS = npm tool directory, default /tmp/gltftools):
//   node lod.mjs SRC.glb OUTDIR
// From SRC's one mesh (LOD0, kept as is) makes LOD1 (~50% of the triangles) and LOD2 (~25%) with
// glTF-Transform's simplifyPrimitive and meshoptimizer's MeshoptSimplifier (error bound lifted so
// the ratio decides), each LOD with its own compacted vertex data, and writes to OUTDIR:
//   bunny-lod-names.glb          root nodes Bunny_LOD0, Bunny_LOD1, Bunny_LOD2 (meshes named the same)
//   bunny-msft-lod.glb           Bunny_LOD0 carries MSFT_lod {ids: [LOD1 node, LOD2 node]} and
//                                extras.MSFT_screencoverage [0.5, 0.2, 0.01]; only LOD0 is a scene root;
//                                MSFT_lod in extensionsUsed, not in extensionsRequired
//   bunny-msft-lod-in-scene.glb  the same, with the LOD1 and LOD2 nodes also scene roots (as UnityGLTF writes)
// glTF-Transform drops extensions it does not know, so MSFT_lod is added to the written JSON chunk.
import { join } from 'node:path';
import { load, readGlb, writeGlb } from './glb.mjs';

const [src, outDir] = process.argv.slice(2);
if (!src || !outDir) throw new Error('usage: node lod.mjs SRC.glb OUTDIR');
const toolDir = process.env.GLTF_TOOLS ?? '/tmp/gltftools';
const { NodeIO } = await load(toolDir, '@gltf-transform/core');
const { simplifyPrimitive } = await load(toolDir, '@gltf-transform/functions');
const { MeshoptSimplifier } = await load(toolDir, 'meshoptimizer');
await MeshoptSimplifier.ready;

const io = new NodeIO();
const doc = await io.read(src);
const scene = doc.getRoot().getDefaultScene() ?? doc.getRoot().listScenes()[0];
const lod0 = scene.listChildren().find((n) => n.getMesh());
if (!lod0 || lod0.getMesh().listPrimitives().length !== 1) throw new Error('expected one mesh node with one primitive');
lod0.setName('Bunny_LOD0');
lod0.getMesh().setName('Bunny_LOD0');
const prim0 = lod0.getMesh().listPrimitives()[0];
const tris = (p) => p.getIndices().getCount() / 3;
const counts = [tris(prim0)];
const names = ['Bunny_LOD0'];
for (const [level, ratio] of [[1, 0.5], [2, 0.25]]) {
	const name = `Bunny_LOD${level}`;
	const prim = prim0.clone();
	simplifyPrimitive(prim, { simplifier: MeshoptSimplifier, ratio, error: 1 });
	scene.addChild(doc.createNode(name).setMesh(doc.createMesh(name).addPrimitive(prim)));
	counts.push(tris(prim));
	names.push(name);
}
if (tris(prim0) !== counts[0]) throw new Error('LOD0 changed');
console.log(`lod.mjs: triangles per LOD ${counts.join(', ')}`);

const namesPath = join(outDir, 'bunny-lod-names.glb');
await io.write(namesPath, doc);

// MSFT_lod variants: edit the JSON of the file just written (node order is the writer's).
const { json, bin } = readGlb(namesPath);
const idx = names.map((n) => json.nodes.findIndex((node) => node.name === n));
if (idx.some((i) => i < 0)) throw new Error('LOD node missing');
const lodNode = json.nodes[idx[0]];
lodNode.extensions = { ...(lodNode.extensions ?? {}), MSFT_lod: { ids: [idx[1], idx[2]] } };
lodNode.extras = { ...(lodNode.extras ?? {}), MSFT_screencoverage: [0.5, 0.2, 0.01] };
json.extensionsUsed = [...(json.extensionsUsed ?? []), 'MSFT_lod'];
const sceneDef = json.scenes[json.scene ?? 0];
sceneDef.nodes = [idx[0], idx[1], idx[2]];
writeGlb(join(outDir, 'bunny-msft-lod-in-scene.glb'), json, bin);
sceneDef.nodes = [idx[0]];
writeGlb(join(outDir, 'bunny-msft-lod.glb'), json, bin);
