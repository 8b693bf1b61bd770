// lodbench tune: switch distances for three.js (THREE.LOD), from each model's bounding-sphere centre.
// These switches keep each switch within a largest lodpop of 0.001229821341890719 at 1920x1080 pixels with a 60.0 degree vertical field of view; at another viewport or field of view the same switch pops differently: tune there.
// They hold for the LOD chain lodbench drew: a glTF file's authored chain (MSFT_lod), else the one lodbench generated with meshoptimizer, which tuned.glb holds. Use those levels, or a chain with these triangle counts:
//   bunny_0_LOD0: 3,674 -> 1,836 -> 918 -> 366 triangles
// Usage: const lod = lodbenchLod(THREE, "NAME", [level0, level1, ...]); scene.add(lod);
const lodbenchModels = {
  "bunny_0_LOD0": {
    "center": [
      -0.004812479019165039,
      4.825799465179443,
      0.04040193557739258
    ],
    "distances": [
      0.0,
      92.97603607177734,
      192.2974090576172,
      231.08990478515625
    ],
    "radius": 6.639063358306885,
    "triangles": [
      3674,
      1836,
      918,
      366
    ]
  }
}; // end of lodbenchModels

// A THREE.LOD of the model `name` from its levels (three.js objects, LOD0 first, in the model's own space):
// each level is put in a group moved by minus the model's bounding-sphere centre, so the LOD object stands at
// that centre and three.js measures its distances from where lodbench did. Place the returned object where the
// model's centre goes (the model's position plus its centre, scaled and turned as the model is).
function lodbenchLod(THREE, name, levels) {
  const model = lodbenchModels[name];
  if (!model) throw new Error(`lodbenchLod: no model ${name}: ${Object.keys(lodbenchModels).join(", ")}`);
  if (levels.length < model.distances.length) {
    throw new Error(`lodbenchLod: ${name} needs ${model.distances.length} levels, got ${levels.length}`);
  }
  const lod = new THREE.LOD();
  model.distances.forEach((distance, k) => {
    const group = new THREE.Group();
    group.position.set(-model.center[0], -model.center[1], -model.center[2]);
    group.add(levels[k]);
    lod.addLevel(group, distance);
  });
  return lod;
}

if (typeof module !== "undefined") module.exports = { lodbenchModels, lodbenchLod };
