//! The node hierarchy (glTF 2.0 section 3.5): every node's local transform and parent, the scene's nodes, their
//! world matrices at rest or under an animation's local transforms, and the mesh placements of the scene (a node's
//! mesh, once per EXT_mesh_gpu_instancing instance).

use super::accessors::Doc;
use super::json::{array, float_list, floats, index, opt_index};
use glam::{Mat4, Quat, Vec3};
use serde_json::Value;

/// A node's local transform as the file gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Local {
    Matrix(Mat4),
    Trs { t: Vec3, r: Quat, s: Vec3 },
}

impl Local {
    pub fn matrix(&self) -> Mat4 {
        match *self {
            Local::Matrix(m) => m,
            Local::Trs { t, r, s } => Mat4::from_scale_rotation_translation(s, r, t),
        }
    }

    /// Translation, rotation and scale (a matrix decomposed: glTF forbids animating a node given by one, so
    /// this is only read for nodes an invalid file animates anyway).
    pub fn trs(&self) -> (Vec3, Quat, Vec3) {
        match *self {
            Local::Matrix(m) => {
                let (s, r, t) = m.to_scale_rotation_translation();
                (t, r, s)
            }
            Local::Trs { t, r, s } => (t, r, s),
        }
    }
}

/// Every node of the file: local transforms, parents, children, names; and the scene read.
#[derive(Debug, Clone)]
pub struct Nodes {
    pub local: Vec<Local>,
    pub parent: Vec<Option<usize>>,
    pub children: Vec<Vec<usize>>,
    pub names: Vec<String>,
    /// The scene read (`scene`, else scene 0); None when the file has no scenes.
    pub scene: Option<usize>,
    /// The scene's nodes depth first in document order (empty without scenes).
    pub scene_order: Vec<usize>,
    /// Every node reachable from a root (a node without a parent), parents before children: the order world
    /// matrices are computed in.
    order: Vec<usize>,
    /// The scene's root nodes.
    scene_roots: Vec<usize>,
}

/// A node's local transform (its `matrix`, or translation, rotation, scale).
fn local(node: &Value) -> Result<Local, String> {
    if let Some(m) = floats::<16>(&node["matrix"], "a node's matrix")? {
        return Ok(Local::Matrix(Mat4::from_cols_array(&m)));
    }
    let t = floats::<3>(&node["translation"], "a node's translation")?.unwrap_or([0.0; 3]);
    let r = floats::<4>(&node["rotation"], "a node's rotation")?.unwrap_or([0.0, 0.0, 0.0, 1.0]);
    let s = floats::<3>(&node["scale"], "a node's scale")?.unwrap_or([1.0; 3]);
    Ok(Local::Trs {
        t: Vec3::from(t),
        r: Quat::from_array(r).normalize(),
        s: Vec3::from(s),
    })
}

impl Nodes {
    /// Reads every node, the hierarchy (a tree: each node has at most one parent and is not its own ancestor)
    /// and the scene.
    pub fn read(json: &Value) -> Result<Nodes, String> {
        let all = array(json, "nodes");
        let n = all.len();
        let mut parent = vec![None; n];
        let mut children = vec![Vec::new(); n];
        let mut locals = Vec::with_capacity(n);
        let mut names = Vec::with_capacity(n);
        for (i, node) in all.iter().enumerate() {
            locals.push(local(node).map_err(|e| format!("node {i}: {e}"))?);
            names.push(node["name"].as_str().unwrap_or("").to_string());
            for c in array(node, "children") {
                let c = index(c, || format!("a child of node {i}"), n)?;
                if let Some(p) = parent[c].replace(i) {
                    return Err(format!(
                        "node {c} is a child of nodes {p} and {i} (glTF node hierarchies must be trees)"
                    ));
                }
                children[i].push(c);
            }
        }
        let mut order = Vec::with_capacity(n);
        let mut stack: Vec<usize> = (0..n).filter(|&i| parent[i].is_none()).rev().collect();
        while let Some(i) = stack.pop() {
            order.push(i);
            stack.extend(children[i].iter().rev());
        }
        if order.len() < n {
            let stuck = (0..n).find(|i| !order.contains(i)).unwrap_or(0);
            return Err(format!(
                "node {stuck} is its own ancestor (glTF node hierarchies must be trees)"
            ));
        }
        let scenes = array(json, "scenes");
        let (mut scene, mut scene_order, mut scene_roots) = (None, Vec::new(), Vec::new());
        if !scenes.is_empty() {
            let s = match json.get("scene") {
                Some(v) => index(v, || "scene".into(), scenes.len())?,
                None => 0,
            };
            for v in array(&scenes[s], "nodes") {
                scene_roots.push(index(v, || format!("a node of scene {s}"), n)?);
            }
            let mut stack: Vec<usize> = scene_roots.iter().rev().copied().collect();
            let mut seen = vec![false; n];
            while let Some(i) = stack.pop() {
                if std::mem::replace(&mut seen[i], true) {
                    return Err(format!(
                        "node {i} is reached twice from scene {s} (glTF node hierarchies must be trees)"
                    ));
                }
                scene_order.push(i);
                stack.extend(children[i].iter().rev());
            }
            scene = Some(s);
        }
        Ok(Nodes {
            local: locals,
            parent,
            children,
            names,
            scene,
            scene_order,
            order,
            scene_roots,
        })
    }

    /// Every node's local matrix at rest.
    pub fn rest_locals(&self) -> Vec<Mat4> {
        self.local.iter().map(Local::matrix).collect()
    }

    /// World matrices of every node from their local matrices `locals`. The scene's nodes are placed from the
    /// scene's roots: a root the file also lists as another node's child stands where its own transform puts it
    /// (as three.js places it), the rest from the true roots.
    pub fn worlds(&self, locals: &[Mat4]) -> Vec<Mat4> {
        let mut world = vec![Mat4::IDENTITY; self.local.len()];
        let orders = [&self.order, &self.scene_order];
        for (pass, order) in orders.into_iter().enumerate() {
            for &i in order.iter() {
                world[i] = match self.parent[i] {
                    Some(p) if !(pass == 1 && self.scene_roots.contains(&i)) => {
                        world[p] * locals[i]
                    }
                    _ => locals[i],
                };
            }
        }
        world
    }

    /// `node` and its descendants, depth first, each with its transform relative to `node` (identity for it).
    pub fn subtree(&self, node: usize) -> Vec<(usize, Mat4)> {
        let mut out = Vec::new();
        let mut stack = vec![(node, Mat4::IDENTITY)];
        while let Some((i, m)) = stack.pop() {
            out.push((i, m));
            for &c in self.children[i].iter().rev() {
                stack.push((c, m * self.local[c].matrix()));
            }
        }
        out
    }

    /// Whether `node` is `ancestor` or below it.
    pub fn is_under(&self, mut node: usize, ancestor: usize) -> bool {
        loop {
            if node == ancestor {
                return true;
            }
            match self.parent[node] {
                Some(p) => node = p,
                None => return false,
            }
        }
    }
}

/// One placement of a glTF mesh: the node (and, with EXT_mesh_gpu_instancing, the instance) that places it.
#[derive(Debug, Clone)]
pub struct Placement {
    pub node: usize,
    /// The node's name ("" when it has none).
    pub name: String,
    /// The instance within the node's EXT_mesh_gpu_instancing (None: the node itself).
    pub instance: Option<usize>,
    pub mesh: usize,
    /// Mesh space to world at rest (for a skinned mesh: the node's, which skinning ignores).
    pub world: Mat4,
    /// The instance's own transform (applied before the node's world matrix; identity without instancing).
    pub instance_local: Mat4,
    /// The node's skin.
    pub skin: Option<usize>,
    /// The node's morph weights (`weights`), when it gives them.
    pub weights: Option<Vec<f32>>,
}

impl Doc<'_> {
    /// The placements of node `n` at `world` (the node alone, not its children): its mesh, once, or once per
    /// EXT_mesh_gpu_instancing instance (instance transform applied before the node's).
    pub fn place(&mut self, n: usize, world: Mat4, out: &mut Vec<Placement>) -> Result<(), String> {
        let node = self.json["nodes"][n].clone();
        let meshes = array(&self.json, "meshes").len();
        let Some(mesh) = opt_index(&node["mesh"], || format!("node {n}'s mesh"), meshes)? else {
            return Ok(());
        };
        let skins = array(&self.json, "skins").len();
        let skin = opt_index(&node["skin"], || format!("node {n}'s skin"), skins)?;
        let weights = float_list(&node["weights"], &format!("node {n}'s weights"))?;
        let name = node["name"].as_str().unwrap_or("").to_string();
        let one = |instance: Option<usize>, local: Mat4| Placement {
            node: n,
            name: name.clone(),
            instance,
            mesh,
            world: world * local,
            instance_local: local,
            skin,
            weights: weights.clone(),
        };
        let Some(attrs) = node.pointer("/extensions/EXT_mesh_gpu_instancing/attributes") else {
            out.push(one(None, Mat4::IDENTITY));
            return Ok(());
        };
        let what = format!("node {n}'s EXT_mesh_gpu_instancing");
        let accessors = array(&self.json, "accessors").len();
        let mut read = |key: &str, components: usize| -> Result<Option<Vec<f32>>, String> {
            let Some(a) = opt_index(&attrs[key], || format!("{what}: {key}"), accessors)? else {
                return Ok(None);
            };
            let (v, c) = self.read_floats(a)?;
            if c != components {
                return Err(format!(
                    "{what}: {key} has {c} components, not {components}"
                ));
            }
            Ok(Some(v))
        };
        let t = read("TRANSLATION", 3)?;
        let r = read("ROTATION", 4)?;
        let s = read("SCALE", 3)?;
        let counts: Vec<usize> = [(&t, 3), (&r, 4), (&s, 3)]
            .iter()
            .filter_map(|(v, c)| v.as_ref().map(|v| v.len() / c))
            .collect();
        let Some(&count) = counts.first() else {
            return Err(format!("{what} has none of TRANSLATION, ROTATION, SCALE"));
        };
        if counts.iter().any(|&c| c != count) {
            return Err(format!(
                "{what}'s attributes have different instance counts {counts:?}"
            ));
        }
        for i in 0..count {
            let tr = t
                .as_ref()
                .map_or(Vec3::ZERO, |v| Vec3::from_slice(&v[3 * i..]));
            let ro = r.as_ref().map_or(Quat::IDENTITY, |v| {
                Quat::from_slice(&v[4 * i..]).normalize()
            });
            let sc = s
                .as_ref()
                .map_or(Vec3::ONE, |v| Vec3::from_slice(&v[3 * i..]));
            if !(tr.is_finite() && ro.is_finite() && sc.is_finite()) {
                return Err(format!("{what}: instance {i} has a non-finite transform"));
            }
            out.push(one(
                Some(i),
                Mat4::from_scale_rotation_translation(sc, ro, tr),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// Worlds follow the hierarchy whatever the document order; a node with two parents and a cycle are
    /// refused by node.
    #[test]
    fn hierarchy_and_worlds() {
        let doc = json!({
            "scenes": [{"nodes": [1]}],
            "nodes": [
                {"translation": [0, 0, 3]},
                {"translation": [1, 0, 0], "children": [2]},
                {"translation": [0, 2, 0], "children": [0]},
            ],
        });
        let n = Nodes::read(&doc).unwrap();
        assert_eq!(n.scene_order, vec![1, 2, 0]);
        let w = n.worlds(&n.rest_locals());
        assert_eq!(w[0].transform_point3(Vec3::ZERO), Vec3::new(1.0, 2.0, 3.0));
        assert!(n.is_under(0, 1) && !n.is_under(1, 0));
        let sub = n.subtree(2);
        assert_eq!(sub.len(), 2);
        assert_eq!(
            sub[1].1.transform_point3(Vec3::ZERO),
            Vec3::new(0.0, 0.0, 3.0)
        );
        let two = json!({"nodes": [{"children": [2]}, {"children": [2]}, {}]});
        let e = Nodes::read(&two).unwrap_err();
        assert!(e.contains("node 2 is a child of nodes 0 and 1"), "{e}");
        let cycle = json!({"nodes": [{}, {"children": [2]}, {"children": [1]}]});
        let e = Nodes::read(&cycle).unwrap_err();
        assert!(e.contains("own ancestor"), "{e}");
        // A scene root that is also a child stands where its own transform puts it.
        let root = json!({"scenes": [{"nodes": [1]}], "nodes": [{"translation": [5, 0, 0], "children": [1]}, {}]});
        let n = Nodes::read(&root).unwrap();
        assert_eq!(n.worlds(&n.rest_locals())[1], Mat4::IDENTITY);
    }
}
