// lodbench tune: mesh_helmet_LP_13930damagedHelmet (distances from its bounding sphere's centre, model space [-0.0024815798, -0.18715495, -1.052022e-5]: place the LOD object there)
const lod = new THREE.LOD();
lod.addLevel(levels[0], 0);
lod.addLevel(levels[1], 19.160713);
lod.addLevel(levels[2], 22.293283);
lod.addLevel(levels[3], 37.874104);
