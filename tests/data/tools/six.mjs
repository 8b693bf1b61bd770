// Instancing fixtures for make.sh. Usage (GLTF_TOOLS = npm tool directory, default /tmp/gltftools):
//   node six.mjs nodes SRC.glb DST.glb     six root nodes Bunny_0..Bunny_5 sharing SRC's one mesh,
//                                          translated along x by i * ceil(1.5 * largest extent)
//   node six.mjs required SRC.glb DST.glb  EXT_mesh_gpu_instancing listed in extensionsRequired
//   node six.mjs optional SRC.glb DST.glb  EXT_mesh_gpu_instancing only in extensionsUsed
// required/optional only edit the JSON chunk; the BIN chunk is copied unchanged.
import { editGlb, load } from './glb.mjs';

const EXT = 'EXT_mesh_gpu_instancing';
const [cmd, src, dst] = process.argv.slice(2);
if (!cmd || !src || !dst) throw new Error('usage: node six.mjs nodes|required|optional SRC DST');

if (cmd === 'nodes') {
	const toolDir = process.env.GLTF_TOOLS ?? '/tmp/gltftools';
	const { NodeIO } = await load(toolDir, '@gltf-transform/core');
	const io = new NodeIO();
	const doc = await io.read(src);
	const scene = doc.getRoot().getDefaultScene() ?? doc.getRoot().listScenes()[0];
	const base = scene.listChildren().find((n) => n.getMesh());
	if (!base || base.getTranslation().some((v) => v !== 0)) throw new Error('expected one untransformed mesh node');
	const mesh = base.getMesh();
	const pos = mesh.listPrimitives()[0].getAttribute('POSITION');
	const min = pos.getMin([]), max = pos.getMax([]);
	const step = Math.ceil(1.5 * Math.max(...max.map((v, i) => v - min[i])));
	base.setName('Bunny_0');
	for (let i = 1; i < 6; i++) {
		scene.addChild(doc.createNode(`Bunny_${i}`).setMesh(mesh).setTranslation([i * step, 0, 0]));
	}
	await io.write(dst, doc);
	console.log(`six.mjs: ${dst}: 6 nodes, x step ${step}`);
} else if (cmd === 'required' || cmd === 'optional') {
	editGlb(src, dst, (json) => {
		if (!(json.extensionsUsed ?? []).includes(EXT)) throw new Error(`${src}: ${EXT} not used`);
		const req = (json.extensionsRequired ?? []).filter((e) => e !== EXT);
		if (cmd === 'required') req.push(EXT);
		if (req.length) json.extensionsRequired = req;
		else delete json.extensionsRequired;
	});
} else {
	throw new Error(`unknown command ${cmd}`);
}
