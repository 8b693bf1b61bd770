//! LOD switches in each engine's own units (`lodbench tune`'s `engines/` folder): a model's switch distances (from
//! its bounding sphere's centre) and blend bands (half-widths as fractions of the switch distance) written as Unity
//! LODGroup, Unreal, Godot, Bevy and three.js settings, and read back from them. The formulas (docs/methods.md,
//! "Choosing thresholds: lodbench tune"):
//!
//! - A sphere of radius r at distance d, seen with vertical field of view `fov_y`, has the screen size
//!   `r / (d tan(fov_y / 2))`: its projected diameter over the viewport's height.
//! - **Unreal** (a mesh's `ScreenSize` per LOD): its `ComputeBoundsScreenSize` is `2 max(P00, P11) / 2 x r / d`,
//!   which for a viewport wider than high is the screen size above. LOD k (k >= 1) starts below
//!   `screen size(s_k)`; LOD0's is 1.
//! - **Unity** (a LODGroup's `screenRelativeTransitionHeight` and `fadeTransitionWidth` per LOD, with the group's
//!   `size` set to the sphere's diameter 2r and `lodBias` 1): its relative height `size / 2 / (d tan(fov / 2))` is
//!   the screen size. LOD k is left below `screen size(s_(k+1) (1 + b))`, the far end of the band; its cross-fade
//!   zone, a share of its range of heights from that end, reaches `screen size(s_(k+1) (1 - b))`:
//!   `fade = (h(s (1 - b)) - h_k) / (h_(k-1) - h_k)` (h_(-1) = 1). The last LOD's height is 0: never culled.
//! - **Godot** (a node per LOD, `visibility_range_begin` / `_end` and their margins, distances to the node's AABB
//!   centre): LOD k's range is `s_k` to `s_(k+1)` with margins `b s` (0 where no band), the fade mode `Self`
//!   where there is a band; LOD0's begin and the last LOD's end are 0 (open). Godot
//!   (`RendererSceneCull::_visibility_range_check`) draws a node from `begin - margin` to `end + margin` and fades
//!   it over `end - margin .. end + margin` (and `begin - margin .. begin + margin`): the band `s (1 - b) ..
//!   s (1 + b)`, both LODs drawn across it.
//! - **Bevy** (`VisibilityRange` per LOD entity: `start_margin` and `end_margin`, ranges of distance over which it
//!   fades in and out): LOD k's `start_margin` is `s_k (1 - b) .. s_k (1 + b)` and its `end_margin` the next
//!   switch's (LOD0 starts at `0..0`, the last LOD ends never).
//! - **three.js** (`LOD.addLevel(object, distance)`, the distance to the LOD object's own position): LOD k at `s_k`
//!   (LOD0 at 0), each level offset by minus the sphere's centre so the LOD object stands at the centre; three.js
//!   does not blend, so the bands are not written (its `hysteresis` stays 0).

use serde::{Deserialize, Serialize};

/// A model's switches as `lodbench tune` chose them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EngineModel {
    pub name: String,
    /// Bounding-sphere radius (world units) and centre (model space): every distance is from that centre.
    pub radius: f32,
    pub center: [f32; 3],
    /// Switch distance to LOD 1, 2, ... (the LODs past a switch that was never within the budget are left out).
    pub switches: Vec<f32>,
    /// Per switch, the blend band's half-width as a fraction of its distance (0: a hard switch).
    pub bands: Vec<f32>,
    /// Triangles of LOD 0, 1, ... of the chain the switches are for (the usable LODs).
    #[serde(default)]
    pub triangles: Vec<u32>,
}

pub use crate::geometry::projection::{distance_of, screen_size};

/// Unreal: `ScreenSize` per LOD (LOD0 first).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnrealLods {
    pub name: String,
    pub screen_size: Vec<f32>,
}

pub fn unreal(m: &EngineModel, fov_y: f32) -> UnrealLods {
    UnrealLods {
        name: m.name.clone(),
        screen_size: std::iter::once(1.0)
            .chain(m.switches.iter().map(|&d| screen_size(m.radius, d, fov_y)))
            .collect(),
    }
}

pub fn from_unreal(u: &UnrealLods, radius: f32, fov_y: f32) -> Vec<f32> {
    u.screen_size[1..]
        .iter()
        .map(|&s| distance_of(radius, s, fov_y))
        .collect()
}

/// Unity: a LODGroup's `size` and, per LOD, `screenRelativeTransitionHeight` and `fadeTransitionWidth`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnityLodGroup {
    pub name: String,
    pub size: f32,
    pub fade_mode: String,
    pub lods: Vec<UnityLod>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnityLod {
    #[serde(rename = "screenRelativeTransitionHeight")]
    pub height: f32,
    #[serde(rename = "fadeTransitionWidth")]
    pub fade: f32,
}

pub fn unity(m: &EngineModel, fov_y: f32) -> UnityLodGroup {
    let h = |d: f32| screen_size(m.radius, d, fov_y);
    let n = m.switches.len();
    let mut lods = Vec::with_capacity(n + 1);
    let mut above = 1.0f32;
    for k in 0..=n {
        let (height, fade) = match m.switches.get(k) {
            Some(&s) => {
                let b = m.bands.get(k).copied().unwrap_or(0.0);
                let low = h(s * (1.0 + b));
                let high = h(s * (1.0 - b));
                let fade = if above > low {
                    ((high - low) / (above - low)).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (low, fade)
            }
            None => (0.0, 0.0),
        };
        lods.push(UnityLod { height, fade });
        above = height;
    }
    UnityLodGroup {
        name: m.name.clone(),
        size: 2.0 * m.radius,
        fade_mode: if m.bands.iter().any(|&b| b > 0.0) {
            "CrossFade".into()
        } else {
            "None".into()
        },
        lods,
    }
}

/// The switches and bands of a LODGroup written by [`unity`].
pub fn from_unity(u: &UnityLodGroup, fov_y: f32) -> (Vec<f32>, Vec<f32>) {
    let r = u.size * 0.5;
    let mut above = 1.0f32;
    let (mut switches, mut bands) = (Vec::new(), Vec::new());
    for lod in &u.lods[..u.lods.len().saturating_sub(1)] {
        let far = distance_of(r, lod.height, fov_y);
        let near = distance_of(r, lod.height + lod.fade * (above - lod.height), fov_y);
        switches.push((far + near) * 0.5);
        bands.push((far - near) / (far + near));
        above = lod.height;
    }
    (switches, bands)
}

/// Godot: a node per LOD with its visibility range.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GodotNode {
    pub lod: usize,
    pub visibility_range_begin: f32,
    pub visibility_range_begin_margin: f32,
    pub visibility_range_end: f32,
    pub visibility_range_end_margin: f32,
    /// 0 Disabled, 1 Self.
    pub visibility_range_fade_mode: u32,
}

pub fn godot(m: &EngineModel) -> Vec<GodotNode> {
    let edge = |k: usize| -> (f32, f32) {
        match m.switches.get(k) {
            Some(&s) => {
                let b = m.bands.get(k).copied().unwrap_or(0.0);
                (s, b * s)
            }
            None => (0.0, 0.0),
        }
    };
    let fade = u32::from(m.bands.iter().any(|&b| b > 0.0));
    (0..=m.switches.len())
        .map(|k| {
            let (begin, begin_margin) = if k == 0 { (0.0, 0.0) } else { edge(k - 1) };
            let (end, end_margin) = edge(k);
            GodotNode {
                lod: k,
                visibility_range_begin: begin,
                visibility_range_begin_margin: begin_margin,
                visibility_range_end: end,
                visibility_range_end_margin: end_margin,
                visibility_range_fade_mode: fade,
            }
        })
        .collect()
}

pub fn from_godot(nodes: &[GodotNode]) -> (Vec<f32>, Vec<f32>) {
    nodes[..nodes.len().saturating_sub(1)]
        .iter()
        .map(|n| {
            let s = n.visibility_range_end;
            (s, n.visibility_range_end_margin / s)
        })
        .unzip()
}

/// Bevy: `VisibilityRange` per LOD entity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BevyRange {
    pub lod: usize,
    pub start_margin: [f32; 2],
    /// `[f32::MAX, f32::MAX]` for the last LOD (never ends).
    pub end_margin: [f32; 2],
}

pub fn bevy(m: &EngineModel) -> Vec<BevyRange> {
    let margin = |k: usize| -> [f32; 2] {
        match m.switches.get(k) {
            Some(&s) => {
                let b = m.bands.get(k).copied().unwrap_or(0.0);
                [s * (1.0 - b), s * (1.0 + b)]
            }
            None => [f32::MAX, f32::MAX],
        }
    };
    (0..=m.switches.len())
        .map(|k| BevyRange {
            lod: k,
            start_margin: if k == 0 { [0.0, 0.0] } else { margin(k - 1) },
            end_margin: margin(k),
        })
        .collect()
}

pub fn from_bevy(ranges: &[BevyRange]) -> (Vec<f32>, Vec<f32>) {
    ranges[..ranges.len().saturating_sub(1)]
        .iter()
        .map(|r| {
            let [lo, hi] = r.end_margin;
            ((lo + hi) * 0.5, (hi - lo) / (hi + lo))
        })
        .unzip()
}

/// The table of models in threejs-lod.js, between these two lines.
const THREE_TABLE_START: &str = "const lodbenchModels = ";
const THREE_TABLE_END: &str = "; // end of lodbenchModels";

/// three.js: a script that builds a `THREE.LOD` per model with `LOD.addLevel(object, distance)` (LOD0 at 0),
/// runnable as a classic script in a page (it defines `lodbenchModels` and `lodbenchLod`) and with Node's
/// `require`. three.js measures a LOD's distance from the LOD object's world position, lodbench's from the
/// model's bounding-sphere centre: `lodbenchLod` wraps each level in a group moved by minus the centre, so the LOD
/// object's position is that centre. `header`: comment lines on what the distances are for.
pub fn threejs(models: &[EngineModel], header: &[String]) -> String {
    let table: serde_json::Map<String, serde_json::Value> = models
        .iter()
        .map(|m| {
            let distances: Vec<f32> = std::iter::once(0.0)
                .chain(m.switches.iter().copied())
                .collect();
            let entry = serde_json::json!({
                "center": m.center,
                "radius": m.radius,
                "triangles": m.triangles,
                "distances": distances,
            });
            (m.name.clone(), entry)
        })
        .collect();
    let mut out: String = header.iter().map(|l| format!("// {l}\n")).collect();
    out.push_str(&format!(
        "{THREE_TABLE_START}{}{THREE_TABLE_END}\n",
        serde_json::to_string_pretty(&table).unwrap_or_default()
    ));
    out.push_str(
        r#"
// A THREE.LOD of the model `name` from its levels (three.js objects, LOD0 first, in the model's own space):
// each level is put in a group moved by minus the model's bounding-sphere centre, so the LOD object stands at
// that centre and three.js measures its distances from where lodbench did. Place the returned object where the
// model's centre goes (the model's position plus its centre, scaled and turned as the model is).
function lodbenchLod(THREE, name, levels) {
  const model = lodbenchModels[name];
  if (!model) throw new Error(`lodbenchLod: no model ${name}: ${Object.keys(lodbenchModels).join(", ")}`);
  if (levels.length < model.distances.length) {
    throw new Error(`lodbenchLod: ${name} needs ${model.distances.length} levels, got ${levels.length}`);
  }
  const lod = new THREE.LOD();
  model.distances.forEach((distance, k) => {
    const group = new THREE.Group();
    group.position.set(-model.center[0], -model.center[1], -model.center[2]);
    group.add(levels[k]);
    lod.addLevel(group, distance);
  });
  return lod;
}

if (typeof module !== "undefined") module.exports = { lodbenchModels, lodbenchLod };
"#,
    );
    out
}

/// The switch distances per model of a script written by [`threejs`] (LOD0's 0 left out), in its order.
pub fn from_threejs(script: &str) -> Option<Vec<(String, Vec<f32>)>> {
    let start = script.find(THREE_TABLE_START)? + THREE_TABLE_START.len();
    let end = script[start..].find(THREE_TABLE_END)? + start;
    let table: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(&script[start..end]).ok()?;
    table
        .iter()
        .map(|(name, m)| {
            let d: Vec<f32> = m["distances"]
                .as_array()?
                .iter()
                .map(|x| x.as_f64().map(|x| x as f32))
                .collect::<Option<_>>()?;
            Some((name.clone(), d.into_iter().skip(1).collect()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> EngineModel {
        EngineModel {
            name: "helmet".into(),
            radius: 0.8,
            center: [0.0, 0.1, 0.0],
            switches: vec![3.0, 6.5, 14.0],
            bands: vec![0.05, 0.1, 0.0],
            triangles: vec![1000, 500, 250, 125],
        }
    }

    fn close(a: &[f32], b: &[f32]) -> bool {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| (x - y).abs() <= 1e-4 * x.abs().max(1e-3))
    }

    /// Every engine's settings read back as the switches (and, where the engine blends, the bands) they were
    /// written from.
    #[test]
    fn every_conversion_round_trips() {
        let m = model();
        let fov = 60f32.to_radians();
        assert!(close(
            &from_unreal(&unreal(&m, fov), m.radius, fov),
            &m.switches
        ));
        let (s, b) = from_unity(&unity(&m, fov), fov);
        assert!(close(&s, &m.switches) && close(&b, &m.bands), "{s:?} {b:?}");
        let (s, b) = from_godot(&godot(&m));
        assert!(close(&s, &m.switches) && close(&b, &m.bands), "{s:?} {b:?}");
        let (s, b) = from_bevy(&bevy(&m));
        assert!(close(&s, &m.switches) && close(&b, &m.bands), "{s:?} {b:?}");
        let three =
            from_threejs(&threejs(std::slice::from_ref(&m), &[])).expect("the table reads back");
        assert_eq!(three.len(), 1);
        assert_eq!(three[0].0, m.name);
        assert!(close(&three[0].1, &m.switches));
    }

    /// The screen size is the projected diameter over the viewport's height: a unit sphere at distance d with a
    /// 90-degree field of view spans 1 / d of it; Unreal's LOD0 is 1, Unity's last LOD never culls.
    #[test]
    fn screen_sizes_are_projected_diameters() {
        let fov = 90f32.to_radians();
        assert!((screen_size(1.0, 4.0, fov) - 0.25).abs() < 1e-6);
        assert!((distance_of(1.0, 0.25, fov) - 4.0).abs() < 1e-5);
        let m = model();
        assert_eq!(unreal(&m, fov).screen_size[0], 1.0);
        let u = unity(&m, fov);
        assert_eq!(u.lods.len(), 4);
        assert_eq!(u.lods[3].height, 0.0);
        assert!(u.lods.windows(2).all(|w| w[1].height < w[0].height));
        let g = godot(&m);
        assert_eq!(
            (g[0].visibility_range_begin, g[3].visibility_range_end),
            (0.0, 0.0)
        );
    }

    /// Godot's visibility range as `_visibility_range_check` applies it with a fade mode: a node is drawn from
    /// `begin - margin` to `end + margin` and fading within a margin of either end. (drawn, fading).
    fn godot_state(n: &GodotNode, d: f32) -> (bool, bool) {
        let far = n.visibility_range_end > 0.0;
        let near = n.visibility_range_begin > 0.0;
        let drawn = (!far || d <= n.visibility_range_end + n.visibility_range_end_margin)
            && (!near || d >= n.visibility_range_begin - n.visibility_range_begin_margin);
        let fading = (far && d > n.visibility_range_end - n.visibility_range_end_margin)
            || (near && d < n.visibility_range_begin + n.visibility_range_begin_margin);
        (drawn, drawn && fading)
    }

    /// Godot's nodes cross-fade exactly over each band s (1 - b) .. s (1 + b): both LODs drawn and fading inside
    /// it, one LOD drawn and not fading outside.
    #[test]
    fn godot_fades_over_the_band() {
        let m = model();
        let nodes = godot(&m);
        for (k, (&s, &b)) in m.switches.iter().zip(&m.bands).enumerate() {
            let (lo, hi) = (s * (1.0 - b), s * (1.0 + b));
            let probes = if b > 0.0 {
                vec![lo * 0.99, lo * 1.01, s, hi * 0.99, hi * 1.01]
            } else {
                vec![s * 0.99, s * 1.01]
            };
            for d in probes {
                let a = godot_state(&nodes[k], d);
                let c = godot_state(&nodes[k + 1], d);
                if b > 0.0 && d > lo && d < hi {
                    assert!(
                        a == (true, true) && c == (true, true),
                        "LOD {k} at {d}: {a:?} {c:?}"
                    );
                } else if d <= lo || (b == 0.0 && d < s) {
                    assert!(a.0 && !c.0, "LOD {k} at {d}: {a:?} {c:?}");
                } else {
                    assert!(!a.0 && c.0, "LOD {k} at {d}: {a:?} {c:?}");
                }
            }
        }
    }
}
