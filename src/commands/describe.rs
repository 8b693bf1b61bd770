//! `lodbench describe SCENE`: what a scene holds (models, LODs, switch distances, blocks, path), as text or
//! JSON.

use crate::cli::DescribeArgs;
use crate::error::Result;
use crate::scene::{SceneConfig, SceneDef, SceneDescription, SceneKind};

/// What every frame's camera shares: field of view, clip planes, viewport, the light and the ambient.
fn view_json(scene: &crate::scene::Scene) -> serde_json::Value {
    serde_json::json!({
        "fov_y_deg": scene.fov_y.to_degrees(),
        "near": scene.near,
        "far": scene.far,
        "width": scene.width,
        "height": scene.height,
        "light_direction": glam::Vec3::from(crate::gpu::LIGHT_DIR).normalize().to_array(),
        "ambient": crate::gpu::AMBIENT,
    })
}

/// Frame `f`'s camera: its eye, view matrix and projection matrix (column-major).
fn frame_camera(scene: &crate::scene::Scene, f: u32) -> serde_json::Map<String, serde_json::Value> {
    let c = scene.camera(f);
    let mut m = serde_json::Map::new();
    m.insert("eye".into(), serde_json::json!(c.eye.to_array()));
    m.insert("view".into(), serde_json::json!(c.view.to_cols_array()));
    m.insert(
        "projection".into(),
        serde_json::json!(c.proj.to_cols_array()),
    );
    m
}

/// Prints the description of the scene `args` name, with its flags.
pub fn execute(args: &DescribeArgs) -> Result<()> {
    let cfg = SceneConfig::from_args(&args.scene_args)?;
    let def = SceneDef::new(SceneKind::from_name(&args.scene)?, &cfg)?;
    if let Some(f) = args.camera_json {
        let scene = def.instantiate(def.counts[0]);
        if f >= scene.frames {
            return Err(crate::error::Error::Config(format!(
                "--camera-json {f}: the scene has {} frames (0..{})",
                scene.frames,
                scene.frames.saturating_sub(1)
            )));
        }
        let mut camera = view_json(&scene);
        camera["frame"] = serde_json::json!(f);
        if let Some(o) = camera.as_object_mut() {
            o.extend(frame_camera(&scene, f));
        }
        outln!("{}", serde_json::to_string_pretty(&camera)?);
        return Ok(());
    }
    if args.cameras_json {
        let scene = def.instantiate(def.counts[0]);
        let mut cameras = view_json(&scene);
        cameras["frames"] = (0..scene.frames)
            .map(|f| {
                let mut c = serde_json::Map::new();
                c.insert("frame".into(), serde_json::json!(f));
                c.extend(frame_camera(&scene, f));
                serde_json::Value::Object(c)
            })
            .collect();
        outln!("{}", serde_json::to_string(&cameras)?);
        return Ok(());
    }
    let d = match args.deviation {
        true => def.describe_with_deviation(&cfg),
        false => def.describe(&cfg),
    };
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&d)?);
        return Ok(());
    }
    outln!(
        "{}: profile {}, {}x{}, fov {} deg, {} frames, instance counts {:?}",
        d.scene,
        d.profile,
        d.width,
        d.height,
        crate::numbers::sig3(Some(d.fov_y_deg as f64)),
        d.frames,
        d.instance_counts
    );
    outln!("mesh: {}", d.mesh);
    if d.unified.is_some() {
        print_blocks(&d);
    } else {
        print_models(&d);
    }
    print_path(&d)
}

/// A unified scene: its blocks, seams and preprocessing.
fn print_blocks(d: &SceneDescription) {
    let Some(u) = &d.unified else {
        return;
    };
    let lods = d.models.iter().map(|m| m.lods.len()).max().unwrap_or(0);
    let per_lod: Vec<String> = (0..lods)
        .map(|l| {
            let t: usize = d
                .models
                .iter()
                .filter_map(|m| m.lods.get(l))
                .map(|x| x.info.triangles)
                .sum();
            format!("LOD{l} {t}")
        })
        .collect();
    outln!(
        "blocks: {} ({:?} grid of {:.3}-unit cubes, --partition {}), {} input triangles, {} in blocks; \
         triangles of all blocks per LOD: {}",
        u.blocks,
        u.grid,
        u.block_size,
        format!("{:?}", u.partition).to_lowercase(),
        u.input_triangles,
        u.block_triangles,
        per_lod.join(", ")
    );
    outln!(
        "seams: {} block pairs, {} edges, {} triangles over all LOD pairs",
        u.seam_pairs,
        u.seam_edges,
        u.seam_triangles_all_lod_pairs
    );
    outln!(
        "preprocessing: blocks {:.0} ms (partition {:.0}, LOD chains {:.0}, seams {:.0}), {:.1} MiB; \
         clusterlod {:.0} ms, {} clusters in {} groups, {} levels, {:.1} MiB",
        u.blocks_ms,
        u.partition_ms,
        u.lod_chains_ms,
        u.seams_ms,
        (u.blocks_bytes + u.seams_bytes) as f64 / (1 << 20) as f64,
        u.clusterlod_ms,
        u.clusters,
        u.cluster_groups,
        u.cluster_levels,
        u.clusterlod_bytes as f64 / (1 << 20) as f64
    );
    print_cut(d);
    print_hierarchy(d);
    outln!("(every block's LODs and switch distances: --json)");
}

/// The clusterlod cut along the camera path, where the description has one.
fn print_cut(d: &SceneDescription) {
    if let Some(c) = &d.cut {
        outln!(
            "clusterlod cut along the path (pixel error {}, {} frames, means): {:.0} triangles; of {:.0} groups with \
             a coarser version, {:.1} over the threshold, {:.1} of them with the camera inside their bounding sphere \
             (distance clamped to the near plane), {:.1} of those under it by the distance to the sphere's centre; \
             most at frame {}: {} of {} over",
            d.pixel_error,
            c.frames,
            c.triangles,
            c.groups,
            c.over,
            c.over_inside_sphere,
            c.over_only_by_sphere,
            c.worst_frame,
            c.worst.over_only_by_sphere,
            c.worst.over
        );
    }
}

/// The blocks-tree's levels, where the scene has one.
fn print_hierarchy(d: &SceneDescription) {
    if let Some(h) = &d.hierarchy {
        let levels: Vec<String> = h
            .levels
            .iter()
            .map(|l| {
                format!(
                    "level {}: {} nodes, {} triangles, error up to {:.4}",
                    l.level, l.nodes, l.triangles, l.error_max
                )
            })
            .collect();
        outln!(
            "blocks-tree: {} x {} leaves; {}; built in {:.0} ms",
            h.leaves,
            h.leaves,
            levels.join("; "),
            h.build_ms
        );
    }
}

/// Each model's LODs and switch distances.
fn print_models(d: &SceneDescription) {
    for m in &d.models {
        outln!(
            "model {} (radius {:.3}, {} instance{}, switch distances from {}):",
            m.name,
            m.radius,
            m.instances,
            if m.instances == 1 { "" } else { "s" },
            m.switch_source
        );
        if let Some([a, b]) = m.sizes {
            outln!(
                "  its instances are {a:.3} to {b:.3} times its size: each switches at that multiple of the \
                 distances below"
            );
        }
        let deviation = m.lods.iter().any(|l| l.deviation_max.is_some());
        outln!(
            "  {:>4} {:>10} {:>9} {:>14} {:>16}{}",
            "lod",
            "triangles",
            "vertices",
            "error_abs",
            "switch_distance",
            if deviation {
                format!(" {:>14} {:>14}", "deviation_max", "deviation_mean")
            } else {
                String::new()
            }
        );
        for l in &m.lods {
            let measured = match (l.deviation_max, l.deviation_mean) {
                (Some(a), Some(b)) => format!(" {a:>14.6} {b:>14.6}"),
                _ => String::new(),
            };
            outln!(
                "  {:>4} {:>10} {:>9} {:>14.6} {:>16}{measured}{}",
                l.info.lod,
                l.info.triangles,
                l.info.vertices,
                l.info.error_abs,
                l.switch_distance
                    .map_or("-".to_string(), |s| format!("{s:.3}")),
                l.note.map_or(String::new(), |n| format!("  ({n})"))
            );
        }
    }
}

/// The pixel error, the impostors' atlas, the camera path, the motion and the notes.
fn print_path(d: &SceneDescription) -> Result<()> {
    outln!("pixel error: {}", d.pixel_error);
    if let Some(imp) = &d.impostor {
        outln!(
            "impostor atlas: {}; {} model{}, {:.1} MiB in all; views at most {:.1} deg from a frame drawn",
            imp.line,
            imp.models,
            if imp.models == 1 { "" } else { "s" },
            imp.bytes as f64 / (1024.0 * 1024.0),
            imp.max_view_angle_deg
        );
    }
    let s = &d.schedule;
    outln!(
        "transitions: {}{}",
        match s.fade {
            crate::scene::schedule::FadeMode::Time =>
                format!("a time fade over {} frames", s.fade_frames),
            crate::scene::schedule::FadeMode::Distance => format!(
                "a distance fade over +-{} % of each switch distance",
                crate::numbers::sig3(Some(s.band as f64 * 100.0))
            ),
        },
        if s.hysteresis > 0.0 {
            format!(", hysteresis {}", s.hysteresis)
        } else {
            String::new()
        }
    );
    if let Some(p) = &d.path {
        outln!(
            "path: from {:.3} to {:.3} (the bounding sphere fits the view from {:.3})",
            p.near,
            p.far,
            p.fit
        );
    }
    if let Some(u) = &d.user {
        outln!(
            "instances: {} of {} models; camera: {}",
            u.instance_count,
            d.models.len(),
            u.camera_source
        );
        for c in &u.chains {
            outln!(
                "authored LOD chain {} ({}, {} levels): switch distances from {}",
                c.model,
                c.source,
                c.levels,
                c.thresholds
            );
        }
    }
    outln!("motion: {}", serde_json::to_string(&d.motion)?);
    for n in &d.notes {
        outln!("note: {n}");
    }
    Ok(())
}
