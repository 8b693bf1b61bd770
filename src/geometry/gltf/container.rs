//! The glTF container: the JSON document and the GLB binary chunk, the required extensions, and buffers named by
//! URI (base64 `data:` URIs and relative file paths).

use super::json::array;
use serde_json::Value;
use std::path::Path;

/// Extensions that change geometry or placement and that this reader decodes.
pub const READ: [&str; 5] = [
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "EXT_mesh_gpu_instancing",
    "MSFT_lod",
];

/// Prefixes of extensions that only change materials, textures, lights or cameras: accepted unread.
const APPEARANCE: [&str; 5] = [
    "KHR_materials_",
    "KHR_texture_",
    "EXT_texture_",
    "KHR_lights_",
    "KHR_xmp",
];

/// What a user can do with a Draco-compressed file.
pub const DRACO_REMEDY: &str = "lodbench does not decode Draco (KHR_draco_mesh_compression): rewrite the file with \
     meshopt compression, which it reads: `npx @gltf-transform/cli meshopt IN.glb OUT.glb` (gltfpack cannot read \
     Draco input)";

/// The JSON and the GLB binary chunk of `bytes`.
pub fn container(bytes: &[u8]) -> Result<(Value, Option<&[u8]>), String> {
    let json_of = |b: &[u8]| -> Result<Value, String> {
        let v: Value = serde_json::from_slice(b).map_err(|e| format!("invalid JSON: {e}"))?;
        match v.pointer("/asset/version").and_then(Value::as_str) {
            Some(ver) if ver.starts_with("2.") => super::json::check_shapes(&v).map(|()| v),
            Some(ver) => Err(format!("glTF version {ver}; lodbench reads glTF 2.0")),
            None => Err("no asset.version: not a glTF 2.0 document".into()),
        }
    };
    if !bytes.starts_with(b"glTF") {
        return Ok((json_of(bytes)?, None));
    }
    let word = |at: usize| -> Option<u32> {
        bytes
            .get(at..at + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let version = word(4).ok_or("GLB header truncated")?;
    if version != 2 {
        return Err(format!("GLB version {version}; lodbench reads version 2"));
    }
    let length = word(8).ok_or("GLB header truncated")? as usize;
    if length != bytes.len() {
        return Err(format!(
            "the GLB header says {length} bytes but the file has {}",
            bytes.len()
        ));
    }
    let (mut at, mut json, mut blob) = (12usize, None, None);
    while at < length {
        let (len, kind) = match (word(at), word(at + 4)) {
            (Some(l), Some(k)) => (l as usize, k),
            _ => return Err(format!("GLB chunk header at byte {at} truncated")),
        };
        let data = bytes
            .get(at + 8..at + 8 + len)
            .ok_or_else(|| format!("GLB chunk at byte {at} runs past the end of the file"))?;
        match (kind, json.is_none()) {
            (0x4E4F_534A, true) => json = Some(json_of(data)?),
            (_, true) => return Err("the first GLB chunk is not JSON".into()),
            (0x004E_4942, false) if blob.is_none() => blob = Some(data),
            _ => {}
        }
        at += 8 + len;
    }
    Ok((json.ok_or("GLB without a JSON chunk")?, blob))
}

/// Refuses a file that requires an extension this reader does not read.
pub fn check_required(json: &Value) -> Result<(), String> {
    for ext in array(json, "extensionsRequired") {
        let Some(name) = ext.as_str() else {
            continue;
        };
        if READ.contains(&name) || APPEARANCE.iter().any(|p| name.starts_with(p)) {
            continue;
        }
        if name == "KHR_draco_mesh_compression" {
            return Err(format!("requires {name}; {DRACO_REMEDY}"));
        }
        return Err(format!(
            "requires extension {name}, which lodbench does not read (it reads {} and ignores texture and \
             material extensions); export the file again without it, or rewrite it with `npx gltfpack -i IN.glb -o \
             OUT.glb -noq` where gltfpack reads the extension",
            READ.join(", ")
        ));
    }
    Ok(())
}

/// A buffer's bytes from a `data:` URI or a file relative to `dir`.
pub fn read_buffer_uri(i: usize, uri: &str, dir: &Path) -> Result<Vec<u8>, String> {
    read_uri(&format!("buffer {i}"), uri, dir)
}

/// The bytes a `data:` URI holds or a file relative to `dir` (percent-encoded) has; `what` (a buffer, an image)
/// names the owner in errors.
pub fn read_uri(what: &str, uri: &str, dir: &Path) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest
            .split_once(',')
            .ok_or_else(|| format!("{what} has a data: URI without a ','"))?;
        let bytes = if header.ends_with(";base64") {
            decode_base64(payload)
        } else {
            percent_decode(payload)
        };
        return bytes.ok_or_else(|| format!("{what} has a data: URI that does not decode"));
    }
    let scheme = uri.split_once(':').map(|(s, _)| s);
    if scheme.is_some_and(|s| {
        s.len() > 1
            && s.starts_with(|c: char| c.is_ascii_alphabetic())
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
    }) {
        return Err(format!(
            "{what} has URI '{uri}': lodbench reads only data: URIs and relative file paths"
        ));
    }
    let relative = percent_decode(uri)
        .and_then(|b| String::from_utf8(b).ok())
        .ok_or_else(|| format!("{what} has URI '{uri}', which is not a valid file path"))?;
    let file = dir.join(relative);
    std::fs::read(&file).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            format!("{what} file {} not found", file.display())
        } else {
            format!("{what} file {} cannot be read ({e})", file.display())
        }
    })
}

/// Standard or URL-safe base64 (the two alphabets may mix), padding optional; `None` for any other character
/// or a length no base64 text has. Bits left over after the last whole byte are ignored.
pub fn decode_base64(text: &str) -> Option<Vec<u8>> {
    use base64::engine::{general_purpose, DecodePaddingMode, Engine, GeneralPurpose};
    const ENGINE: GeneralPurpose = GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        general_purpose::NO_PAD
            .with_decode_padding_mode(DecodePaddingMode::RequireNone)
            .with_decode_allow_trailing_bits(true),
    );
    let standard: String = text
        .trim_end_matches('=')
        .chars()
        .map(|c| match c {
            '-' => '+',
            '_' => '/',
            c => c,
        })
        .collect();
    ENGINE.decode(standard).ok()
}

/// Decodes `%XX` escapes; `None` for a `%` not followed by two hex digits.
pub fn percent_decode(text: &str) -> Option<Vec<u8>> {
    // The crate leaves a malformed escape as it is; a URI with one is refused instead.
    let b = text.as_bytes();
    let malformed = b.iter().enumerate().any(|(i, &c)| {
        c == b'%'
            && !b
                .get(i + 1..i + 3)
                .is_some_and(|hex| hex.iter().all(u8::is_ascii_hexdigit))
    });
    (!malformed).then(|| percent_encoding::percent_decode(b).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A required extension lodbench does not read is refused by name; texture-only ones are not.
    #[test]
    fn required_extensions() {
        let doc = |ext: &str| serde_json::json!({"asset": {"version": "2.0"}, "extensionsRequired": [ext]});
        let msg = check_required(&doc("EXT_mesh_features_x")).unwrap_err();
        assert!(
            msg.contains("EXT_mesh_features_x") && msg.contains("gltfpack"),
            "{msg}"
        );
        assert!(check_required(&doc("KHR_texture_basisu")).is_ok());
        assert!(check_required(&doc("KHR_mesh_quantization")).is_ok());
    }
}
