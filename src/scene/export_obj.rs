//! `lodbench export --out FILE.obj`: the geometry lodbench draws on one frame, every instance at LOD0 in world
//! space (deformed meshes posed, windmill blades turned), one OBJ group per instance with its normals. For a
//! glTF scene each group is named by the node it places (`node<N>`, `node<N>.<I>` for an EXT_mesh_gpu_instancing
//! instance), and the header says which nodes hold no instance and why, so that another decoder of the file can
//! be compared with what lodbench reads (`scripts/check_gltf.py`).

use crate::geometry::lod::LodChain;
use crate::geometry::mesh::AUX_BLADE;
use crate::scene::animated::Posed;
use crate::scene::def::SceneDef;
use crate::scene::model::{Motion, Scene};
use glam::{Mat3, Vec3};
use std::fmt::Write;

/// The OBJ text of `scene` (built from `def`) on `frame`.
pub fn obj(def: &SceneDef, scene: &Scene, frame: u32) -> String {
    let mut out = String::new();
    let user = def.user();
    let _ = writeln!(out, "# lodbench export: {}", def.mesh_source);
    let mut posed = Posed::default();
    match &scene.motion {
        Motion::Animated(a) => {
            let chains: Vec<&LodChain> = scene.models.iter().map(|m| &m.chain).collect();
            a.pose(
                &chains,
                frame,
                &|i| scene.instance_matrix(i, frame),
                &mut posed,
            );
            let _ = writeln!(
                out,
                "# frame {frame} animation {} time {}",
                a.clip.index,
                a.clip.time_of(frame)
            );
        }
        _ => {
            let _ = writeln!(out, "# frame {frame} animation none time 0");
        }
    }
    for (node, why) in user.map_or(&[][..], |u| &u.skipped[..]) {
        let _ = writeln!(out, "# skipped node {node}: {why}");
    }
    let mut base = 1usize;
    for (i, inst) in scene.instances.iter().enumerate() {
        if scene.ground == Some(i) {
            continue;
        }
        match user.and_then(|u| u.sources.get(i)) {
            Some(s) => {
                if !s.holds.is_empty() {
                    let held: Vec<String> = s.holds.iter().map(|n| n.to_string()).collect();
                    let _ = writeln!(out, "# node {} holds {}", s.node, held.join(" "));
                }
                let _ = match s.instance {
                    Some(k) => writeln!(out, "o node{}.{k}", s.node),
                    None => writeln!(out, "o node{}", s.node),
                };
            }
            None => {
                let _ = writeln!(out, "o instance{i}");
            }
        }
        let mesh = &scene.models[inst.model as usize].chain.lods[0].mesh;
        let (positions, normals) = match posed.of(inst.model, 0) {
            Some(p) => (&p.positions, &p.normals),
            None => (&mesh.positions, &mesh.normals),
        };
        let m = scene.instance_matrix(i, frame);
        let nm = Mat3::from_mat4(m).inverse().transpose();
        let angle = scene.animation_angle(i, frame);
        for (v, (p, n)) in positions.iter().zip(normals).enumerate() {
            let (mut p, mut n) = (Vec3::from(*p), Vec3::from(*n));
            if let Some(a) = mesh.aux.get(v).filter(|a| a[2] == AUX_BLADE) {
                // shaders/mesh.wgsl's blade turn about the axis parallel to +z through (0, hub_y).
                let (s, c) = angle.sin_cos();
                let (x, y) = (p.x, p.y - a[3]);
                p = Vec3::new(c * x - s * y, s * x + c * y + a[3], p.z);
                n = Vec3::new(c * n.x - s * n.y, s * n.x + c * n.y, n.z);
            }
            let w = m.transform_point3(p);
            let wn = (nm * n).try_normalize().unwrap_or(n);
            let _ = writeln!(out, "v {} {} {}", w.x, w.y, w.z);
            let _ = writeln!(out, "vn {} {} {}", wn.x, wn.y, wn.z);
        }
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|k| base + k as usize);
            let _ = writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}");
        }
        base += positions.len();
    }
    out
}
