//! Frame Sequential Interpolation on the software adapter (image tests a-f). The combination pass is
//! checked pixel by pixel against a CPU implementation of Scherzer & Wimmer 2008 sections 3.4-3.5 and eq. 2 that reads the
//! same two LOD buffers (colour, depth, id) back from the GPU. That its combination pass holds no memory per
//! frame is a long-suite test (tests/long/methods_fsi_memory.rs).

use glam::{Mat4, Vec4};
use indicatif::ProgressBar;
use lodbench::gpu::GpuContext;
use lodbench::gpu::{RenderTarget, SceneGpu, TextureReadback};
use lodbench::measure::{BlockRunner, FrameDriver};
use lodbench::methods::fsi::{reprojection, Fsi, FsiCheck, LodBufferImage, Variant};
use lodbench::methods::{Method, MethodOptions};
use lodbench::scene::{Scene, SceneDef, SceneKind};

use crate::common::{near_distance, scene_config as scene_cfg, srgb_to_linear, static_scene, H, W};

struct Frame {
    out: Vec<u8>,
    newer: LodBufferImage,
    older: LodBufferImage,
    reproject: Mat4,
    /// With `--fsi-check forward` on `fsi`: eq. 2 inverted (older clip space to newer).
    forward: Option<Mat4>,
    /// `fsi-blend`: frame-sequential blending instead of the paper's cases.
    blend: bool,
}

/// Renders frames 0..=last with `variant` and returns the last one with both LOD buffers.
fn render_fsi(ctx: &GpuContext, scene: &Scene, variant: Variant, last: u32) -> Frame {
    render_fsi_checked(ctx, scene, variant, FsiCheck::None, last)
}

fn render_fsi_checked(
    ctx: &GpuContext,
    scene: &Scene,
    variant: Variant,
    check: FsiCheck,
    last: u32,
) -> Frame {
    let gpu = SceneGpu::new(ctx, scene).unwrap();
    let mut options = MethodOptions::default();
    options.fsi.fsi_check = check;
    let mut fsi = Fsi::new(&gpu, scene, &options.fsi, 1, variant);
    let target = RenderTarget::new(&ctx.device, "test target", scene.width, scene.height);
    let readback = TextureReadback::color(&ctx.device, "test read-back", scene.width, scene.height);
    let mut driver = FrameDriver::new(scene);
    for f in 0..=last {
        driver.advance(f);
        gpu.write_camera(&scene.camera(f));
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        fsi.encode(&gpu, &driver.input(f), &mut encoder, &target);
        if f == last {
            readback.encode_copy(&mut encoder, &target);
        }
        ctx.queue.submit([encoder.finish()]);
        ctx.wait_idle().unwrap();
    }
    ctx.check_errors().unwrap();
    let out = readback.read(ctx).unwrap();
    let [b0, b1] = fsi.read_lod_buffers(ctx).unwrap();
    let (newer, older) = if last.is_multiple_of(2) {
        (b0, b1)
    } else {
        (b1, b0)
    };
    let reproject = match variant {
        Variant::Sequential | Variant::Blend if last > 0 => {
            reprojection(&scene.camera(last), &scene.camera(last - 1))
        }
        _ => Mat4::IDENTITY,
    };
    let forward = (variant == Variant::Sequential && check == FsiCheck::Forward && last > 0)
        .then(|| reprojection(&scene.camera(last - 1), &scene.camera(last)));
    Frame {
        out,
        newer,
        older,
        reproject,
        forward,
        blend: variant == Variant::Blend,
    }
}

fn linear_to_srgb(c: f64) -> f32 {
    let s = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0) as f32
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Case {
    /// Newer colour because the pixel reprojects outside the older buffer.
    Outside,
    BothN,
    Average,
    NewerCloser,
    OlderCloser,
    /// `--fsi-check forward`: no older fragment found that reprojects into the pixel; the newer colour.
    NoMatch,
    /// `fsi-blend`: a t-instance in either buffer; the two colours mixed by its LOD's weight.
    Blend,
}

/// Where pixel position (x, y) of one frame at `depth` lies in the other by the clip-to-clip matrix `m`, in
/// pixels; None behind the camera.
fn map_pixel(m: Mat4, x: f32, y: f32, depth: f32, w: u32, h: u32) -> Option<(f32, f32, f32)> {
    let ndc = Vec4::new(
        x / w as f32 * 2.0 - 1.0,
        1.0 - y / h as f32 * 2.0,
        depth,
        1.0,
    );
    let c = m * ndc;
    if c.w <= 0.0 {
        return None;
    }
    let o = c.truncate() / c.w;
    Some((
        (o.x + 1.0) * 0.5 * w as f32,
        (1.0 - o.y) * 0.5 * h as f32,
        o.z,
    ))
}

/// Within 1e-3 pixel of a pixel edge: floating-point rounding could put it on either side.
fn near_edge(v: f32) -> bool {
    (v - v.round()).abs() < 1e-3
}

/// `--fsi-check forward`: the older texel whose fragment, reprojected with its own depth by `m`, lands within a
/// pixel (in x and in y) of pixel `p`'s centre, searched from `q` by moving the lookup by the rounded miss, at
/// most 4 texels in all (the shader's FORWARD_STEPS and FORWARD_TOLERANCE). Outer None where rounding could go
/// either way.
fn forward_match(fr: &Frame, m: Mat4, p: (u32, u32), q: (u32, u32)) -> Option<Option<(u32, u32)>> {
    let (w, h) = (fr.older.width, fr.older.height);
    let centre = (p.0 as f32 + 0.5, p.1 as f32 + 0.5);
    let mut q = (q.0 as i64, q.1 as i64);
    for _ in 0..4 {
        let d = fr.older.depth[(q.1 * w as i64 + q.0) as usize];
        let Some((fx, fy, _)) = map_pixel(m, q.0 as f32 + 0.5, q.1 as f32 + 0.5, d, w, h) else {
            return Some(None);
        };
        let miss = (centre.0 - fx, centre.1 - fy);
        // Near the tolerance or a rounding boundary of the miss, the GPU may go either way.
        let unsure = |v: f32| (v.abs() - 1.0).abs() < 1e-3 || (v - v.floor() - 0.5).abs() < 1e-3;
        if unsure(miss.0) || unsure(miss.1) {
            return None;
        }
        if miss.0.abs() <= 1.0 && miss.1.abs() <= 1.0 {
            return Some(Some((q.0 as u32, q.1 as u32)));
        }
        q = (
            q.0 + miss.0.round_ties_even() as i64,
            q.1 + miss.1.round_ties_even() as i64,
        );
        if q.0 < 0 || q.1 < 0 || q.0 >= w as i64 || q.1 >= h as i64 {
            return Some(None);
        }
    }
    Some(None)
}

/// What the combination pass must write at pixel (x, y), by the paper: None where floating-point rounding
/// could honestly go either way (a reprojected position within 1e-3 pixel of a pixel edge, or two depths
/// within 1e-6).
fn expected(fr: &Frame, x: u32, y: u32, reproject: bool) -> Option<(Case, [f32; 3], (u32, u32))> {
    let (w, h) = (fr.newer.width, fr.newer.height);
    let p = (y * w + x) as usize;
    let cn = &fr.newer.color[p * 4..p * 4 + 3];
    let newer = [cn[0] as f32, cn[1] as f32, cn[2] as f32];
    let dn = fr.newer.depth[p];
    let (q, dn_old) = if reproject {
        let Some(px) = map_pixel(fr.reproject, x as f32 + 0.5, y as f32 + 0.5, dn, w, h) else {
            return Some((Case::Outside, newer, (x, y)));
        };
        if near_edge(px.0) || near_edge(px.1) {
            return None;
        }
        if px.0 < 0.0 || px.1 < 0.0 || px.0 >= w as f32 || px.1 >= h as f32 {
            return Some((Case::Outside, newer, (x, y)));
        }
        let q = (px.0.floor() as u32, px.1.floor() as u32);
        let q = match fr.forward {
            Some(m) => match forward_match(fr, m, (x, y), q)? {
                Some(q) => q,
                None => return Some((Case::NoMatch, newer, (x, y))),
            },
            None => q,
        };
        (q, px.2)
    } else {
        ((x, y), dn)
    };
    let qi = (q.1 * w + q.0) as usize;
    let co = &fr.older.color[qi * 4..qi * 4 + 3];
    let older = [co[0] as f32, co[1] as f32, co[2] as f32];
    let (idn, ido) = (fr.newer.id[p], fr.older.id[qi]);
    if idn == 0 && ido == 0 {
        return Some((Case::BothN, newer, q));
    }
    if fr.blend {
        // The weight of the newer buffer's t-instance LOD (its alpha byte), else 1 - the older one's.
        let (an, ao) = (
            fr.newer.color[p * 4 + 3] as f64 / 255.0,
            fr.older.color[qi * 4 + 3] as f64 / 255.0,
        );
        let w = if idn != 0 { an } else { 1.0 - ao };
        let mix = |i: usize| {
            linear_to_srgb((1.0 - w) * srgb_to_linear(co[i]) + w * srgb_to_linear(cn[i]))
        };
        return Some((Case::Blend, [mix(0), mix(1), mix(2)], q));
    }
    if idn == ido {
        let avg = |i: usize| linear_to_srgb(0.5 * (srgb_to_linear(cn[i]) + srgb_to_linear(co[i])));
        return Some((Case::Average, [avg(0), avg(1), avg(2)], q));
    }
    let d_old = fr.older.depth[qi];
    if (d_old - dn_old).abs() < 1e-6 {
        return None;
    }
    if d_old < dn_old {
        Some((Case::OlderCloser, older, q))
    } else {
        Some((Case::NewerCloser, newer, q))
    }
}

/// Per pixel (row by row) its case and the older texel it read; None where [`expected`] skips the pixel.
type Lookups = Vec<Option<(Case, (u32, u32))>>;

/// Checks every pixel of the GPU's combined frame against [`expected`]: exact for copied pixels, within 1 of
/// 255 for averaged ones. Returns how often each case occurred and the [`Lookups`].
fn check_combination(fr: &Frame, reproject: bool) -> (Vec<(Case, usize)>, Lookups) {
    let (w, h) = (fr.newer.width, fr.newer.height);
    let mut counts: Vec<(Case, usize)> = Vec::new();
    let mut lookups = Vec::with_capacity((w * h) as usize);
    let mut bad = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let Some((case, want, q)) = expected(fr, x, y, reproject) else {
                lookups.push(None);
                continue;
            };
            lookups.push(Some((case, q)));
            let p = ((y * w + x) * 4) as usize;
            let got = &fr.out[p..p + 3];
            let tol = if matches!(case, Case::Average | Case::Blend) {
                1.0
            } else {
                0.0
            };
            if (0..3).any(|i| (got[i] as f32 - want[i]).abs() > tol + 1e-3) {
                bad.push((x, y, case, got.to_vec(), want));
            }
            match counts.iter_mut().find(|(c, _)| *c == case) {
                Some((_, n)) => *n += 1,
                None => counts.push((case, 1)),
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{} pixels differ from the paper's combination, first: {:?}",
        bad.len(),
        &bad[..bad.len().min(5)]
    );
    (counts, lookups)
}

/// How many lookups read another texel than the pixel's own (q != p).
fn moved(lookups: &Lookups, width: u32) -> usize {
    let own = |i: usize| (i as u32 % width, i as u32 / width);
    lookups
        .iter()
        .enumerate()
        .filter(|(i, l)| l.is_some_and(|(_, q)| q != own(*i)))
        .count()
}

fn count(counts: &[(Case, usize)], case: Case) -> usize {
    counts
        .iter()
        .find(|(c, _)| *c == case)
        .map_or(0, |(_, n)| *n)
}

fn is_background(c: &[u8]) -> bool {
    let bg = [60u8, 63, 69];
    (0..3).all(|i| c[i].abs_diff(bg[i]) <= 2)
}

/// (a) Frames with no instance in transition, in that frame and the one before (whose buffer FSI still
/// reads), are bit-identical to `discrete`, with a moving camera too.
#[test]
fn a_no_transition_frames_match_discrete_bit_for_bit() {
    let ctx = crate::common::gpu();
    for camera in ["fixed", "orbit"] {
        let cfg = scene_cfg(
            "bunny-sweep",
            &[
                "--width",
                "160",
                "--height",
                "120",
                "--frames",
                "160",
                "--switch-distances",
                "12,16,20",
                "--camera",
                camera,
            ],
        );
        let scene = SceneDef::new(SceneKind::BunnySweep, &cfg)
            .unwrap()
            .instantiate(1);
        let mut block =
            BlockRunner::new(&ctx, &scene, Default::default(), true, &Default::default()).unwrap();
        let mut frames = std::collections::HashMap::new();
        for method in ["discrete", "fsi"] {
            let out = block
                .run_method(method, 0, 1, &ProgressBar::hidden(), |f, img| {
                    frames.insert((method, f), img.method.to_vec());
                    Ok(())
                })
                .unwrap();
            if method == "fsi" {
                let t: Vec<u32> = out.rows.iter().map(|r| r.t_instances).collect();
                let steady: Vec<u32> = (1..scene.frames)
                    .filter(|&f| t[f as usize] == 0 && t[f as usize - 1] == 0)
                    .collect();
                let moving: Vec<u32> = (0..scene.frames).filter(|&f| t[f as usize] > 0).collect();
                assert!(steady.len() > 20 && moving.len() > 10, "{camera}: {t:?}");
                for f in &steady {
                    assert!(
                        frames[&("fsi", *f)] == frames[&("discrete", *f)],
                        "{camera}: frame {f} has no transition but differs from discrete"
                    );
                }
                // Not vacuous: frames in transition do differ.
                assert!(moving
                    .iter()
                    .any(|f| frames[&("fsi", *f)] != frames[&("discrete", *f)]));
            }
        }
    }
}

/// (b) Static camera and object at k = 0.5, where both LODs are complete (Fig. 2): wherever both LOD buffers
/// hold the object, the frame is the average of the two LOD colours (a cross-dissolve of red LOD0 and green
/// LOD1), to 1/255.
#[test]
fn b_half_way_is_a_cross_dissolve() {
    let ctx = crate::common::gpu();
    let d = near_distance();
    let scene = static_scene(&[d], [d, d * 1.5, d * 2.0], 3, "fixed");
    let fr = render_fsi(&ctx, &scene, Variant::Sequential, 2);
    let (counts, _) = check_combination(&fr, true);
    let n = (W * H) as usize;
    let mut both = 0;
    for p in 0..n {
        let (a, b) = (
            &fr.newer.color[p * 4..p * 4 + 3],
            &fr.older.color[p * 4..p * 4 + 3],
        );
        if is_background(a) || is_background(b) {
            continue;
        }
        both += 1;
        assert!(fr.newer.id[p] == 1 && fr.older.id[p] == 1);
        // One buffer holds red LOD0, the other green LOD1.
        let red = |c: &[u8]| c[0] > c[1];
        assert_ne!(red(a), red(b), "pixel {p}: both buffers show the same LOD");
        let o = &fr.out[p * 4..p * 4 + 3];
        for i in 0..3 {
            let want = linear_to_srgb(0.5 * (srgb_to_linear(a[i]) + srgb_to_linear(b[i])));
            assert!((o[i] as f32 - want).abs() <= 1.0 + 1e-3, "pixel {p}");
        }
    }
    assert!(both > 2000, "the bunny covers only {both} pixels in both");
    assert_eq!(count(&counts, Case::Average), both);
}

/// (c) A t-instance in front of an n-instance wins by depth, whichever buffer is newer: a near bunny at
/// k = 0.25 (LOD0 complete in one buffer, LOD1 stippled at tau = 0.5 in the other) in front of a far bunny
/// steady at LOD3.
#[test]
fn c_t_instance_in_front_wins_by_depth() {
    let ctx = crate::common::gpu();
    let d = near_distance();
    // Band 0.05: k = 0.25 at d = s (1 - 0.05 / 2).
    let s0 = d / (1.0 - 0.025);
    let scene = static_scene(&[d, d * 1.7], [s0, s0 * 1.2, s0 * 1.4], 4, "fixed");
    let mut older_won = 0;
    for last in [2, 3] {
        let fr = render_fsi(&ctx, &scene, Variant::Sequential, last);
        let (counts, _) = check_combination(&fr, true);
        // Pixels where one buffer shows the near t-instance and the other the far n-instance (yellow).
        let yellow = |c: &[u8]| c[0] > 3 * c[2] / 2 && c[1] > 3 * c[2] / 2;
        let mut won = 0;
        for p in 0..(W * H) as usize {
            let (n, o) = (fr.newer.id[p], fr.older.id[p]);
            let (cn, co) = (
                &fr.newer.color[p * 4..p * 4 + 4],
                &fr.older.color[p * 4..p * 4 + 4],
            );
            let out = &fr.out[p * 4..p * 4 + 4];
            if n == 1 && o == 0 && yellow(co) {
                assert_eq!(out, cn, "frame {last} pixel {p}: the far bunny won");
                won += 1;
            }
            if n == 0 && o == 1 && yellow(cn) {
                assert_eq!(out, co, "frame {last} pixel {p}: the far bunny won");
                won += 1;
            }
        }
        assert!(won > 100, "frame {last}: only {won} pixels tested");
        older_won += count(&counts, Case::OlderCloser);
    }
    // In one of the two frames the complete LOD0 is in the older buffer and wins over the newer buffer.
    assert!(older_won > 100, "{older_won}");
}

/// (d) With the camera orbiting, every pixel of the combined frame reads the older buffer where eq. 2 says
/// (P_old V_old V_new^-1 P_new^-1 applied to the pixel and its stored depth), checked against the CPU; and
/// the reprojection really moves lookups.
#[test]
fn d_reprojection_follows_equation_2() {
    let ctx = crate::common::gpu();
    let d = near_distance();
    let scene = static_scene(&[d], [d, d * 1.5, d * 2.0], 40, "orbit");
    // Frame 31: the eye moves about half a degree per frame around the bunny.
    let fr = render_fsi(&ctx, &scene, Variant::Sequential, 31);
    assert!(!fr.reproject.abs_diff_eq(Mat4::IDENTITY, 1e-4));
    let (counts, lookups) = check_combination(&fr, true);
    let n_moved = moved(&lookups, W);
    assert!(n_moved > 1000, "only {n_moved} lookups moved");
    assert!(count(&counts, Case::Average) > 1000, "{counts:?}");
    // A known pixel: the bunny's centre projects where eq. 2 maps it.
    let centre = scene.instance_position(0, 31).extend(1.0);
    let (new, old) = (scene.camera(31), scene.camera(30));
    let c_new = new.proj * new.view * centre;
    let c_old = old.proj * old.view * centre;
    let mapped = fr.reproject * (c_new / c_new.w);
    assert!((mapped / mapped.w - c_old / c_old.w).abs().max_element() < 1e-4);
    // And without reprojection the same frame reads the same pixel.
    let same = render_fsi(&ctx, &scene, Variant::NoReproject, 31);
    let (_, lookups) = check_combination(&same, false);
    assert_eq!(moved(&lookups, W), 0);
}

/// `--fsi-check forward` (not in the paper): the older fragment used is one that reprojects, with its own depth,
/// into the pixel, found from eq. 2's lookup by moving it by the miss. A near bunny in transition (k = 0.25) in
/// front of a far one that the camera orbits: the near bunny moves a few pixels a frame across the view, so
/// eq. 2 back-projects the background it uncovers onto where it stood a frame ago (section 4.2's
/// disocclusion), and what is seen through eq. 1's holes (the bunny's own inside, drawn two-sided) onto another
/// part of it. Every pixel matches the CPU model; the search moves lookups (lavapipe: 747 at frame 3, 432 at
/// frame 4) and finds no fragment for some pixels. Since t-instances are two-sided the holes show the inside
/// rather than the background, whose depth misleads eq. 2 less: the search moved over 1,000 lookups a frame and
/// found the older LOD0 for over 3/4 of the holes plain eq. 2 fills with it when the holes showed background;
/// now 1,219 of 1,689 (the test asks 2/3).
#[test]
fn f_forward_check_finds_the_fragment_that_moved_here() {
    let ctx = crate::common::gpu();
    let d = near_distance();
    let s0 = d / (1.0 - 0.025);
    // Instance 0 (the orbit's centre) far at LOD3, instance 1 near, in the band of the first switch.
    let scene = static_scene(&[d * 3.0, d], [s0, s0 * 1.2, s0 * 1.4], 8, "orbit");
    // Frame 3's newer buffer holds the stippled LOD1, frame 4's the complete LOD0.
    for last in [3, 4] {
        let checked =
            render_fsi_checked(&ctx, &scene, Variant::Sequential, FsiCheck::Forward, last);
        let (with, checked_lookups) = check_combination(&checked, true);
        assert!(count(&with, Case::NoMatch) > 50, "frame {last}: {with:?}");
        let plain = render_fsi(&ctx, &scene, Variant::Sequential, last);
        let (without, plain_lookups) = check_combination(&plain, true);
        // The search found another texel than eq. 2's lookup for many pixels (the buffers are the same, so the
        // plain run's lookup is eq. 2's).
        let searched = checked_lookups
            .iter()
            .zip(&plain_lookups)
            .filter(|(a, b)| match (a, b) {
                (Some((case, q)), Some((_, q_eq2))) => *case != Case::NoMatch && q != q_eq2,
                _ => false,
            })
            .count();
        assert!(
            searched > 300,
            "frame {last}: the search moved {searched} lookups"
        );
        if last == 3 {
            // Most holes of the stippled LOD1 still show the older LOD0, found by the search.
            let (a, b) = (
                count(&with, Case::OlderCloser),
                count(&without, Case::OlderCloser),
            );
            assert!(b > 1000 && a > b * 2 / 3, "{with:?} against {without:?}");
        }
        // The buffers are the same; only the combination differs.
        assert!(plain.newer.color == checked.newer.color && plain.older.id == checked.older.id);
        assert!(plain.out != checked.out);
    }
    // The other variants do not reproject, and ignore the check.
    let same = render_fsi_checked(&ctx, &scene, Variant::NoReproject, FsiCheck::Forward, 3);
    let plain = render_fsi(&ctx, &scene, Variant::NoReproject, 3);
    assert!(same.out == plain.out);
}

/// Section 4.1: the triangle count stays even between frames. Eight static bunnies in the transition bands of
/// all three switches, as many LOD pairs as possible toggling from the first frame: their phases are balanced,
/// so after that first frame (which renders both LOD buffers) the triangle count changes by less than the
/// paper's 2 % between consecutive frames. Starting them all at the same phase would change it by ~50 %.
#[test]
fn e_static_transitions_toggle_out_of_phase() {
    let ctx = crate::common::gpu();
    // All on the near side of their switch (k < 0.5): each starts with its finer LOD, so in step they would all
    // drop to the coarser one on the same frame.
    let distances = [9.6, 9.7, 9.8, 9.9, 19.4, 19.7, 38.5, 39.4];
    let scene = static_scene(&distances, [10.0, 20.0, 40.0], 6, "fixed");
    let mut block =
        BlockRunner::new(&ctx, &scene, Default::default(), true, &Default::default()).unwrap();
    let out = block
        .run_method("fsi", 0, 1, &ProgressBar::hidden(), |_, _| Ok(()))
        .unwrap();
    let tris: Vec<u64> = out.rows.iter().map(|r| r.triangles).collect();
    assert!(
        out.rows.iter().all(|r| r.t_instances == 8),
        "every bunny in transition: {:?}",
        out.rows.iter().map(|r| r.t_instances).collect::<Vec<_>>()
    );
    // The warm-up replays frame 0 as the previous frame, so the first timed frame draws one LOD buffer like the
    // rest (it drew the scene twice before).
    assert!(tris[0] < tris[1] * 3 / 2, "{tris:?}");
    let alternation = lodbench::measure::records::tri_alternation_max(&out.rows);
    assert!(alternation < 0.02, "{alternation} {tris:?}");
}

/// `--vis-space world` (claim F27): the visibility texture looked up at the world-space position. On windmills,
/// whose instances are placed away from the origin, the two lookups keep different fragments on frames that
/// combine a transition's LOD buffers (a transition frame, or the frame after one, whose older buffer is of the
/// transition) and give the same frames elsewhere. Looking up the object-space position in both entry points
/// (tried) fails the first check. (On bunny-sweep the bunny's transform is the identity: the lookups agree.)
#[test]
fn g_world_space_lookup_changes_only_transition_frames() {
    let dir = tempfile::tempdir().unwrap();
    let run = |space: &str| {
        let out = crate::common::run_into(
            &dir.path().join(space),
            &[
                "--scene",
                "windmills",
                "--profile",
                "regress",
                "--frames",
                "48",
                "--method",
                "fsi",
                "--vis-space",
                space,
            ],
        );
        crate::common::read_csv(&out.join("frames.csv"))
    };
    let (object, world) = (run("object"), run("world"));
    let in_transition: Vec<bool> = object.iter().map(|r| r["t_instances"] != "0").collect();
    let mut differ = 0;
    for (f, (a, b)) in object.iter().zip(&world).enumerate() {
        if a["rmse"] != b["rmse"] {
            differ += 1;
            let combined = in_transition[f] || (f > 0 && in_transition[f - 1]);
            assert!(combined, "frame {f} differs away from a transition");
        }
    }
    assert!(differ > 0, "no frame differs");
}

/// (h) `fsi-blend` (frame-sequential blending, claim F28): the two LOD buffers hold complete LODs (no visibility
/// texture: no pixel of a t-instance is discarded) and every pixel with a t-instance in either buffer is the two
/// colours mixed by the LOD's weight, k for the incoming LOD and 1 - k for the outgoing one, checked against the
/// CPU pixel by pixel: the near bunny at k = 0.25 in front of a far one at LOD3, on two consecutive frames.
#[test]
fn h_frame_sequential_blending_mixes_by_k() {
    let ctx = crate::common::gpu();
    let d = near_distance();
    let s0 = d / (1.0 - 0.025);
    let scene = static_scene(&[d, d * 1.7], [s0, s0 * 1.2, s0 * 1.4], 4, "fixed");
    for last in [2, 3] {
        let fr = render_fsi(&ctx, &scene, Variant::Blend, last);
        let (counts, _) = check_combination(&fr, true);
        assert!(count(&counts, Case::Blend) > 2000, "{counts:?}");
        // The weights the buffers carry: 0.25 for LOD1 (incoming), 0.75 for LOD0, in whichever buffer.
        let mut weights: Vec<u8> = (0..(W * H) as usize)
            .filter(|&p| fr.newer.id[p] == 1)
            .map(|p| fr.newer.color[p * 4 + 3])
            .collect();
        weights.dedup();
        assert_eq!(
            weights.len(),
            1,
            "one LOD, one weight: {:?}",
            &weights[..weights.len().min(4)]
        );
        assert!([64u8, 191].contains(&weights[0]), "{}", weights[0]);
    }
}
