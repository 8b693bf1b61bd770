//! Authored LOD chains: MSFT_lod on a node (its levels in the scene or not), and sibling nodes named
//! `NAME_LOD0`, `NAME_LOD1`, ... as Unity, Unreal and Godot importers name them. A level is its node and the
//! nodes below it (Microsoft's glTF-Toolkit writes MSFT_lod on root nodes whose levels are node hierarchies), so
//! that no caller merges the levels or draws a level's children at every distance.

use super::json::{array, index};
use super::nodes::Nodes;
use serde_json::Value;

/// Where an authored LOD chain was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChainSource {
    /// MSFT_lod on the LOD0 node (`ids`: the coarser levels' nodes).
    MsftLod,
    /// Sibling nodes named `NAME_LOD0`, `NAME_LOD1`, ...
    LodNames,
}

/// An authored LOD chain: one node per level, finest first; each level is that node and its descendants.
#[derive(Debug, Clone)]
pub struct AuthoredChain {
    pub source: ChainSource,
    /// The LOD0 node's name, or the names' common stem.
    pub name: String,
    pub nodes: Vec<usize>,
    /// MSFT_lod's `extras.MSFT_screencoverage` on the LOD0 node, when present.
    pub screen_coverage: Option<Vec<f64>>,
    /// `extras.lodbench_switch_distances` on the LOD0 node (what `lodbench export` writes): exact switch
    /// distances, preferred to the screen coverage.
    pub switch_distances: Option<Vec<f32>>,
    /// `extras.lodbench_spin_per_frame` (windmill blades' turn per frame, radians), 0 without it.
    pub spin_per_frame: f32,
}

/// `NAME_LODn` nodes grouped by (parent, stem): their (level, node) pairs.
type NameGroups = Vec<((Option<usize>, String), Vec<(u32, usize)>)>;

/// The authored LOD chains among the scene's nodes (none without scenes: every mesh is placed untransformed).
pub fn chains(json: &Value, nodes: &Nodes) -> Result<Vec<AuthoredChain>, String> {
    let all = array(json, "nodes");
    let mut out = Vec::new();
    if nodes.scene.is_none() {
        return Ok(out);
    }
    let in_scene = |n: usize| nodes.scene_order.contains(&n);
    for (n, node) in all.iter().enumerate() {
        let Some(ids) = node.pointer("/extensions/MSFT_lod/ids") else {
            continue;
        };
        if !in_scene(n) {
            continue;
        }
        let mut chain = vec![n];
        for id in ids.as_array().map_or(&[][..], Vec::as_slice) {
            let id = index(id, || format!("an MSFT_lod id of node {n}"), all.len())?;
            if chain.contains(&id) || all[id].pointer("/extensions/MSFT_lod").is_some() {
                return Err(format!(
                    "node {n}'s MSFT_lod lists node {id}, which is already a level of the chain or has a chain \
                     of its own (a cycle)"
                ));
            }
            chain.push(id);
        }
        let numbers = |key: &str| -> Result<Option<Vec<f64>>, String> {
            let Some(v) = node.pointer(&format!("/extras/{key}")) else {
                return Ok(None);
            };
            v.as_array()
                .and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>())
                .filter(|a| a.iter().all(|x| x.is_finite()))
                .map(Some)
                .ok_or_else(|| format!("node {n}'s extras.{key} is not an array of numbers"))
        };
        let screen_coverage = numbers("MSFT_screencoverage")?;
        let switch_distances =
            numbers("lodbench_switch_distances")?.map(|a| a.iter().map(|&d| d as f32).collect());
        out.push(AuthoredChain {
            source: ChainSource::MsftLod,
            name: node["name"].as_str().unwrap_or("").to_string(),
            nodes: chain,
            screen_coverage,
            switch_distances,
            spin_per_frame: node
                .pointer("/extras/lodbench_spin_per_frame")
                .and_then(Value::as_f64)
                .unwrap_or(0.0) as f32,
        });
    }
    // `NAME_LODn` siblings: group the scene's nodes by parent and stem.
    let mut groups: NameGroups = Vec::new();
    let in_msft: Vec<usize> = out.iter().flat_map(|c| c.nodes.iter().copied()).collect();
    for &n in &nodes.scene_order {
        if in_msft.contains(&n) {
            continue;
        }
        let Some((stem, level)) = lod_name(&nodes.names[n]) else {
            continue;
        };
        let key = (nodes.parent[n], stem.to_string());
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, levels)) => levels.push((level, n)),
            None => groups.push((key, vec![(level, n)])),
        }
    }
    for ((_, stem), mut levels) in groups {
        if levels.len() < 2 {
            continue;
        }
        levels.sort();
        if levels.windows(2).any(|w| w[0].0 == w[1].0) || levels[0].0 != 0 {
            return Err(format!(
                "the nodes named {stem}_LODn have levels {:?}: an authored chain needs LOD0 and each level once",
                levels.iter().map(|l| l.0).collect::<Vec<_>>()
            ));
        }
        out.push(AuthoredChain {
            source: ChainSource::LodNames,
            name: stem,
            nodes: levels.into_iter().map(|l| l.1).collect(),
            screen_coverage: None,
            switch_distances: None,
            spin_per_frame: 0.0,
        });
    }
    refuse_nested(nodes, &out)?;
    Ok(out)
}

/// A level holding another chain's level (one chain inside another's hierarchy) is refused: which of the two
/// chooses the geometry there has no answer in either convention.
fn refuse_nested(nodes: &Nodes, chains: &[AuthoredChain]) -> Result<(), String> {
    for (a, c) in chains.iter().enumerate() {
        for (b, d) in chains.iter().enumerate() {
            if a == b {
                continue;
            }
            for &level in &c.nodes {
                if let Some(&inner) = d
                    .nodes
                    .iter()
                    .find(|&&m| m != level && nodes.is_under(m, level))
                {
                    return Err(format!(
                        "LOD chain '{}': level node {level} holds node {inner}, a level of LOD chain '{}'; lodbench \
                         reads chains side by side, not one inside another's level",
                        c.name, d.name
                    ));
                }
            }
        }
    }
    Ok(())
}

/// `NAME_LOD3` (also `_lod3`, `-LOD3`): the stem and the level.
pub fn lod_name(name: &str) -> Option<(&str, u32)> {
    let lower = name.to_ascii_lowercase();
    let at = lower.rfind("lod")?;
    let level: u32 = lower[at + 3..].parse().ok()?;
    let stem = name[..at].strip_suffix(['_', '-'])?;
    (!stem.is_empty()).then_some((stem, level))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lod_names() {
        assert_eq!(lod_name("Rock_LOD0"), Some(("Rock", 0)));
        assert_eq!(lod_name("SM_Rock_lod12"), Some(("SM_Rock", 12)));
        assert_eq!(lod_name("tree-LOD2"), Some(("tree", 2)));
        assert_eq!(lod_name("LOD1"), None);
        assert_eq!(lod_name("Rock_LODx"), None);
        assert_eq!(lod_name("Melody"), None);
    }
}
