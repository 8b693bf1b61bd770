//! Adding a method is one new file plus one registry line. This file is that new file: `LodTo`, a throwaway
//! method that draws every instance at its incoming LOD as soon as a transition starts (a discrete switch at
//! k = 0 instead of k = 0.5), written against the public method API only; the registry line is in
//! `registry_with_lod_to`. The run then measures it like any built-in method.

use crate::common::read_csv;

use lodbench::cli::run_config::RunConfig;
use lodbench::gpu::{DrawStats, RenderTarget, SceneGpu};
use lodbench::methods::{FrameInput, Method, MethodEntry, OpaqueInstances, Registry};
use lodbench::scene::Scene;
use std::collections::HashMap;

/// The throwaway method.
struct LodTo {
    instances: OpaqueInstances,
}

impl LodTo {
    fn new(gpu: &SceneGpu, scene: &Scene) -> Self {
        LodTo {
            instances: OpaqueInstances::new(gpu, scene, "lod-to instances"),
        }
    }
}

impl Method for LodTo {
    fn encode(
        &mut self,
        gpu: &SceneGpu,
        input: &FrameInput<'_>,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
    ) -> DrawStats {
        self.instances
            .encode(gpu, input, encoder, target, "lod-to pass", |s| s.lod_to)
    }
}

#[rustfmt::skip]
fn registry_with_lod_to() -> Registry {
    // The one registry line.
    Registry::builtin().with(MethodEntry { name: "lod-to", about: "switch at k = 0", create: |b| Ok(Box::new(LodTo::new(b.gpu, b.scene))), options: |_| None }).unwrap()
}

#[test]
fn a_method_added_with_one_registry_line_runs_like_a_builtin() {
    let registry = registry_with_lod_to();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let argv = [
        "--scene",
        "bunny-sweep",
        "--method",
        "discrete,lod-to",
        "--width",
        "64",
        "--height",
        "48",
        "--frames",
        "60",
        "--band",
        "0.2",
        "--out",
        out,
    ];
    let args = crate::common::run_args(&argv);
    // The built-in registry does not know the name; the extended one does.
    let err = RunConfig::from_args(&args).unwrap_err().to_string();
    assert!(err.contains("lod-to"), "{err}");
    let cfg = RunConfig::from_args_in(&args, &registry).unwrap();
    lodbench::commands::run::run_with(&cfg, &registry).unwrap();

    let rows = read_csv(&dir.path().join("frames.csv"));
    let of = |m: &str| -> Vec<&HashMap<String, String>> {
        rows.iter().filter(|r| r["method"] == m).collect()
    };
    let (discrete, lod_to) = (of("discrete"), of("lod-to"));
    assert_eq!(lod_to.len(), 60);
    assert_eq!(discrete.len(), 60);
    let mut before_midpoint = 0;
    for (d, t) in discrete.iter().zip(&lod_to) {
        if d["t_instances"] == "0" {
            // Outside transitions both draw the schedule's only LOD: the same image.
            assert_eq!(d["rmse"], t["rmse"], "frame {}", d["frame"]);
            assert_eq!(d["triangles"], t["triangles"], "frame {}", d["frame"]);
        } else if d["triangles"] != t["triangles"] {
            before_midpoint += 1;
        }
    }
    // In the first half of each transition discrete still shows lod_from and lod-to already lod_to.
    assert!(
        before_midpoint > 0,
        "no transition frame told the two apart"
    );
    // lod-to gives no answers of its own to the quality pass (no `Counterfactual`): lodpop's default
    // counterfactual draws its frame again with the states of the frame before, so it pops on the frames where
    // some lod_to changed, and as often as discrete, which switches once per transition too.
    let pops = |rows: &[&HashMap<String, String>]| {
        rows.iter()
            .filter(|r| r["lodpop"].parse::<f64>().unwrap() > 0.0)
            .count()
    };
    assert!(pops(&lod_to) > 0, "lod-to never popped");
    assert_eq!(pops(&lod_to), pops(&discrete));
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("run.json")).unwrap())
            .unwrap();
    assert_eq!(manifest["status"], "complete");
    assert!(manifest["blocks"]
        .as_array()
        .unwrap()
        .iter()
        .any(|b| b["method"] == "lod-to"));
}

#[test]
fn a_taken_name_is_refused() {
    let dup = Registry::builtin().with(MethodEntry {
        name: "discrete",
        about: "",
        create: |b| Ok(Box::new(LodTo::new(b.gpu, b.scene))),
        options: |_| None,
    });
    assert!(dup.is_err());
}
