// lodbench tune: bunny (distances from its bounding sphere's centre, model space [-0.0168405, 0.110154, -0.0015369989]: place the LOD object there)
const lod = new THREE.LOD();
lod.addLevel(levels[0], 0);
lod.addLevel(levels[1], 0.7037303);
lod.addLevel(levels[2], 0.86117095);
lod.addLevel(levels[3], 1.0019629);
