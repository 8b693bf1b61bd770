// lodbench tune: switch distances for three.js (THREE.LOD), from each model's bounding-sphere centre.
// These switches keep each switch within a largest lodpop of 0.004 at 320x240 pixels with a 60.0 degree vertical field of view; at another viewport or field of view the same switch pops differently: tune there.
// They hold for the LOD chain lodbench drew: a glTF file's authored chain (MSFT_lod), else the one lodbench generated with meshoptimizer, which tuned.glb holds. Use those levels, or a chain with these triangle counts:
//   tree: 92,924 -> 39,984 -> 14,784 -> 4,836 -> 2 triangles
// Usage: const lod = lodbenchLod(THREE, "NAME", [level0, level1, ...]); scene.add(lod);
const lodbenchModels = {
  "tree": {
    "center": [
      0.12479114532470703,
      4.0,
      -0.06784069538116455
    ],
    "distances": [
      0.0,
      87.49988555908203,
      112.61890411376953,
      124.59800720214844,
      137.85130310058594
    ],
    "radius": 4.080379962921143,
    "triangles": [
      92924,
      39984,
      14784,
      4836,
      2
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
