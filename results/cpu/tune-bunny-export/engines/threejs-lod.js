// lodbench tune: bunny_0_LOD0 (distances from its bounding sphere's centre, model space [-0.004812479, 4.8257995, 0.040401936]: place the LOD object there)
const lod = new THREE.LOD();
lod.addLevel(levels[0], 0);
lod.addLevel(levels[1], 42.395016);
lod.addLevel(levels[2], 73.8658);
lod.addLevel(levels[3], 89.82276);
