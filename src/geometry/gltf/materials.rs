//! Materials, textures, samplers and images (glTF 2.0 sections 3.8 and 3.9): the core metallic-roughness
//! model, KHR_texture_transform, KHR_materials_emissive_strength and KHR_materials_unlit, images in PNG, JPEG and
//! WebP (EXT_texture_webp). A texture whose only image is one lodbench does not decode (KTX2 / Basis Universal,
//! AVIF) refuses the file with the command that converts it; a material extension that changes the look but is
//! not drawn is named in a note (the material is drawn as its core metallic-roughness fallback, as the
//! extension's specification allows a viewer that does not support it).

use super::accessors::Doc;
use super::container::read_uri;
use super::json::{array, floats, index, number_or, opt_index, uint_or};
use crate::geometry::material::{
    AlphaMode, Filter, Image, Material, Materials, Sampler, TextureRef, Wrap, IDENTITY_TRANSFORM,
};
use crate::raster::{format_of, Format, RgbaImage};
use serde_json::Value;
use std::collections::HashMap;

/// Material extensions drawn: texture transforms, emissive strength and unlit.
const DRAWN: [&str; 4] = [
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
    "KHR_materials_unlit",
    "EXT_texture_webp",
];

/// What to do with a file whose textures lodbench cannot decode.
const KTX2_REMEDY: &str = "lodbench decodes PNG, JPEG and WebP: rewrite the textures with `npx @gltf-transform/cli \
     ktxdecompress IN.glb OUT.glb` (it needs KTX-Software's `ktx` on the PATH), or draw the file without its \
     materials with --materials flat";
const AVIF_REMEDY: &str =
    "lodbench decodes PNG, JPEG and WebP: rewrite the textures with `npx @gltf-transform/cli \
     png IN.glb OUT.glb`, or draw the file without its materials with --materials flat";

/// The materials a scene draws, read as its primitives name them: glTF material indices (None: the default
/// material) map to lodbench's, and each image is decoded once.
#[derive(Debug, Default)]
pub struct MaterialTable {
    pub materials: Materials,
    by_gltf: HashMap<Option<usize>, u32>,
    images: HashMap<usize, u32>,
    /// What is not drawn as the file says (a material extension lodbench does not draw), one line each.
    pub notes: Vec<String>,
}

impl MaterialTable {
    /// The lodbench material of glTF material `gltf` (None: the default material), if read already.
    pub fn get(&self, gltf: Option<usize>) -> Option<u32> {
        self.by_gltf.get(&gltf).copied()
    }
}

fn material_name(json: &Value, i: usize) -> String {
    match json["materials"][i]["name"].as_str() {
        Some(n) if !n.is_empty() => format!("material {i} ('{n}')"),
        _ => format!("material {i}"),
    }
}

fn wrap(v: &Value, what: &str) -> Result<Wrap, String> {
    match uint_or(v, 10497, || what.to_string())? {
        10497 => Ok(Wrap::Repeat),
        33648 => Ok(Wrap::MirroredRepeat),
        33071 => Ok(Wrap::ClampToEdge),
        other => Err(format!("{what} is {other}, which glTF does not define")),
    }
}

/// A sampler (glTF 2.0 section 3.8.3); undefined filters are the implementation's choice: trilinear.
fn sampler(json: &Value, i: usize) -> Result<Sampler, String> {
    let s = &json["samplers"][i];
    let what = |p: &str| format!("sampler {i}'s {p}");
    let mut out = Sampler {
        wrap_s: wrap(&s["wrapS"], &what("wrapS"))?,
        wrap_t: wrap(&s["wrapT"], &what("wrapT"))?,
        ..Sampler::default()
    };
    match super::json::opt_uint(&s["magFilter"], || what("magFilter"))? {
        None | Some(9729) => out.mag = Filter::Linear,
        Some(9728) => out.mag = Filter::Nearest,
        Some(other) => {
            return Err(format!(
                "{} is {other}, which glTF does not define",
                what("magFilter")
            ))
        }
    }
    let (min, mipmap) = match super::json::opt_uint(&s["minFilter"], || what("minFilter"))? {
        None | Some(9987) => (Filter::Linear, Some(Filter::Linear)),
        Some(9728) => (Filter::Nearest, None),
        Some(9729) => (Filter::Linear, None),
        Some(9984) => (Filter::Nearest, Some(Filter::Nearest)),
        Some(9985) => (Filter::Linear, Some(Filter::Nearest)),
        Some(9986) => (Filter::Nearest, Some(Filter::Linear)),
        Some(other) => {
            return Err(format!(
                "{} is {other}, which glTF does not define",
                what("minFilter")
            ))
        }
    };
    out.min = min;
    out.mipmap = mipmap;
    Ok(out)
}

impl Doc<'_> {
    /// The lodbench index of glTF material `gltf` (None: glTF's default material), reading it and its images
    /// the first time.
    pub fn material(
        &mut self,
        table: &mut MaterialTable,
        gltf: Option<usize>,
    ) -> Result<u32, String> {
        if let Some(i) = table.get(gltf) {
            return Ok(i);
        }
        let material = match gltf {
            None => Material {
                name: "default".into(),
                ..Material::default()
            },
            Some(i) => self.read_material(table, i)?,
        };
        let index = table.materials.materials.len() as u32;
        table.materials.materials.push(material);
        table.by_gltf.insert(gltf, index);
        Ok(index)
    }

    fn read_material(&mut self, table: &mut MaterialTable, i: usize) -> Result<Material, String> {
        let m = array(&self.json, "materials")
            .get(i)
            .cloned()
            .ok_or_else(|| format!("material {i} does not exist"))?;
        let what = material_name(&self.json, i);
        let pbr = &m["pbrMetallicRoughness"];
        let base_color = floats::<4>(
            &pbr["baseColorFactor"],
            &format!("{what}'s baseColorFactor"),
        )?
        .unwrap_or([1.0; 4]);
        let mut out = Material {
            name: m["name"].as_str().unwrap_or("").to_string(),
            base_color,
            base_color_texture: self.texture_info(
                table,
                &pbr["baseColorTexture"],
                &format!("{what}'s baseColorTexture"),
            )?,
            metallic: number_or(&pbr["metallicFactor"], 1.0, || {
                format!("{what}'s metallicFactor")
            })?,
            roughness: number_or(&pbr["roughnessFactor"], 1.0, || {
                format!("{what}'s roughnessFactor")
            })?,
            metallic_roughness_texture: self.texture_info(
                table,
                &pbr["metallicRoughnessTexture"],
                &format!("{what}'s metallicRoughnessTexture"),
            )?,
            normal_texture: self.texture_info(
                table,
                &m["normalTexture"],
                &format!("{what}'s normalTexture"),
            )?,
            normal_scale: number_or(&m["normalTexture"]["scale"], 1.0, || {
                format!("{what}'s normalTexture.scale")
            })?,
            occlusion_texture: self.texture_info(
                table,
                &m["occlusionTexture"],
                &format!("{what}'s occlusionTexture"),
            )?,
            occlusion_strength: number_or(&m["occlusionTexture"]["strength"], 1.0, || {
                format!("{what}'s occlusionTexture.strength")
            })?,
            emissive: floats::<3>(&m["emissiveFactor"], &format!("{what}'s emissiveFactor"))?
                .unwrap_or([0.0; 3]),
            emissive_texture: self.texture_info(
                table,
                &m["emissiveTexture"],
                &format!("{what}'s emissiveTexture"),
            )?,
            alpha: match m["alphaMode"].as_str() {
                None | Some("OPAQUE") => AlphaMode::Opaque,
                Some("MASK") => AlphaMode::Mask(number_or(&m["alphaCutoff"], 0.5, || {
                    format!("{what}'s alphaCutoff")
                })?),
                Some("BLEND") => AlphaMode::Blend,
                Some(other) => {
                    return Err(format!(
                        "{what} has alphaMode '{other}', which glTF does not define (OPAQUE, MASK, BLEND)"
                    ))
                }
            },
            double_sided: m["doubleSided"].as_bool().unwrap_or(false),
            unlit: m.pointer("/extensions/KHR_materials_unlit").is_some(),
        };
        out.metallic = out.metallic.clamp(0.0, 1.0);
        out.roughness = out.roughness.clamp(0.0, 1.0);
        if let Some(s) = m.pointer("/extensions/KHR_materials_emissive_strength/emissiveStrength") {
            let s = number_or(s, 1.0, || format!("{what}'s emissiveStrength"))?;
            out.emissive = out.emissive.map(|e| e * s);
        }
        if let Some(ext) = m["extensions"].as_object() {
            let undrawn: Vec<&str> = ext
                .keys()
                .map(String::as_str)
                .filter(|k| !DRAWN.contains(k))
                .collect();
            if !undrawn.is_empty() {
                let remedy = if undrawn.contains(&"KHR_materials_pbrSpecularGlossiness") {
                    " (convert it with `npx @gltf-transform/cli metalrough IN.glb OUT.glb`)"
                } else {
                    ""
                };
                table.notes.push(format!(
                    "{what} uses {}, which lodbench does not draw: drawn as its core metallic-roughness \
                     material{remedy}",
                    undrawn.join(", ")
                ));
            }
        }
        Ok(out)
    }

    /// A textureInfo (glTF 2.0 section 5.29): its texture's image and sampler, its texture coordinates and
    /// their KHR_texture_transform; None when absent.
    fn texture_info(
        &mut self,
        table: &mut MaterialTable,
        info: &Value,
        what: &str,
    ) -> Result<Option<TextureRef>, String> {
        if info.is_null() {
            return Ok(None);
        }
        let textures = array(&self.json, "textures").len();
        let t = index(&info["index"], || format!("{what}'s index"), textures)?;
        let mut texcoord = uint_or(&info["texCoord"], 0, || format!("{what}'s texCoord"))?;
        let mut transform = IDENTITY_TRANSFORM;
        if let Some(x) = info.pointer("/extensions/KHR_texture_transform") {
            let offset =
                floats::<2>(&x["offset"], &format!("{what}'s offset"))?.unwrap_or([0.0; 2]);
            let rotation = number_or(&x["rotation"], 0.0, || format!("{what}'s rotation"))?;
            let scale = floats::<2>(&x["scale"], &format!("{what}'s scale"))?.unwrap_or([1.0; 2]);
            transform = TextureRef::transform_of(offset, rotation, scale);
            texcoord = uint_or(&x["texCoord"], texcoord, || {
                format!("{what}'s KHR_texture_transform texCoord")
            })?;
        }
        if texcoord > 1 {
            return Err(format!(
                "{what} samples TEXCOORD_{texcoord}; lodbench reads TEXCOORD_0 and TEXCOORD_1: move the texture \
                 to one of those in the tool that wrote the file"
            ));
        }
        let texture = self.json["textures"][t].clone();
        let samplers = array(&self.json, "samplers").len();
        let sampler = match opt_index(
            &texture["sampler"],
            || format!("texture {t}'s sampler"),
            samplers,
        )? {
            Some(s) => sampler(&self.json, s)?,
            None => Sampler::default(),
        };
        let images = array(&self.json, "images").len();
        let image_of =
            |v: &Value, key: &str| opt_index(v, || format!("texture {t}'s {key}"), images);
        let webp = image_of(
            texture
                .pointer("/extensions/EXT_texture_webp/source")
                .unwrap_or(&Value::Null),
            "EXT_texture_webp source",
        )?;
        let source = image_of(&texture["source"], "source")?;
        let image = match (webp, source) {
            (Some(i), _) | (None, Some(i)) => i,
            (None, None) => {
                let (ext, remedy) = if texture.pointer("/extensions/KHR_texture_basisu").is_some() {
                    ("KHR_texture_basisu (KTX2 / Basis Universal)", KTX2_REMEDY)
                } else if texture.pointer("/extensions/EXT_texture_avif").is_some() {
                    ("EXT_texture_avif", AVIF_REMEDY)
                } else {
                    ("no image at all", AVIF_REMEDY)
                };
                return Err(format!(
                    "{what}: texture {t} has {ext} and no PNG or JPEG fallback; {remedy}"
                ));
            }
        };
        Ok(Some(TextureRef {
            image: self.image(table, image)?,
            sampler,
            texcoord: texcoord as u8,
            transform,
        }))
    }

    /// glTF image `i` decoded (once) into the table.
    fn image(&mut self, table: &mut MaterialTable, i: usize) -> Result<u32, String> {
        if let Some(&k) = table.images.get(&i) {
            return Ok(k);
        }
        let desc = self.json["images"][i].clone();
        let what = match desc["name"].as_str().or(desc["uri"].as_str()) {
            Some(n) if !n.starts_with("data:") => format!("image {i} ('{n}')"),
            _ => format!("image {i}"),
        };
        let views = array(&self.json, "bufferViews").len();
        let bytes = match (
            desc["uri"].as_str(),
            opt_index(
                &desc["bufferView"],
                || format!("{what}'s bufferView"),
                views,
            )?,
        ) {
            (Some(uri), _) => read_uri(&what, uri, self.dir()).map_err(|e| {
                format!(
                    "{e}: put the image beside the file, or draw the file without its materials with \
                     --materials flat"
                )
            })?,
            (None, Some(v)) => self.view_bytes(v, &what)?,
            (None, None) => return Err(format!("{what} has neither a uri nor a bufferView")),
        };
        let decoded = decode_image(&bytes, desc["mimeType"].as_str())
            .map_err(|e| format!("{what} cannot be decoded: {e}"))?;
        let (width, height) = decoded.dimensions();
        let mime = match format_of(&bytes) {
            Some(Format::Png) => Some("image/png"),
            Some(Format::Jpeg) => Some("image/jpeg"),
            _ => None,
        };
        let k = table.materials.images.len() as u32;
        table.materials.images.push(Image {
            name: what,
            width,
            height,
            rgba: decoded.into_raw(),
            encoded: mime.map(|m| (bytes, m)),
        });
        table.images.insert(i, k);
        Ok(k)
    }
}

/// PNG, JPEG or WebP bytes as RGBA8 (16-bit and grey images converted); the format from the bytes themselves
/// (a file's mimeType may be wrong), KTX2 and AVIF refused with the command that converts them.
fn decode_image(bytes: &[u8], mime: Option<&str>) -> Result<RgbaImage, String> {
    let format = format_of(bytes);
    if format == Some(Format::Other("KTX2")) || mime == Some("image/ktx2") {
        return Err(format!("it is KTX2 (Basis Universal); {KTX2_REMEDY}"));
    }
    match format {
        Some(Format::Png | Format::Jpeg | Format::WebP) => crate::raster::decode(bytes),
        Some(Format::Other("AVIF")) => Err(format!("it is AVIF; {AVIF_REMEDY}")),
        Some(Format::Other(name)) => Err(format!(
            "it is {name}, not PNG, JPEG or WebP as glTF allows; {AVIF_REMEDY}"
        )),
        None => Err(format!(
            "its format is none lodbench knows, not PNG, JPEG or WebP (mimeType {mime:?})"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(w: u32, h: u32, px: [u8; 4]) -> Vec<u8> {
        crate::raster::png_bytes(w, h, &px.repeat((w * h) as usize)).unwrap()
    }

    fn doc_with(json: serde_json::Value) -> (serde_json::Value, std::path::PathBuf) {
        (json, std::env::temp_dir())
    }

    /// A material's factors, textures, sampler, transform and alpha mode are read as written; an image is
    /// decoded once however many textures use it.
    #[test]
    fn materials_are_read_as_written() {
        let b64 = {
            use base64::Engine;
            base64::engine::general_purpose::STANDARD.encode(png(2, 1, [255, 0, 0, 128]))
        };
        let (json, dir) = doc_with(serde_json::json!({
            "asset": {"version": "2.0"},
            "images": [{"uri": format!("data:image/png;base64,{b64}")}],
            "samplers": [{"magFilter": 9728, "minFilter": 9729, "wrapS": 33071, "wrapT": 33648}],
            "textures": [{"source": 0, "sampler": 0}, {"source": 0}],
            "materials": [{
                "name": "leaf",
                "pbrMetallicRoughness": {
                    "baseColorFactor": [0.5, 0.5, 0.5, 1.0],
                    "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform":
                        {"offset": [0.5, 0.0], "scale": [2.0, 2.0], "texCoord": 1}}},
                    "metallicFactor": 0.0
                },
                "normalTexture": {"index": 1, "scale": 0.5},
                "emissiveFactor": [1.0, 0.5, 0.0],
                "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 2.0},
                               "KHR_materials_sheen": {}},
                "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": true
            }]
        }));
        let mut doc = Doc::new(json, None, &dir);
        let mut table = MaterialTable::default();
        let m = doc.material(&mut table, Some(0)).unwrap();
        assert_eq!(doc.material(&mut table, Some(0)).unwrap(), m);
        let d = doc.material(&mut table, None).unwrap();
        assert_ne!(d, m);
        let mats = &table.materials;
        assert_eq!(mats.images.len(), 1);
        assert_eq!((mats.images[0].width, mats.images[0].height), (2, 1));
        assert_eq!(&mats.images[0].rgba[..4], &[255, 0, 0, 128]);
        let leaf = &mats.materials[m as usize];
        assert_eq!(leaf.name, "leaf");
        assert_eq!(leaf.base_color, [0.5, 0.5, 0.5, 1.0]);
        assert_eq!((leaf.metallic, leaf.roughness), (0.0, 1.0));
        assert_eq!(leaf.alpha, AlphaMode::Mask(0.3));
        assert!(leaf.double_sided);
        assert_eq!(leaf.emissive, [2.0, 1.0, 0.0]);
        assert_eq!(leaf.normal_scale, 0.5);
        let base = leaf.base_color_texture.as_ref().unwrap();
        assert_eq!(base.texcoord, 1);
        assert_eq!(base.apply([0.25, 0.25]), [1.0, 0.5]);
        assert_eq!(base.sampler.mag, Filter::Nearest);
        assert_eq!(base.sampler.mipmap, None);
        assert_eq!(
            (base.sampler.wrap_s, base.sampler.wrap_t),
            (Wrap::ClampToEdge, Wrap::MirroredRepeat)
        );
        let normal = leaf.normal_texture.as_ref().unwrap();
        assert_eq!(normal.sampler, Sampler::default());
        assert_eq!(normal.image, base.image);
        assert_eq!(table.notes.len(), 1);
        assert!(
            table.notes[0].contains("KHR_materials_sheen"),
            "{}",
            table.notes[0]
        );
        let default = &mats.materials[d as usize];
        assert_eq!((default.metallic, default.roughness), (1.0, 1.0));
        assert!(!default.double_sided);
    }

    /// A texture with only a KTX2 image refuses the file with the command that converts it; an image that does
    /// not decode names itself.
    #[test]
    fn undecodable_textures_are_refused_with_a_remedy() {
        let (json, dir) = doc_with(serde_json::json!({
            "asset": {"version": "2.0"},
            "images": [{"uri": "data:image/png;base64,AAAA", "name": "broken"}],
            "textures": [{"extensions": {"KHR_texture_basisu": {"source": 0}}}, {"source": 0}],
            "materials": [
                {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
                {"emissiveTexture": {"index": 1}},
                {"occlusionTexture": {"index": 1, "texCoord": 2}}
            ]
        }));
        let mut doc = Doc::new(json, None, &dir);
        let mut table = MaterialTable::default();
        let e = doc.material(&mut table, Some(0)).unwrap_err();
        assert!(
            e.contains("KHR_texture_basisu") && e.contains("ktxdecompress"),
            "{e}"
        );
        let e = doc.material(&mut table, Some(1)).unwrap_err();
        assert!(e.contains("image 0 ('broken') cannot be decoded"), "{e}");
        let e = doc.material(&mut table, Some(2)).unwrap_err();
        assert!(e.contains("TEXCOORD_2"), "{e}");
    }
}
