//! Cluster LOD, the cluster DAG of Nanite as meshoptimizer 1.x builds it (`meshopt::clod_build`): the mesh is
//! split into clusters of at most [`MAX_TRIANGLES`] triangles; groups of neighbouring clusters are merged,
//! simplified with their outer border locked and split again, level after level, so every group carries the
//! error of its simplified version and every cluster names the more refined group it was made from. Pure CPU.
//!
//! The per-frame cut ([`ClusterDag::cut`]) follows meshoptimizer's rule (`clodGroup`'s documentation): a
//! cluster is drawn when the projected error of the group it is in is over the threshold and the cluster is
//! original geometry or the projected error of the group it was refined from is at or under it. Projected
//! error in pixels: `error / max(distance(centre, eye) - radius, znear) * height / (2 tan(fov_y / 2))`, the same
//! conservative distance the block scenes' switch distances use (docs/methods.md, "Unified LOD"). A cluster
//! either is drawn or not: cut changes are hard switches, there is no transition between them.

use crate::error::{Error, Result};
use crate::geometry::mesh::Mesh;
use glam::Vec3;

/// Triangles per cluster at most (meshoptimizer's default configuration for rasterisation at this size).
pub const MAX_TRIANGLES: usize = 128;

/// Sphere bounds and error of a group's simplified geometry, in mesh units, and a box bound (`--cluster-bound
/// box`): the axis-aligned box of the group's own clusters, of the clusters made from it, and of the boxes of
/// the groups its clusters were made from, so that a group's box holds every finer group's box below it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroupBounds {
    pub center: Vec3,
    pub radius: f32,
    pub min: Vec3,
    pub max: Vec3,
    /// `f32::MAX` for a terminal group (nothing coarser was made from it).
    pub error: f32,
    pub depth: u32,
}

/// One cluster: a range of [`ClusterDag::indices`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cluster {
    pub first_index: u32,
    pub index_count: u32,
    /// The group the cluster is in.
    pub group: u32,
    /// The group it was simplified from, or None for original geometry.
    pub refined: Option<u32>,
}

/// The DAG of one mesh.
#[derive(Debug, Clone)]
pub struct ClusterDag {
    /// Every cluster's triangles, into the mesh's own vertices, cluster after cluster.
    pub indices: Vec<u32>,
    pub clusters: Vec<Cluster>,
    pub groups: Vec<GroupBounds>,
    /// Milliseconds `clod_build` took.
    pub build_ms: f64,
}

/// How the cut projects errors: the camera's position, pixels per unit of error at distance 1
/// (`height / (2 tan(fov_y / 2))`), the near plane, the threshold in pixels and the bound the distance is
/// measured to.
#[derive(Debug, Clone, Copy)]
pub struct CutCamera {
    pub eye: Vec3,
    pub pixels_per_unit: f32,
    pub znear: f32,
    pub pixel_error: f32,
    pub bound: CutBound,
}

/// `--cluster-bound`: what a group's distance to the camera is measured to.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum CutBound {
    /// meshoptimizer's sphere per group (`clodGroup`'s rule): a camera inside it is at the near plane.
    #[default]
    Sphere,
    /// The group's axis-aligned box, unioned up the DAG ([`GroupBounds`]): over a flat patch of terrain the
    /// camera is its height away, not inside a sphere as wide as the patch.
    Box,
}

/// Why a frame's cut is as fine as it is (`lodbench describe` on a unified scene, averaged along the path):
/// of the groups that have a coarser version, how many are over the threshold, and of those how many have the
/// camera inside their bounding sphere, so that their distance is clamped to the near plane.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct CutDiagnosis {
    /// Groups with a coarser version (non-terminal).
    pub groups: u32,
    /// Of those, over the threshold: drawn finer than their coarser version.
    pub over: u32,
    /// Over the threshold with the camera inside the group's sphere (distance to it clamped to the near plane).
    pub over_inside_sphere: u32,
    /// Of those, under the threshold when the distance is measured to the sphere's centre instead: the groups
    /// the sphere bound alone keeps fine (the centre distance is no bound: it is what the cut would give up).
    pub over_only_by_sphere: u32,
    /// Triangles of the cut.
    pub triangles: u64,
}

impl CutCamera {
    /// The error of group `g`'s simplified version in pixels, at its distance to `bound` (clamped to the near
    /// plane; infinite for a terminal group).
    pub fn projected_error(&self, g: &GroupBounds) -> f32 {
        if g.error == f32::MAX {
            return f32::INFINITY;
        }
        match self.bound {
            CutBound::Sphere => self.projected(g.error, g.center.distance(self.eye) - g.radius),
            CutBound::Box => self.projected_to_box(g.error, g.min, g.max),
        }
    }

    /// `error` in pixels at the camera's distance to the box `min`..`max` (0 inside it, then clamped to the
    /// near plane): the bound `--cluster-bound box` and ROAM's triangles use.
    pub fn projected_to_box(&self, error: f32, min: Vec3, max: Vec3) -> f32 {
        self.projected(error, (self.eye - self.eye.clamp(min, max)).length())
    }

    /// `error` in pixels at distance `d` (clamped to the near plane).
    fn projected(&self, error: f32, d: f32) -> f32 {
        error / d.max(self.znear) * self.pixels_per_unit
    }

    fn over(&self, g: &GroupBounds) -> bool {
        self.projected_error(g) > self.pixel_error
    }
}

impl ClusterDag {
    /// Builds the DAG of `mesh` (positions only; meshoptimizer's default configuration for rasterisation
    /// with [`MAX_TRIANGLES`]).
    pub fn build(name: &str, mesh: &Mesh) -> Result<ClusterDag> {
        let started = std::time::Instant::now();
        let bytes: &[u8] = bytemuck::cast_slice(&mesh.positions);
        let adapter = meshopt::VertexDataAdapter::new(bytes, 12, 0).map_err(|e| Error::Mesh {
            path: name.to_string(),
            problem: format!("meshopt rejected the vertices: {e}"),
        })?;
        let mut dag = ClusterDag {
            indices: Vec::new(),
            clusters: Vec::new(),
            groups: Vec::new(),
            build_ms: 0.0,
        };
        let config = meshopt::clod_default_config(MAX_TRIANGLES);
        meshopt::clod_build(
            config,
            &meshopt::ClodMesh::new(&mesh.indices, &adapter),
            |group, clusters| {
                let id = dag.groups.len() as u32;
                let s = group.simplified;
                dag.groups.push(GroupBounds {
                    center: Vec3::from(s.center),
                    radius: s.radius,
                    min: Vec3::splat(f32::INFINITY),
                    max: Vec3::splat(f32::NEG_INFINITY),
                    error: s.error,
                    depth: group.depth.max(0) as u32,
                });
                for c in clusters {
                    dag.clusters.push(Cluster {
                        first_index: dag.indices.len() as u32,
                        index_count: c.indices.len() as u32,
                        group: id,
                        refined: u32::try_from(c.refined).ok(),
                    });
                    dag.indices.extend_from_slice(c.indices);
                }
                id as i32
            },
        );
        if dag.clusters.is_empty() {
            return Err(Error::Mesh {
                path: name.to_string(),
                problem: "cluster LOD built no clusters".into(),
            });
        }
        dag.boxes(mesh);
        dag.build_ms = started.elapsed().as_secs_f64() * 1e3;
        Ok(dag)
    }

    /// Each group's box: its own clusters and the clusters made from it, then, in the order the groups were
    /// made (a cluster's refined group always comes before the group it is in), the boxes of the groups its
    /// clusters were made from, so a group's projected error is never below a finer one's and the cut stays
    /// consistent.
    fn boxes(&mut self, mesh: &Mesh) {
        let ClusterDag {
            indices,
            clusters,
            groups,
            ..
        } = self;
        for c in clusters.iter() {
            let range = c.first_index as usize..(c.first_index + c.index_count) as usize;
            let (lo, hi) = indices[range].iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), &v| {
                    let p = Vec3::from(mesh.positions[v as usize]);
                    (lo.min(p), hi.max(p))
                },
            );
            for g in std::iter::once(c.group).chain(c.refined) {
                let b = &mut groups[g as usize];
                b.min = b.min.min(lo);
                b.max = b.max.max(hi);
            }
        }
        let mut order: Vec<&Cluster> = clusters.iter().filter(|c| c.refined.is_some()).collect();
        order.sort_by_key(|c| c.group);
        for c in order {
            if let Some(r) = c.refined {
                let (lo, hi) = (groups[r as usize].min, groups[r as usize].max);
                let b = &mut groups[c.group as usize];
                b.min = b.min.min(lo);
                b.max = b.max.max(hi);
            }
        }
    }

    /// Levels of the DAG (the deepest group's depth + 1).
    pub fn levels(&self) -> u32 {
        self.groups
            .iter()
            .map(|g| g.depth)
            .max()
            .map_or(0, |d| d + 1)
    }

    /// Bytes of the clusters' indices and their records.
    pub fn bytes(&self) -> u64 {
        (self.indices.len() * 4
            + self.clusters.len() * std::mem::size_of::<Cluster>()
            + self.groups.len() * std::mem::size_of::<GroupBounds>()) as u64
    }

    /// The clusters to draw for `camera`, in cluster order, into `out` (cleared first).
    pub fn cut(&self, camera: &CutCamera, out: &mut Vec<u32>) {
        self.cut_into(camera, &mut Vec::new(), out);
    }

    /// [`ClusterDag::cut`] with the per-group scratch `over` kept by the caller (nothing allocated once it
    /// has grown).
    pub fn cut_into(&self, camera: &CutCamera, over: &mut Vec<bool>, out: &mut Vec<u32>) {
        out.clear();
        over.clear();
        over.extend(self.groups.iter().map(|g| camera.over(g)));
        out.extend(
            self.clusters
                .iter()
                .enumerate()
                .filter(|(_, c)| {
                    over[c.group as usize] && c.refined.is_none_or(|r| !over[r as usize])
                })
                .map(|(i, _)| i as u32),
        );
    }

    /// [`CutDiagnosis`] of the cut for `camera`.
    pub fn diagnose(&self, camera: &CutCamera) -> CutDiagnosis {
        let mut d = CutDiagnosis::default();
        for g in self.groups.iter().filter(|g| g.error != f32::MAX) {
            d.groups += 1;
            if !camera.over(g) {
                continue;
            }
            d.over += 1;
            let centre = g.center.distance(camera.eye);
            if centre - g.radius <= camera.znear {
                d.over_inside_sphere += 1;
                let by_centre = camera.projected(g.error, centre);
                d.over_only_by_sphere += (by_centre <= camera.pixel_error) as u32;
            }
        }
        let mut cut = Vec::new();
        self.cut(camera, &mut cut);
        d.triangles = self.triangles(&cut);
        d
    }

    /// Triangles of the clusters `selected`.
    pub fn triangles(&self, selected: &[u32]) -> u64 {
        selected
            .iter()
            .map(|&c| self.clusters[c as usize].index_count as u64 / 3)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(eye: Vec3, pixel_error: f32) -> CutCamera {
        CutCamera {
            eye,
            pixels_per_unit: 600.0 / (2.0 * 30f32.to_radians().tan()),
            znear: 0.01,
            pixel_error,
            bound: CutBound::Sphere,
        }
    }

    /// At a vanishing pixel error the cut is the original mesh, triangle for triangle; at a huge one it is the
    /// terminal groups' clusters; farther or more tolerant never draws more.
    #[test]
    fn the_cut_runs_from_the_mesh_to_the_coarsest_clusters() {
        let mesh = crate::geometry::terrain::terrain_mesh(3, 64).unwrap();
        let dag = ClusterDag::build("terrain", &mesh).unwrap();
        assert!(dag.levels() > 2, "{} levels", dag.levels());
        let mut cut = Vec::new();
        dag.cut(&camera(Vec3::new(50.0, 20.0, 50.0), 1e-9), &mut cut);
        assert!(cut
            .iter()
            .all(|&c| dag.clusters[c as usize].refined.is_none()));
        assert_eq!(dag.triangles(&cut), mesh.triangle_count() as u64);
        let mut tris: Vec<[u32; 3]> = cut
            .iter()
            .flat_map(|&c| {
                let c = dag.clusters[c as usize];
                dag.indices[c.first_index as usize..(c.first_index + c.index_count) as usize]
                    .chunks_exact(3)
                    .map(|t| {
                        let mut t = [t[0], t[1], t[2]];
                        t.sort_unstable();
                        t
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        let mut original: Vec<[u32; 3]> = mesh
            .indices
            .chunks_exact(3)
            .map(|t| {
                let mut t = [t[0], t[1], t[2]];
                t.sort_unstable();
                t
            })
            .collect();
        tris.sort_unstable();
        original.sort_unstable();
        assert_eq!(tris, original);
        dag.cut(&camera(Vec3::new(50.0, 20.0, 50.0), 1e9), &mut cut);
        assert!(cut
            .iter()
            .all(|&c| dag.groups[dag.clusters[c as usize].group as usize].error == f32::MAX));
        let coarsest = dag.triangles(&cut);
        assert!(coarsest * 10 < mesh.triangle_count() as u64, "{coarsest}");
        let mut last = u64::MAX;
        for d in [5.0, 20.0, 80.0, 320.0] {
            dag.cut(&camera(Vec3::new(50.0, d, 50.0), 1.0), &mut cut);
            let t = dag.triangles(&cut);
            assert!(t <= last && t >= coarsest, "{t} at height {d}");
            last = t;
        }
    }

    /// The diagnosis counts what the cut does: a camera far above the terrain has no group's sphere around it;
    /// one standing on the terrain is inside the spheres of the coarse groups under it, and those are over
    /// the threshold by the clamp alone where their centre is far enough away.
    #[test]
    fn diagnosis_counts_groups_with_the_camera_inside_their_sphere() {
        let mesh = crate::geometry::terrain::terrain_mesh(3, 64).unwrap();
        let dag = ClusterDag::build("terrain", &mesh).unwrap();
        let far = dag.diagnose(&camera(Vec3::new(32.0, 500.0, 32.0), 1.0));
        assert_eq!(far.over_inside_sphere, 0);
        assert!(far.over <= far.groups && far.groups > 0);
        let mut cut = Vec::new();
        let low = camera(Vec3::new(32.0, 2.0, 32.0), 1.0);
        dag.cut(&low, &mut cut);
        let d = dag.diagnose(&low);
        assert_eq!(d.triangles, dag.triangles(&cut));
        assert!(d.over_inside_sphere > 0, "{d:?}");
        assert!(d.over_only_by_sphere <= d.over_inside_sphere && d.over_inside_sphere <= d.over);
    }

    /// `--cluster-bound box`: a group's box holds every finer group's below it, so for any camera a group's
    /// projected error is at least that of each group its clusters were made from (the cut stays consistent,
    /// as with the spheres); over a low camera the box cut is coarser than the sphere cut.
    #[test]
    fn box_bounds_keep_the_cut_consistent_and_coarsen_it_near_the_ground() {
        let mesh = crate::geometry::terrain::terrain_mesh(3, 64).unwrap();
        let dag = ClusterDag::build("terrain", &mesh).unwrap();
        let mut rng = crate::rng::SplitMix64::new(11);
        for _ in 0..200 {
            let eye = Vec3::new(
                64.0 * rng.next_f32() - 8.0,
                30.0 * rng.next_f32(),
                64.0 * rng.next_f32() - 8.0,
            );
            let mut cam = camera(eye, 1.0);
            cam.bound = CutBound::Box;
            for c in &dag.clusters {
                if let Some(r) = c.refined {
                    let (g, r) = (&dag.groups[c.group as usize], &dag.groups[r as usize]);
                    if g.error != f32::MAX {
                        assert!(cam.projected_error(g) >= cam.projected_error(r), "{eye:?}");
                    }
                }
            }
        }
        let coarser = [1.0, 8.0, 64.0, 512.0].into_iter().any(|pixel_error| {
            let low = camera(Vec3::new(32.0, 2.0, 32.0), pixel_error);
            let boxed = CutCamera {
                bound: CutBound::Box,
                ..low
            };
            let (mut a, mut b) = (Vec::new(), Vec::new());
            dag.cut(&low, &mut a);
            dag.cut(&boxed, &mut b);
            dag.triangles(&b) < dag.triangles(&a)
        });
        assert!(coarser, "the box cut is never coarser than the sphere cut");
    }
}
