// Camera-animation fixture for make.sh. Usage (GLTF_TOOLS = npm tool directory, default /tmp/gltftools):
//   node camera.mjs SRC.glb DST.glb
// SRC's scene plus a perspective camera (yfov 0.8 rad) on a node under a parent translated by (0, 5, 0), with a
// LINEAR animation over 4 s: translation keys (0, 0, 20), (30, 0, 40), (75, 0, 60) at 0, 2, 4 s, and rotation
// keys at 0 and 4 s (identity, then 0.25 rad about +y), so an importer must
// compose parent, translation and rotation, and resample two channels with different key times.
import { load } from './glb.mjs';

const [src, dst] = process.argv.slice(2);
if (!src || !dst) throw new Error('usage: node camera.mjs SRC DST');
const toolDir = process.env.GLTF_TOOLS ?? '/tmp/gltftools';
const { NodeIO } = await load(toolDir, '@gltf-transform/core');
const io = new NodeIO();
const doc = await io.read(src);
const scene = doc.getRoot().getDefaultScene() ?? doc.getRoot().listScenes()[0];
const buffer = doc.getRoot().listBuffers()[0];
const camera = doc.createCamera('Cam').setType('perspective').setYFov(0.8).setZNear(0.1).setZFar(1000).setAspectRatio(4 / 3);
const rig = doc.createNode('Rig').setTranslation([0, 5, 0]);
const node = doc.createNode('CameraNode').setCamera(camera).setTranslation([0, 0, 20]);
rig.addChild(node);
scene.addChild(rig);
const acc = (type, values) => doc.createAccessor().setType(type).setArray(new Float32Array(values)).setBuffer(buffer);
const s = Math.sin(0.125), c = Math.cos(0.125);
const tSampler = doc.createAnimationSampler().setInput(acc('SCALAR', [0, 2, 4])).setOutput(acc('VEC3', [0, 0, 20, 30, 0, 40, 75, 0, 60])).setInterpolation('LINEAR');
const rSampler = doc.createAnimationSampler().setInput(acc('SCALAR', [0, 4])).setOutput(acc('VEC4', [0, 0, 0, 1, 0, s, 0, c])).setInterpolation('LINEAR');
doc.createAnimation('Fly')
	.addSampler(tSampler).addSampler(rSampler)
	.addChannel(doc.createAnimationChannel().setTargetNode(node).setTargetPath('translation').setSampler(tSampler))
	.addChannel(doc.createAnimationChannel().setTargetNode(node).setTargetPath('rotation').setSampler(rSampler));
await io.write(dst, doc);
console.log(`camera.mjs: ${dst}: camera node under a rig, 2 channels`);
