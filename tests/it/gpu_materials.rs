//! A user scene's materials as the GPU draws them (src/gpu/surface.rs, shaders/surface/pbr.wgsl), on the
//! fixtures of tests/data/gltf/make_materials.py: texels where the texture and its KHR_texture_transform put
//! them; cut-out cards covering what their mask covers, at every LOD; a BLEND surface over an opaque one; the
//! flat surface of `--materials flat` and `reference-flat`; what a method does not draw, said in run.json; and
//! the images `lodbench export` carries.

use crate::common::{col, lodbench, read_csv, run_into};
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/gltf")
        .join(name)
}

/// A dumped frame of `run`: (width, RGBA bytes).
fn frame(run: &Path, scene: &str, method: &str, f: u32, kind: &str) -> (u32, Vec<u8>) {
    let p = run
        .join("frames")
        .join(format!("{scene}_{method}_c1_f{f:05}_{kind}.png"));
    let img = lodbench::raster::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    (img.width(), img.into_raw())
}

/// The pixels of `rgba` whose RGB is not the background's (its top-left pixel: the fixtures never reach it).
fn covered(rgba: &[u8]) -> usize {
    let bg = &rgba[..3];
    rgba.chunks_exact(4).filter(|p| &p[..3] != bg).count()
}

/// texel-grid.gltf's texture (make_materials.py's TEXEL_GRID): row r, column c.
fn texel(r: usize, c: usize) -> [u8; 3] {
    [
        (r * 60 + 20) as u8,
        (c * 60 + 30) as u8,
        ((r * 4 + c) * 15) as u8,
    ]
}

/// The unlit quad shows its 4 x 4 texture texel for texel, shifted by its KHR_texture_transform's offset of a
/// quarter in u (the quad's column c is the texture's column c + 1, wrapping): at the centre of each of the
/// quad's 16 cells the colour is the texel's, to 1 (the sRGB texture is decoded to linear light and the target
/// encodes it again, which can round the last bit). With `--materials flat` the quad is one colour.
#[test]
fn texels_are_drawn_where_the_texture_and_its_transform_put_them() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("texel-grid.gltf");
    let scene = scene.to_str().unwrap();
    let base = ["--method", "reference", "--frames", "1", "--width", "160"];
    let mut args = vec!["--scene", scene, "--height", "120", "--dump-frames"];
    args.extend_from_slice(&base);
    let full = run_into(&dir.path().join("full"), &args);
    let (w, img) = frame(&full, "texel-grid.gltf", "reference", 0, "reference");
    let bg = [img[0], img[1], img[2]];
    let at = |x: u32, y: u32| -> [u8; 3] {
        let i = ((y * w + x) * 4) as usize;
        [img[i], img[i + 1], img[i + 2]]
    };
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for y in 0..img.len() as u32 / 4 / w {
        for x in 0..w {
            if at(x, y) != bg {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            }
        }
    }
    assert!(
        x1 > x0 + 40 && y1 > y0 + 40,
        "the quad is {x0}..{x1} x {y0}..{y1}"
    );
    let cell = |i: u32, lo: u32, hi: u32| lo + ((2 * i + 1) * (hi + 1 - lo)) / 8;
    for r in 0..4 {
        for c in 0..4 {
            let got = at(cell(c, x0, x1), cell(r, y0, y1));
            let want = texel(r as usize, (c as usize + 1) % 4);
            assert!(
                (0..3).all(|k| got[k].abs_diff(want[k]) <= 1),
                "cell ({r}, {c}): {got:?}, the texel {want:?}"
            );
        }
    }
    args.extend_from_slice(&["--materials", "flat"]);
    let flat = run_into(&dir.path().join("flat"), &args);
    let (_, img) = frame(&flat, "texel-grid.gltf", "reference", 0, "reference");
    let mut colours: Vec<&[u8]> = img
        .chunks_exact(4)
        .map(|p| &p[..3])
        .filter(|p| *p != &img[..3])
        .collect();
    colours.sort();
    colours.dedup();
    assert_eq!(colours.len(), 1, "flat: {colours:?}");
}

/// leaf-cards.gltf: cut-out cards (MASK, cutoff 0.5) whose texture's alpha is a disc over 0.793 of its texels
/// (make_materials.py's DISC_FRACTION), an authored chain of 16 small cards then 4 large ones over the same
/// square. On every frame, at either LOD, the cards cover between none of their quads and all of them as the
/// mask says: the pixels covered with the materials over those covered with `--materials flat` (the quads whole)
/// are the disc's share to within 0.03. The share is of texels (NEAREST sampling, no mipmaps) and a pixel is
/// covered by its centre's texel, so the pixel count departs from it only along the discs' edges, more as the
/// cards shrink along the flight: measured 0.776 to 0.809 over the 40 frames (0.793 asked). Cards drawn as quads
/// would give 1, an inverted mask 0.21.
#[test]
fn cut_out_cards_cover_what_their_mask_covers_at_every_lod() {
    const DISC_FRACTION: f64 = 812.0 / 1024.0;
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("leaf-cards.gltf");
    let scene = scene.to_str().unwrap();
    let mut args = vec![
        "--scene",
        scene,
        "--method",
        "discrete",
        "--frames",
        "40",
        "--width",
        "320",
        "--height",
        "240",
        "--dump-frames",
        "--quality",
        "on",
    ];
    let full = run_into(&dir.path().join("full"), &args);
    args.extend_from_slice(&["--materials", "flat"]);
    let flat = run_into(&dir.path().join("flat"), &args);
    let triangles = col(&read_csv(&full.join("frames.csv")), "discrete", "triangles");
    assert!(
        triangles.contains(&32.0) && triangles.contains(&8.0),
        "both LODs on the path: {triangles:?}"
    );
    for f in 0..40 {
        let (_, a) = frame(&full, "leaf-cards.gltf", "discrete", f, "method");
        let (_, b) = frame(&flat, "leaf-cards.gltf", "discrete", f, "method");
        let (cut, whole) = (covered(&a), covered(&b));
        assert!(cut > 0 && cut < whole, "frame {f}: {cut} of {whole}");
        let share = cut as f64 / whole as f64;
        assert!(
            (share - DISC_FRACTION).abs() < 0.03,
            "frame {f} ({} triangles): the cards cover {share:.4} of their quads, the mask {DISC_FRACTION:.4}",
            triangles[f as usize]
        );
    }
}

/// blend-over.gltf: a BLEND quad of base colour (1, 0, 0, 0.5), unlit, 0.1 in front of an opaque green one: where
/// they overlap the pixel is half red over green in linear light, sRGB-encoded (188, 188, 0), to 1. The methods
/// whose double pass cannot draw BLEND surfaces in transition say so in run.json; the others do not.
#[test]
fn a_blend_surface_is_drawn_over_the_opaque_one() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("blend-over.gltf");
    #[rustfmt::skip]
    let out = run_into(dir.path(), &[
        "--scene", scene.to_str().unwrap(), "--method", "reference,discrete,alpha-2pass,alpha-linear",
        "--frames", "2", "--width", "96", "--height", "72", "--dump-frames",
    ]);
    let (w, img) = frame(&out, "blend-over.gltf", "reference", 0, "reference");
    let h = img.len() as u32 / 4 / w;
    let i = ((h / 2 * w + w / 2) * 4) as usize;
    let want = [188u8, 188, 0];
    assert!(
        (0..3).all(|k| img[i + k].abs_diff(want[k]) <= 1),
        "centre {:?}",
        &img[i..i + 3]
    );
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    for b in run["blocks"].as_array().unwrap() {
        let limited = b.get("material_limits").is_some();
        let method = b["method"].as_str().unwrap();
        assert_eq!(
            limited,
            method.starts_with("alpha-"),
            "{method}: material_limits {:?}",
            b.get("material_limits")
        );
    }
}

/// `reference-flat` draws the reference's triangles with the flat surface: the same frame as the reference of
/// `--materials flat`, byte for byte, and not the textured reference's.
#[test]
fn reference_flat_is_the_reference_without_its_materials() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("texel-grid.gltf");
    let scene = scene.to_str().unwrap();
    let common = [
        "--frames",
        "1",
        "--width",
        "96",
        "--height",
        "72",
        "--dump-frames",
    ];
    let mut a = vec!["--scene", scene, "--method", "reference,reference-flat"];
    a.extend_from_slice(&common);
    let both = run_into(&dir.path().join("a"), &a);
    let mut b = vec![
        "--scene",
        scene,
        "--method",
        "reference",
        "--materials",
        "flat",
    ];
    b.extend_from_slice(&common);
    let flat = run_into(&dir.path().join("b"), &b);
    let name = "texel-grid.gltf";
    let (_, textured) = frame(&both, name, "reference", 0, "method");
    let (_, reference_flat) = frame(&both, name, "reference-flat", 0, "method");
    let (_, flat_reference) = frame(&flat, name, "reference", 0, "method");
    assert_eq!(reference_flat, flat_reference);
    assert_ne!(reference_flat, textured);
}

/// `lodbench export` carries each PNG or JPEG image as the bytes it was read from (texel-grid.gltf's PNG, byte for
/// byte, with its MIME type), so the file it writes decodes to the same pixels without re-encoding them.
#[test]
fn an_export_carries_the_images_it_read() {
    use base64::Engine;
    let dir = tempfile::tempdir().unwrap();
    let scene = fixture("texel-grid.gltf");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&scene).unwrap()).unwrap();
    let uri = doc["images"][0]["uri"].as_str().unwrap();
    let source = base64::engine::general_purpose::STANDARD
        .decode(uri.split_once(',').unwrap().1)
        .unwrap();
    let glb = dir.path().join("texel-grid.glb");
    let (scene, out) = (scene.to_str().unwrap(), glb.to_str().unwrap());
    let run = lodbench(&["export", "--scene", scene, "--out", out], &[]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // GLB: a 12-byte header, then the JSON chunk and the BIN chunk, each after its length and type.
    let bytes = std::fs::read(&glb).unwrap();
    let chunk = |at: usize| {
        let len = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        (&bytes[at + 8..at + 8 + len], at + 8 + len)
    };
    let (json, next) = chunk(12);
    let (bin, _) = chunk(next);
    let json: serde_json::Value = serde_json::from_slice(json).unwrap();
    let image = &json["images"][0];
    assert_eq!(image["mimeType"], "image/png");
    let view = &json["bufferViews"][image["bufferView"].as_u64().unwrap() as usize];
    let at = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let len = view["byteLength"].as_u64().unwrap() as usize;
    assert!(
        bin[at..at + len] == source[..],
        "the exported image is the source's bytes"
    );
}
