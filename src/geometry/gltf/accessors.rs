//! Accessors: the typed views of buffer data (glTF 2.0 section 3.6), sparse ones included, over buffer views that
//! may be meshopt-compressed (EXT_ and KHR_meshopt_compression, decoded with meshoptimizer, filters included)
//! and attributes that may be quantised (KHR_mesh_quantization: integers, normalised or not, dequantised as
//! section 3.11 says).

use super::container::read_buffer_uri;
use super::json::{array, index, opt_index, opt_uint, uint, uint_or};
use serde_json::Value;
use std::borrow::Cow;
use std::path::Path;

/// The largest buffer view a meshopt-compressed view may decode to (1 GiB).
const MAX_VIEW_BYTES: usize = 1 << 30;

/// The largest accessor made without buffer data (no buffer view: zeros, then its sparse values): 256 MiB.
const MAX_ZERO_BYTES: usize = 1 << 28;

/// The document's buffers and buffer views, read when first used.
pub struct Doc<'a> {
    pub json: Value,
    blob: Option<&'a [u8]>,
    dir: &'a Path,
    buffers: Vec<Option<Vec<u8>>>,
    /// Decoded meshopt-compressed buffer views, by view index.
    views: Vec<Option<Vec<u8>>>,
}

/// An accessor's layout.
#[derive(Debug, Clone, Copy)]
struct Layout {
    view: Option<usize>,
    offset: usize,
    count: usize,
    component: u64,
    components: usize,
    normalized: bool,
}

impl Layout {
    fn component_size(&self) -> usize {
        component_size(self.component).unwrap_or(4)
    }

    fn element_size(&self) -> usize {
        self.component_size() * self.components
    }
}

fn component_size(c: u64) -> Option<usize> {
    match c {
        5120 | 5121 => Some(1),
        5122 | 5123 => Some(2),
        5125 | 5126 => Some(4),
        _ => None,
    }
}

fn component_name(c: u64) -> &'static str {
    match c {
        5120 => "byte",
        5121 => "unsigned byte",
        5122 => "short",
        5123 => "unsigned short",
        5125 => "unsigned int",
        5126 => "float",
        _ => "unknown",
    }
}

impl<'a> Doc<'a> {
    pub fn new(json: Value, blob: Option<&'a [u8]>, dir: &'a Path) -> Doc<'a> {
        Doc {
            buffers: vec![None; array(&json, "buffers").len()],
            views: vec![None; array(&json, "bufferViews").len()],
            json,
            blob,
            dir,
        }
    }

    fn layout(&self, i: usize) -> Result<Layout, String> {
        let accessors = array(&self.json, "accessors");
        let a = accessors.get(i).ok_or_else(|| {
            format!(
                "accessor {i} does not exist ({} accessors)",
                accessors.len()
            )
        })?;
        let view = opt_index(
            &a["bufferView"],
            || format!("accessor {i}'s bufferView"),
            self.views.len(),
        )?;
        let component = uint(&a["componentType"]).unwrap_or(0);
        if component_size(component).is_none() {
            return Err(format!(
                "accessor {i} has componentType {}, which glTF does not define",
                a["componentType"]
            ));
        }
        let components = match a["type"].as_str() {
            Some("SCALAR") => 1,
            Some("VEC2") => 2,
            Some("VEC3") => 3,
            Some("VEC4") | Some("MAT2") => 4,
            Some("MAT3") => 9,
            Some("MAT4") => 16,
            other => {
                return Err(format!(
                    "accessor {i} has type {}, which glTF does not define",
                    other.unwrap_or("(none)")
                ))
            }
        };
        // Matrix columns of 1- and 2-byte components are padded to 4 bytes (section 3.6.2.4); lodbench reads
        // the matrices glTF uses (inverse bind matrices: floats), whose columns need no padding.
        if matches!(a["type"].as_str(), Some("MAT2" | "MAT3")) && component != 5126 {
            return Err(format!(
                "accessor {i} is a {} matrix of {}s; lodbench reads matrices of floats",
                a["type"],
                component_name(component)
            ));
        }
        Ok(Layout {
            view,
            offset: uint_or(&a["byteOffset"], 0, || format!("accessor {i}'s byteOffset"))? as usize,
            count: uint_or(&a["count"], 0, || format!("accessor {i}'s count"))? as usize,
            component,
            components,
            normalized: a["normalized"].as_bool().unwrap_or(false),
        })
    }

    /// The bytes of buffer `b`.
    fn buffer(&mut self, b: usize) -> Result<&[u8], String> {
        let n = self.buffers.len();
        if b >= n {
            return Err(format!("buffer {b} does not exist ({n} buffers)"));
        }
        if self.buffers[b].is_none() {
            let desc = &self.json["buffers"][b];
            let declared = uint_or(&desc["byteLength"], 0, || {
                format!("buffer {b}'s byteLength")
            })? as usize;
            let data: Vec<u8> = match desc["uri"].as_str() {
                Some(uri) => read_buffer_uri(b, uri, self.dir)?,
                None if b == 0 => self
                    .blob
                    .ok_or_else(|| {
                        format!("buffer {b} refers to the GLB binary chunk, which the file does not have")
                    })?
                    .to_vec(),
                None if desc.pointer("/extensions/EXT_meshopt_compression/fallback").is_some()
                    || desc.pointer("/extensions/KHR_meshopt_compression/fallback").is_some() =>
                {
                    return Err(format!(
                        "buffer {b} is a meshopt fallback buffer without data, read by a buffer view that is not \
                         compressed"
                    ))
                }
                None => return Err(format!("buffer {b} has no uri and is not the GLB binary chunk")),
            };
            if data.len() < declared {
                return Err(format!(
                    "buffer {b} holds {} bytes but declares byteLength {declared}",
                    data.len()
                ));
            }
            self.buffers[b] = Some(data);
        }
        Ok(self.buffers[b].as_deref().unwrap_or(&[]))
    }

    /// Buffer view `v`'s bytes (an image's, decoded when meshopt-compressed), `what` naming who reads it.
    pub(super) fn view_bytes(&mut self, v: usize, what: &str) -> Result<Vec<u8>, String> {
        if v >= self.views.len() {
            return Err(format!(
                "{what}'s bufferView is {v}, not an index below {}",
                self.views.len()
            ));
        }
        Ok(self.view(v)?.0.into_owned())
    }

    /// The folder external files are read from.
    pub(super) fn dir(&self) -> &Path {
        self.dir
    }

    /// Buffer view `v`'s bytes (decoded when meshopt-compressed) and its stride.
    fn view(&mut self, v: usize) -> Result<(Cow<'_, [u8]>, Option<usize>), String> {
        let desc = self.json["bufferViews"][v].clone();
        let stride = opt_uint(&desc["byteStride"], || {
            format!("buffer view {v}'s byteStride")
        })?
        .map(|s| s as usize);
        let compressed = desc
            .pointer("/extensions/EXT_meshopt_compression")
            .or_else(|| desc.pointer("/extensions/KHR_meshopt_compression"))
            .cloned();
        if let Some(ext) = compressed {
            if self.views[v].is_none() {
                let view_length = uint_or(&desc["byteLength"], 0, || {
                    format!("buffer view {v}'s byteLength")
                })? as usize;
                let decoded = self.decode_meshopt(v, &ext, view_length)?;
                self.views[v] = Some(decoded);
            }
            return Ok((
                Cow::Borrowed(self.views[v].as_deref().unwrap_or(&[])),
                stride,
            ));
        }
        let b = index(
            &desc["buffer"],
            || format!("buffer view {v}'s buffer"),
            self.buffers.len(),
        )?;
        let offset = uint_or(&desc["byteOffset"], 0, || {
            format!("buffer view {v}'s byteOffset")
        })? as usize;
        let length = uint_or(&desc["byteLength"], 0, || {
            format!("buffer view {v}'s byteLength")
        })? as usize;
        let data = self.buffer(b)?;
        let have = data.len();
        let bytes = offset
            .checked_add(length)
            .and_then(|end| data.get(offset..end))
            .ok_or_else(|| {
                format!("buffer view {v} reaches past the end of buffer {b} ({have} bytes)")
            })?;
        Ok((Cow::Borrowed(bytes), stride))
    }

    /// EXT_ or KHR_meshopt_compression: the view's decoded bytes (count x byteStride).
    fn decode_meshopt(
        &mut self,
        v: usize,
        ext: &Value,
        view_length: usize,
    ) -> Result<Vec<u8>, String> {
        let what = format!("buffer view {v} (meshopt-compressed)");
        let b = index(
            &ext["buffer"],
            || format!("{what}: buffer"),
            self.buffers.len(),
        )?;
        let offset = uint_or(&ext["byteOffset"], 0, || format!("{what}: byteOffset"))? as usize;
        let length = uint_or(&ext["byteLength"], 0, || format!("{what}: byteLength"))? as usize;
        let stride = uint_or(&ext["byteStride"], 0, || format!("{what}: byteStride"))? as usize;
        let count = uint_or(&ext["count"], 0, || format!("{what}: count"))? as usize;
        let mode = ext["mode"].as_str().unwrap_or("");
        let filter = ext["filter"].as_str().unwrap_or("NONE");
        let data = self.buffer(b)?;
        let src = offset
            .checked_add(length)
            .and_then(|end| data.get(offset..end))
            .ok_or_else(|| format!("{what} reaches past the end of buffer {b}"))?;
        // The decoders allocate count x stride before they look at the data: the size must be the view's
        // (as the extension requires), and the compressed stream long enough for the count it claims.
        if count.checked_mul(stride) != Some(view_length) || view_length > MAX_VIEW_BYTES {
            return Err(format!(
                "{what}: count {count} x byteStride {stride} is not the view's byteLength {view_length} (or over \
                 {MAX_VIEW_BYTES} bytes)"
            ));
        }
        let index_mode = matches!(mode, "TRIANGLES" | "INDICES");
        if index_mode && filter != "NONE" {
            return Err(format!("{what}: mode {mode} takes no filter ({filter})"));
        }
        if mode == "TRIANGLES" && !count.is_multiple_of(3) {
            return Err(format!(
                "{what}: TRIANGLES with count {count}, not a multiple of 3"
            ));
        }
        let least = match mode {
            "TRIANGLES" => 17 + count / 3,
            "INDICES" => 5 + count,
            _ => 1,
        };
        if src.len() < least {
            return Err(format!(
                "{what}: {} compressed bytes cannot hold {count} elements",
                src.len()
            ));
        }
        let fail = |e: meshopt::Error| format!("{what} does not decode ({e})");
        let mut out = match (mode, stride) {
            ("ATTRIBUTES", s) if s > 0 && s % 4 == 0 && s <= 256 => decode_vertices(src, count, s)?,
            ("TRIANGLES", 2) => bytemuck::cast_slice(&meshopt::decode_index_buffer::<u16>(src, count).map_err(fail)?).to_vec(),
            ("TRIANGLES", 4) => bytemuck::cast_slice(&meshopt::decode_index_buffer::<u32>(src, count).map_err(fail)?).to_vec(),
            ("INDICES", 2) => bytemuck::cast_slice(&meshopt::decode_index_sequence::<u16>(src, count).map_err(fail)?).to_vec(),
            ("INDICES", 4) => bytemuck::cast_slice(&meshopt::decode_index_sequence::<u32>(src, count).map_err(fail)?).to_vec(),
            _ => return Err(format!("{what} has mode {mode:?} with byteStride {stride}, which the extension does not allow")),
        };
        unfilter(&mut out, filter, stride).map_err(|e| format!("{what}: {e}"))?;
        Ok(out)
    }

    /// The elements of accessor `i` (laid out as `l`) as bytes, the stride between them and the first one's
    /// offset: its buffer view's bytes, checked to hold every element; or, for an accessor without a buffer view
    /// or with sparse values, a tightly packed copy (zeros where it has no view, the sparse values substituted,
    /// section 3.6.2.3).
    fn elements(&mut self, i: usize, l: &Layout) -> Result<(Cow<'_, [u8]>, usize, usize), String> {
        let elem = l.element_size();
        let sparse = self.json["accessors"][i].get("sparse").cloned();
        let Some(view) = l.view else {
            let bytes = l
                .count
                .checked_mul(elem)
                .filter(|&n| n <= MAX_ZERO_BYTES)
                .ok_or_else(|| {
                    format!(
                        "accessor {i} has no buffer view and {} elements (over {MAX_ZERO_BYTES} bytes of zeros)",
                        l.count
                    )
                })?;
            let mut data = vec![0u8; bytes];
            if let Some(s) = &sparse {
                self.substitute(i, l, s, &mut data)?;
            }
            return Ok((Cow::Owned(data), elem, 0));
        };
        if let Some(s) = sparse {
            let mut data = Vec::new();
            {
                let (bytes, stride) = self.view(view)?;
                let stride = fits(i, l, view, bytes.len(), stride)?;
                data.reserve(l.count * elem);
                for e in 0..l.count {
                    let at = l.offset + e * stride;
                    data.extend_from_slice(&bytes[at..at + elem]);
                }
            }
            self.substitute(i, l, &s, &mut data)?;
            return Ok((Cow::Owned(data), elem, 0));
        }
        let (bytes, stride) = self.view(view)?;
        let stride = fits(i, l, view, bytes.len(), stride)?;
        Ok((bytes, stride, l.offset))
    }

    /// Writes accessor `i`'s sparse values (`sparse`) into its tightly packed elements `data`.
    fn substitute(
        &mut self,
        i: usize,
        l: &Layout,
        sparse: &Value,
        data: &mut [u8],
    ) -> Result<(), String> {
        let what = format!("accessor {i}'s sparse");
        let count = uint(&sparse["count"])
            .filter(|&c| c >= 1 && c as usize <= l.count)
            .ok_or_else(|| {
                format!(
                    "{what}.count is {}, not between 1 and the accessor's count {}",
                    sparse["count"], l.count
                )
            })? as usize;
        let elem = l.element_size();
        let views = self.views.len();
        let part = |key: &str| -> Result<(usize, usize), String> {
            let p = &sparse[key];
            let view = index(
                &p["bufferView"],
                || format!("{what}.{key}.bufferView"),
                views,
            )?;
            let offset =
                uint_or(&p["byteOffset"], 0, || format!("{what}.{key}.byteOffset"))? as usize;
            Ok((view, offset))
        };
        let (iview, ioffset) = part("indices")?;
        let (vview, voffset) = part("values")?;
        let isize = match uint(&sparse["indices"]["componentType"]) {
            Some(5121) => 1,
            Some(5123) => 2,
            Some(5125) => 4,
            _ => {
                return Err(format!(
                    "{what}.indices has componentType {}; sparse indices are unsigned integers",
                    sparse["indices"]["componentType"]
                ))
            }
        };
        let targets: Vec<usize> = {
            let (bytes, _) = self.view(iview)?;
            let all = ioffset
                .checked_add(count * isize)
                .and_then(|end| bytes.get(ioffset..end))
                .ok_or_else(|| format!("{what}.indices do not fit in buffer view {iview}"))?;
            all.chunks_exact(isize)
                .map(|b| match isize {
                    1 => b[0] as usize,
                    2 => u16::from_le_bytes([b[0], b[1]]) as usize,
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
                })
                .collect()
        };
        if let Some(&bad) = targets.iter().find(|&&t| t >= l.count) {
            return Err(format!(
                "{what} substitutes element {bad} of an accessor of {} elements",
                l.count
            ));
        }
        let (bytes, _) = self.view(vview)?;
        let values = voffset
            .checked_add(count * elem)
            .and_then(|end| bytes.get(voffset..end))
            .ok_or_else(|| format!("{what}.values do not fit in buffer view {vview}"))?;
        for (k, &t) in targets.iter().enumerate() {
            data[t * elem..(t + 1) * elem].copy_from_slice(&values[k * elem..(k + 1) * elem]);
        }
        Ok(())
    }

    /// Accessor `i`'s elements as floats (integers dequantised: normalised ones to [-1, 1] or [0, 1], others
    /// as their value) and its component count.
    pub fn read_floats(&mut self, i: usize) -> Result<(Vec<f32>, usize), String> {
        let l = self.layout(i)?;
        let size = l.component_size();
        let (bytes, stride, offset) = self.elements(i, &l)?;
        let mut out = Vec::with_capacity(l.count * l.components);
        for e in 0..l.count {
            let at = offset + e * stride;
            for c in 0..l.components {
                let b = &bytes[at + c * size..at + (c + 1) * size];
                out.push(component(b, l.component, l.normalized));
            }
        }
        Ok((out, l.components))
    }

    /// An attribute of `N` components per element (`kind` in errors: "positions", "normals", ...) of `what`,
    /// as arrays.
    pub fn read_vecs<const N: usize>(
        &mut self,
        i: usize,
        what: &str,
        kind: &str,
    ) -> Result<Vec<[f32; N]>, String> {
        let l = self.layout(i)?;
        if l.components != N {
            return Err(format!(
                "{what} has {}-component {kind}, where glTF has {N}",
                l.components
            ));
        }
        let (v, _) = self.read_floats(i)?;
        Ok(v.chunks_exact(N)
            .map(|c| std::array::from_fn(|k| c[k]))
            .collect())
    }

    /// An attribute that is VEC3 or VEC4 (`COLOR_0`), as VEC4 (alpha 1 where absent).
    pub fn read_rgba(&mut self, i: usize, what: &str) -> Result<Vec<[f32; 4]>, String> {
        let (v, c) = self.read_floats(i)?;
        match c {
            3 => Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2], 1.0]).collect()),
            4 => Ok(v
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect()),
            _ => Err(format!(
                "{what} has {c}-component colours; glTF colours are VEC3 or VEC4"
            )),
        }
    }

    /// Accessor `i` as unsigned integers (`what` in errors: indices, joints) and its component count. Read as
    /// integers, not through f32, where an index above 2^24 would round.
    pub fn read_uints(&mut self, i: usize, what: &str) -> Result<(Vec<u32>, usize), String> {
        let l = self.layout(i)?;
        if !matches!(l.component, 5121 | 5123 | 5125) || l.normalized {
            return Err(format!(
                "{what} has {} components{}; it takes unsigned integers",
                component_name(l.component),
                if l.normalized { " (normalised)" } else { "" }
            ));
        }
        let size = l.component_size();
        let (bytes, stride, offset) = self.elements(i, &l)?;
        let mut out = Vec::with_capacity(l.count * l.components);
        for e in 0..l.count {
            for c in 0..l.components {
                let b = &bytes[offset + e * stride + c * size..];
                out.push(match size {
                    1 => u32::from(b[0]),
                    2 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                });
            }
        }
        Ok((out, l.components))
    }

    /// A primitive's index accessor.
    pub fn read_indices(&mut self, i: usize, what: &str) -> Result<Vec<u32>, String> {
        let (v, c) = self.read_uints(i, &format!("{what}'s index accessor"))?;
        if c != 1 {
            return Err(format!(
                "{what} has indices of {c} components; glTF indices are scalars"
            ));
        }
        Ok(v)
    }
}

/// The stride of accessor `i` (laid out as `l`) in buffer view `view` of `len` bytes with `stride` (None: tightly
/// packed), checked to hold every element: a stride that holds an element, the last element inside the view.
fn fits(
    i: usize,
    l: &Layout,
    view: usize,
    len: usize,
    stride: Option<usize>,
) -> Result<usize, String> {
    let elem = l.element_size();
    let stride = stride.unwrap_or(elem);
    if stride < elem {
        return Err(format!(
            "buffer view {view} has stride {stride}, less than accessor {i}'s {elem}-byte elements"
        ));
    }
    let end = l
        .count
        .checked_sub(1)
        .and_then(|n| n.checked_mul(stride))
        .and_then(|n| n.checked_add(elem))
        .and_then(|n| n.checked_add(l.offset));
    if l.count > 0 && end.is_none_or(|end| end > len) {
        return Err(format!(
            "accessor {i} ({} elements) does not fit in buffer view {view}",
            l.count
        ));
    }
    Ok(stride)
}

/// One component of an accessor element as f32 (glTF 2.0 section 3.11 for normalised integers).
fn component(b: &[u8], kind: u64, normalized: bool) -> f32 {
    match (kind, normalized) {
        (5126, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (5125, _) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
        (5120, false) => b[0] as i8 as f32,
        (5120, true) => (b[0] as i8 as f32 / 127.0).max(-1.0),
        (5121, false) => b[0] as f32,
        (5121, true) => b[0] as f32 / 255.0,
        (5122, false) => i16::from_le_bytes([b[0], b[1]]) as f32,
        (5122, true) => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
        (5123, false) => u16::from_le_bytes([b[0], b[1]]) as f32,
        _ => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
    }
}

/// `count` vertices of `stride` bytes from meshoptimizer's vertex codec.
fn decode_vertices(src: &[u8], count: usize, stride: usize) -> Result<Vec<u8>, String> {
    #[derive(Clone, Copy)]
    #[repr(transparent)]
    struct Bytes<const N: usize>([u8; N]);
    impl<const N: usize> Default for Bytes<N> {
        fn default() -> Self {
            Bytes([0; N])
        }
    }
    fn run<const N: usize>(src: &[u8], count: usize) -> Result<Vec<u8>, String> {
        let v: Vec<Bytes<N>> = meshopt::decode_vertex_buffer(src, count)
            .map_err(|e| format!("the vertex stream does not decode ({e})"))?;
        Ok(v.into_iter().flat_map(|b| b.0).collect())
    }
    macro_rules! by_stride {
        ($($n:literal)*) => {
            match stride {
                $($n => run::<$n>(src, count),)*
                _ => Err(format!("byteStride {stride} is not a multiple of 4 up to 256")),
            }
        };
    }
    by_stride!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108 112 116 120 124 128
        132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192 196 200 204 208 212 216 220 224 228 232
        236 240 244 248 252 256)
}

/// Undoes a meshopt filter in place (EXT_meshopt_compression's filters, and KHR's COLOR).
fn unfilter(data: &mut [u8], filter: &str, stride: usize) -> Result<(), String> {
    fn apply<T: bytemuck::Pod>(data: &mut [u8], f: impl FnOnce(&mut [T])) {
        let mut v: Vec<T> = data
            .chunks_exact(std::mem::size_of::<T>())
            .map(bytemuck::pod_read_unaligned)
            .collect();
        f(&mut v);
        data.copy_from_slice(bytemuck::cast_slice(&v));
    }
    match (filter, stride) {
        ("NONE", _) => {}
        ("OCTAHEDRAL", 4) => apply::<[i8; 4]>(data, meshopt::decode_filter_oct),
        ("OCTAHEDRAL", 8) => apply::<[i16; 4]>(data, meshopt::decode_filter_oct),
        ("QUATERNION", 8) => apply::<[i16; 4]>(data, meshopt::decode_filter_quat),
        ("EXPONENTIAL", 4) => apply::<[u32; 1]>(data, meshopt::decode_filter_exp),
        ("EXPONENTIAL", 8) => apply::<[u32; 2]>(data, meshopt::decode_filter_exp),
        ("EXPONENTIAL", 12) => apply::<[u32; 3]>(data, meshopt::decode_filter_exp),
        ("EXPONENTIAL", 16) => apply::<[u32; 4]>(data, meshopt::decode_filter_exp),
        ("COLOR", 4) => apply::<[u8; 4]>(data, meshopt::decode_filter_color),
        ("COLOR", 8) => apply::<[u16; 4]>(data, meshopt::decode_filter_color),
        _ => {
            return Err(format!(
                "filter {filter} with byteStride {stride} is not one lodbench decodes"
            ))
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// glTF 2.0 section 3.11: f = max(c / 127, -1) for bytes, c / 255 for unsigned bytes, max(c / 32767, -1)
    /// for shorts, c / 65535 for unsigned shorts; integers that are not normalised keep their value.
    #[test]
    fn normalised_integers_dequantise_as_the_spec_says() {
        let short = |v: i16| v.to_le_bytes();
        assert_eq!(component(&short(32767), 5122, true), 1.0);
        assert_eq!(component(&short(-32767), 5122, true), -1.0);
        assert_eq!(component(&short(-32768), 5122, true), -1.0);
        assert_eq!(component(&short(16384), 5122, true), 16384.0 / 32767.0);
        assert_eq!(component(&short(-7), 5122, false), -7.0);
        assert_eq!(component(&65535u16.to_le_bytes(), 5123, true), 1.0);
        assert_eq!(component(&1000u16.to_le_bytes(), 5123, false), 1000.0);
        assert_eq!(component(&[127], 5120, true), 1.0);
        assert_eq!(component(&[0x80], 5120, true), -1.0);
        assert_eq!(component(&[0x81], 5120, false), -127.0);
        assert_eq!(component(&[255], 5121, true), 1.0);
        assert_eq!(component(&[51], 5121, true), 0.2);
        assert_eq!(component(&1.5f32.to_le_bytes(), 5126, true), 1.5);
    }
}
