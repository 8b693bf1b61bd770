// lodbench's frame in three.js, shared by render.html (scripts/three_fidelity.py) and lod.html (scripts/three_lod.py):
// the renderer stores pixels as lodbench does (no antialiasing, pixel ratio 1, sRGB output, no tone mapping, the
// drawing buffer kept for read-back), and the scene is lit as lodbench lights it: its directional light
// (irradiance pi x (1 - ambient) at normal incidence), its ambient as a uniform environment of radiance `ambient`
// (three.js's image-based lighting of a constant environment map) and its clear colour. `job` holds width,
// height, background (linear RGB), light_direction and ambient.
import * as THREE from 'three';

export function lodbenchRenderer(job) {
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(job.width, job.height, false);
  renderer.outputColorSpace = THREE.SRGBColorSpace;
  renderer.toneMapping = THREE.NoToneMapping;
  document.body.appendChild(renderer.domElement);
  return renderer;
}

export function lodbenchScene(renderer, job) {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color().setRGB(...job.background, THREE.LinearSRGBColorSpace);
  const light = new THREE.DirectionalLight(0xffffff, Math.PI * (1 - job.ambient));
  light.position.set(...job.light_direction);
  scene.add(light, light.target);
  const a = job.ambient;
  const constant = new THREE.DataTexture(new Float32Array([a, a, a, 1, a, a, a, 1]), 2, 1, THREE.RGBAFormat,
                                         THREE.FloatType);
  constant.mapping = THREE.EquirectangularReflectionMapping;
  constant.colorSpace = THREE.LinearSRGBColorSpace;
  constant.needsUpdate = true;
  scene.environment = new THREE.PMREMGenerator(renderer).fromEquirectangular(constant).texture;
  return scene;
}
