//! `lodbench export`: a built-in scene as a glTF 2.0 binary (GLB), so that it opens in Blender or an engine and
//! so that the user-scene import (`user.rs`) is tested end to end.
//!
//! What the file holds, for the instance count exported:
//! - per model and LOD, a mesh (float positions and normals, 32-bit indices) with a material whose base colour is
//!   the LOD's colour, dielectric, fully rough and double-sided (the built-in scenes draw both faces); the per-vertex shading extras that the procedural models need (windmill blades, leaf
//!   cards) as the application-specific attribute `_LODBENCH_AUX` (glTF 2.0 section 3.7.2.1 allows attributes
//!   starting with `_`);
//! - per instance, a node placing the model's LOD0 at the instance's frame-0 transform, with MSFT_lod naming the
//!   coarser LODs' nodes (outside the scene, as the extension's example has them), `extras.MSFT_screencoverage`
//!   (lodbench's switch distances as screen sizes, `config::screen_size_distance`'s inverse, then 0) and lodbench's
//!   exact switch distances in `extras.lodbench_switch_distances` (which the import prefers), and the blades'
//!   turn per frame in `extras.lodbench_spin_per_frame`;
//! - the camera as a node with a perspective camera (the scene's vertical fov) and a LINEAR animation of its
//!   translation and rotation, one key per frame at 1/60 s apart. Where the instances move (bunny-sweep), the
//!   motion is given to the camera instead (the instances stay at their frame-0 place and the camera moves by the
//!   opposite): the same relative geometry, and the light is directional, so the same pictures.
//!
//! Not exported: the unified scenes (their blocks and seams have no glTF form), the ground of `--shadows on`.

use crate::error::{Error, Result};
use crate::geometry::material::{
    AlphaMode, Filter, Materials, TextureRef, Wrap, IDENTITY_TRANSFORM,
};
use crate::geometry::mesh::{Mesh, AUX_SOLID};
use crate::geometry::projection::screen_size;
use crate::scene::model::Scene;
use glam::Vec3;
use serde_json::{json, Value};

/// Seconds between the camera animation's keys.
pub const FRAME_SECONDS: f64 = 1.0 / 60.0;

/// The GLB of `scene` (one instance count of a built-in scene).
pub fn glb(scene: &Scene) -> Result<Vec<u8>> {
    glb_with(scene, true)
}

/// [`glb`], with the scene's camera path as a camera animation or (`camera` false: what `lodbench tune` writes)
/// without one, so that a run of the file flies its own default flight through the switches it holds.
pub fn glb_with(scene: &Scene, camera: bool) -> Result<Vec<u8>> {
    if scene.unified.is_some() {
        return Err(Error::Config(format!(
            "export: {} is a unified scene; its blocks and seams have no glTF form, so it is not exported",
            scene.name()
        )));
    }
    let card = |m: &&crate::scene::Model| crate::geometry::impostor::ends_in_card(&m.chain);
    if let Some(m) = scene.models.iter().find(card) {
        return Err(Error::Config(format!(
            "export: model {}'s chain ends in an impostor, which is baked when a scene is drawn and has no glTF \
             form; export without --impostor",
            m.name
        )));
    }
    let mut w = Writer::default();
    // A user scene's materials, with their images as PNG.
    let drawn = w.materials_of(&scene.materials)?;
    // Meshes and materials, per model and LOD.
    let lod_meshes = w.lod_meshes(scene, &drawn);
    // Instances: LOD0 in the scene, the coarser LODs outside it.
    let mut roots = Vec::new();
    for (i, inst) in scene.instances.iter().enumerate() {
        if scene.ground == Some(i) {
            continue;
        }
        let node = w.instance(scene, i, &lod_meshes[inst.model as usize]);
        roots.push(w.node(node));
    }
    if scene.models.iter().any(|m| m.chain.lods.len() > 1) {
        w.used.push("MSFT_lod");
    }
    if !camera {
        return Ok(w.finish(scene, roots));
    }
    let cam_node = w.camera_path(scene);
    roots.push(cam_node);
    Ok(w.finish(scene, roots))
}

/// A GLB being written: the JSON's arrays and the binary chunk.
#[derive(Default)]
struct Writer {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    nodes: Vec<Value>,
    cameras: Vec<Value>,
    animations: Vec<Value>,
    images: Vec<Value>,
    samplers: Vec<Value>,
    textures: Vec<Value>,
    used: Vec<&'static str>,
}

impl Writer {
    /// A buffer view of `bytes` (4-byte aligned) and its index.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    /// A float accessor of `values` (`kind` VEC3, VEC4, SCALAR) with min/max, and its index.
    fn floats(&mut self, values: &[f32], kind: &str, target: Option<u32>) -> usize {
        let n = match kind {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            _ => 4,
        };
        let view = self.view(bytemuck::cast_slice(values), target);
        let mut min = vec![f32::INFINITY; n];
        let mut max = vec![f32::NEG_INFINITY; n];
        for v in values.chunks_exact(n) {
            for c in 0..n {
                min[c] = min[c].min(v[c]);
                max[c] = max[c].max(v[c]);
            }
        }
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5126, "count": values.len() / n, "type": kind,
            "min": min, "max": max,
        }));
        self.accessors.len() - 1
    }

    fn material(&mut self, color: [f32; 3]) -> usize {
        let m = json!({"pbrMetallicRoughness": {
            "baseColorFactor": [color[0], color[1], color[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0
        }, "doubleSided": true});
        match self.materials.iter().position(|x| *x == m) {
            Some(i) => i,
            None => {
                self.materials.push(m);
                self.materials.len() - 1
            }
        }
    }

    /// A mesh of one primitive per material part (`materials[part]` its glTF material), or of one primitive in
    /// the flat `material` when it has no parts; its texture coordinates, tangents and colours where it has them.
    fn mesh(&mut self, name: &str, mesh: &Mesh, material: usize, materials: &[usize]) -> usize {
        let positions: Vec<f32> = mesh.positions.iter().flatten().copied().collect();
        let normals: Vec<f32> = mesh.normals.iter().flatten().copied().collect();
        let position = self.floats(&positions, "VEC3", Some(34962));
        let normal = self.floats(&normals, "VEC3", Some(34962));
        let mut attributes = json!({"POSITION": position, "NORMAL": normal});
        if mesh.aux.iter().any(|a| a[2] != AUX_SOLID) {
            let aux: Vec<f32> = mesh.aux.iter().flatten().copied().collect();
            attributes["_LODBENCH_AUX"] = json!(self.floats(&aux, "VEC4", Some(34962)));
        }
        if !mesh.parts.is_empty() && !materials.is_empty() {
            let d = &mesh.data;
            for (key, uv) in [("TEXCOORD_0", &d.uv0), ("TEXCOORD_1", &d.uv1)] {
                if let Some(uv) = uv {
                    let flat: Vec<f32> = uv.iter().flatten().copied().collect();
                    attributes[key] = json!(self.floats(&flat, "VEC2", Some(34962)));
                }
            }
            for (key, v) in [("TANGENT", &d.tangents), ("COLOR_0", &d.colors)] {
                if let Some(v) = v {
                    let flat: Vec<f32> = v.iter().flatten().copied().collect();
                    attributes[key] = json!(self.floats(&flat, "VEC4", Some(34962)));
                }
            }
        }
        let runs: Vec<(usize, &[u32])> = match (mesh.parts.is_empty(), materials.is_empty()) {
            (false, false) => mesh
                .parts
                .iter()
                .map(|p| {
                    let a = p.first_index as usize;
                    (
                        materials[p.material as usize],
                        &mesh.indices[a..a + p.index_count as usize],
                    )
                })
                .collect(),
            _ => vec![(material, &mesh.indices[..])],
        };
        let mut primitives = Vec::with_capacity(runs.len());
        for (material, indices) in runs {
            let view = self.view(bytemuck::cast_slice(indices), Some(34963));
            self.accessors.push(json!({
                "bufferView": view, "componentType": 5125, "count": indices.len(), "type": "SCALAR",
            }));
            primitives.push(json!({
                "attributes": attributes, "indices": self.accessors.len() - 1, "material": material, "mode": 4
            }));
        }
        self.meshes
            .push(json!({"name": name, "primitives": primitives}));
        self.meshes.len() - 1
    }

    /// A user scene's materials (none for a built-in scene): their images as PNG, samplers, textures; the glTF
    /// index of each.
    fn materials_of(&mut self, materials: &Materials) -> Result<Vec<usize>> {
        let mut images = Vec::with_capacity(materials.images.len());
        for img in &materials.images {
            if img.rgba.len() != img.width as usize * img.height as usize * 4 {
                return Err(Error::Config(format!(
                    "export: {} is not whole RGBA",
                    img.name
                )));
            }
            // The bytes the image was read from where glTF's core reads them, else PNG.
            let (view, mime) = match &img.encoded {
                Some((bytes, mime)) => (self.view(bytes, None), *mime),
                None => {
                    let png = crate::raster::png_bytes(img.width, img.height, &img.rgba).map_err(
                        |e| Error::Config(format!("export: {} cannot be encoded: {e}", img.name)),
                    )?;
                    (self.view(&png, None), "image/png")
                }
            };
            self.images
                .push(json!({"bufferView": view, "mimeType": mime, "name": img.name}));
            images.push(self.images.len() - 1);
        }
        let mut out = Vec::with_capacity(materials.materials.len());
        for m in &materials.materials {
            let mut pbr = json!({
                "baseColorFactor": m.base_color, "metallicFactor": m.metallic, "roughnessFactor": m.roughness,
            });
            let mut doc = json!({"name": m.name, "doubleSided": m.double_sided});
            if let Some(t) = &m.base_color_texture {
                pbr["baseColorTexture"] = self.texture_info(t, &images);
            }
            if let Some(t) = &m.metallic_roughness_texture {
                pbr["metallicRoughnessTexture"] = self.texture_info(t, &images);
            }
            doc["pbrMetallicRoughness"] = pbr;
            if let Some(t) = &m.normal_texture {
                doc["normalTexture"] = self.texture_info(t, &images);
                doc["normalTexture"]["scale"] = json!(m.normal_scale);
            }
            if let Some(t) = &m.occlusion_texture {
                doc["occlusionTexture"] = self.texture_info(t, &images);
                doc["occlusionTexture"]["strength"] = json!(m.occlusion_strength);
            }
            if let Some(t) = &m.emissive_texture {
                doc["emissiveTexture"] = self.texture_info(t, &images);
            }
            let strength = m.emissive.iter().copied().fold(1.0f32, f32::max);
            doc["emissiveFactor"] = json!(m.emissive.map(|e| e / strength));
            let mut extensions = serde_json::Map::new();
            if strength > 1.0 {
                extensions.insert(
                    "KHR_materials_emissive_strength".into(),
                    json!({"emissiveStrength": strength}),
                );
                self.use_extension("KHR_materials_emissive_strength");
            }
            if m.unlit {
                extensions.insert("KHR_materials_unlit".into(), json!({}));
                self.use_extension("KHR_materials_unlit");
            }
            if !extensions.is_empty() {
                doc["extensions"] = Value::Object(extensions);
            }
            match m.alpha {
                AlphaMode::Opaque => {}
                AlphaMode::Mask(c) => {
                    doc["alphaMode"] = json!("MASK");
                    doc["alphaCutoff"] = json!(c);
                }
                AlphaMode::Blend => doc["alphaMode"] = json!("BLEND"),
            }
            self.materials.push(doc);
            out.push(self.materials.len() - 1);
        }
        Ok(out)
    }

    /// A textureInfo of `t`: its texture (image and sampler), texture coordinates and transform.
    fn texture_info(&mut self, t: &TextureRef, images: &[usize]) -> Value {
        let wrap = |w: Wrap| match w {
            Wrap::Repeat => 10497,
            Wrap::MirroredRepeat => 33648,
            Wrap::ClampToEdge => 33071,
        };
        let s = t.sampler;
        let min = match (s.min, s.mipmap) {
            (Filter::Nearest, None) => 9728,
            (Filter::Linear, None) => 9729,
            (Filter::Nearest, Some(Filter::Nearest)) => 9984,
            (Filter::Linear, Some(Filter::Nearest)) => 9985,
            (Filter::Nearest, Some(Filter::Linear)) => 9986,
            (Filter::Linear, Some(Filter::Linear)) => 9987,
        };
        let sampler = json!({
            "magFilter": if s.mag == Filter::Nearest { 9728 } else { 9729 },
            "minFilter": min, "wrapS": wrap(s.wrap_s), "wrapT": wrap(s.wrap_t),
        });
        let sampler = match self.samplers.iter().position(|x| *x == sampler) {
            Some(i) => i,
            None => {
                self.samplers.push(sampler);
                self.samplers.len() - 1
            }
        };
        let texture = json!({"source": images[t.image as usize], "sampler": sampler});
        let texture = match self.textures.iter().position(|x| *x == texture) {
            Some(i) => i,
            None => {
                self.textures.push(texture);
                self.textures.len() - 1
            }
        };
        let mut info = json!({"index": texture, "texCoord": t.texcoord});
        if t.transform != IDENTITY_TRANSFORM {
            // rows [c sx, s sy, ox] and [-s sx, c sy, oy] (TextureRef::transform_of)
            let [a, b] = t.transform;
            let sx = a[0].hypot(b[0]);
            let sy = a[1].hypot(b[1]);
            let rotation = (-b[0] / sx).atan2(a[0] / sx);
            info["extensions"] = json!({"KHR_texture_transform": {
                "offset": [a[2], b[2]], "rotation": rotation, "scale": [sx, sy],
            }});
            self.use_extension("KHR_texture_transform");
        }
        info
    }

    fn use_extension(&mut self, name: &'static str) {
        if !self.used.contains(&name) {
            self.used.push(name);
        }
    }

    /// Every model's LOD meshes (each with its LOD's material): `[model][lod]`.
    fn lod_meshes(&mut self, scene: &Scene, drawn: &[usize]) -> Vec<Vec<usize>> {
        let mut lod_meshes: Vec<Vec<usize>> = Vec::new();
        for m in scene.models.iter() {
            let mut ids = Vec::new();
            for (l, lod) in m.chain.lods.iter().enumerate() {
                let material = self.material(m.color_of(l as u32));
                ids.push(self.mesh(&format!("{}_LOD{l}", m.name), &lod.mesh, material, drawn));
            }
            lod_meshes.push(ids);
        }
        lod_meshes
    }

    /// Instance `i`'s LOD0 node at its frame-0 placement (not yet added), its model's coarser LODs (`ids[1..]`)
    /// added as nodes outside the scene and named by MSFT_lod, with their screen coverages and switch distances.
    fn instance(&mut self, scene: &Scene, i: usize, ids: &[usize]) -> Value {
        let inst = &scene.instances[i];
        let m = &scene.models[inst.model as usize];
        let (s, r, t) = scene.instance_matrix(i, 0).to_scale_rotation_translation();
        let place = |mesh: usize, name: String| {
            json!({
                "name": name,
                "mesh": mesh,
                "translation": t.to_array(),
                "rotation": r.to_array(),
                "scale": s.to_array(),
            })
        };
        let coarser: Vec<usize> = ids[1..]
            .iter()
            .enumerate()
            .map(|(l, &mesh)| self.node(place(mesh, format!("{}_{i}_LOD{}", m.name, l + 1))))
            .collect();
        let mut node = place(ids[0], format!("{}_{i}_LOD0", m.name));
        if !coarser.is_empty() {
            let mut coverage: Vec<f64> = m
                .switches
                .iter()
                .map(|&d| f64::from(screen_size(m.radius, d, scene.fov_y)))
                .collect();
            coverage.push(0.0);
            node["extensions"] = json!({"MSFT_lod": {"ids": coarser}});
            node["extras"] = json!({
                "MSFT_screencoverage": coverage,
                // The instance's own: its model's times its size, where lodbench selects its LODs.
                "lodbench_switch_distances": m.switches.iter().map(|d| d * inst.size()).collect::<Vec<_>>(),
            });
        }
        if m.spin_per_frame != 0.0 {
            let extras = node
                .as_object_mut()
                .map(|o| o.entry("extras").or_insert_with(|| json!({})));
            if let Some(e) = extras {
                e["lodbench_spin_per_frame"] = json!(m.spin_per_frame);
            }
        }
        node
    }

    /// The camera node, with the scene's camera path as its animation (one key per frame); returns the node.
    fn camera_path(&mut self, scene: &Scene) -> usize {
        // The instances' motion given to the camera.
        let frames = scene.frames.max(2);
        let mut times = Vec::new();
        let mut eyes = Vec::new();
        let mut rotations = Vec::new();
        // Every moving instance moves alike (bunny-sweep's one bunny, `Motion::SweepX`); the ground comes last.
        // A user scene's animation is not exported: its instances stand where frame 0 has them.
        let moving = matches!(scene.motion, crate::scene::model::Motion::SweepX { .. })
            && !scene.instances.is_empty()
            && scene.ground != Some(0);
        for f in 0..frames {
            let c = scene.camera(f.min(scene.frames - 1));
            let shift = match moving {
                true => scene.instance_position(0, f) - scene.instance_position(0, 0),
                false => Vec3::ZERO,
            };
            let (_, rot, eye) = c.view.inverse().to_scale_rotation_translation();
            times.push(f as f32 * FRAME_SECONDS as f32);
            eyes.extend((eye - shift).to_array());
            rotations.extend(rot.normalize().to_array());
        }
        let camera = self.camera(
            scene.fov_y,
            scene.near,
            scene.far,
            scene.width,
            scene.height,
        );
        let cam_node = self.node(json!({"name": "lodbench_camera", "camera": camera}));
        let input = self.floats(&times, "SCALAR", None);
        let t_out = self.floats(&eyes, "VEC3", None);
        let r_out = self.floats(&rotations, "VEC4", None);
        self.animations.push(json!({
            "name": "lodbench camera path",
            "samplers": [
                {"input": input, "output": t_out, "interpolation": "LINEAR"},
                {"input": input, "output": r_out, "interpolation": "LINEAR"},
            ],
            "channels": [
                {"sampler": 0, "target": {"node": cam_node, "path": "translation"}},
                {"sampler": 1, "target": {"node": cam_node, "path": "rotation"}},
            ],
        }));
        cam_node
    }

    fn node(&mut self, node: Value) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    fn camera(&mut self, fov_y: f32, near: f32, far: f32, width: u32, height: u32) -> usize {
        self.cameras.push(json!({"type": "perspective", "perspective": {
            "yfov": fov_y, "znear": near, "zfar": far, "aspectRatio": width as f32 / height as f32
        }}));
        self.cameras.len() - 1
    }

    fn finish(mut self, scene: &Scene, roots: Vec<usize>) -> Vec<u8> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": format!("lodbench {} export", env!("CARGO_PKG_VERSION"))},
            "scene": 0,
            "scenes": [{"name": scene.name(), "nodes": roots}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "cameras": self.cameras,
            "animations": self.animations,
            "images": self.images,
            "samplers": self.samplers,
            "textures": self.textures,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{"byteLength": self.bin.len()}],
            "extras": {"lodbench_scene": scene.name(), "lodbench_frames": scene.frames},
        });
        if !self.used.is_empty() {
            doc["extensionsUsed"] = json!(self.used);
        }
        let mut text = doc.to_string().into_bytes();
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let total = 12 + 8 + text.len() + 8 + self.bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend(b"glTF");
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((text.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(text);
        out.extend((self.bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(self.bin);
        out
    }
}
