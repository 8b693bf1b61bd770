//! The scenes lodbench knows, by name, and what each profile (size preset) sets for each. Everything the rest
//! of the program asks about a scene's kind (its name, whether it is a bunny scene, its frame and instance
//! counts per profile) is answered here, so no other module matches scene names.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Size and length presets; explicit flags override them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// A minute's look at everything: small viewport, few frames.
    Quick,
    /// What CI runs on a software adapter.
    Ci,
    /// The test suite's regression set: 96x72, paths short enough to render every scene with every method in
    /// about a minute on a software adapter, long enough to pass through each scene's transitions; the bunny
    /// scenes as a close-up (`--sweep-start close-up`), where their LOD differences are visible at 96x72.
    Regress,
    /// The papers' sizes: 800x600, 3,600 timed frames, the full instance counts.
    Paper,
}

/// `--camera`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum CameraMode {
    /// The scene's own camera (fixed for the bunny scenes).
    Fixed,
    /// The eye swings around the point it looks at (the swept bunny, or the first grid bunny) by
    /// `ORBIT_AMPLITUDE_DEG` * sin(2 pi f / `ORBIT_PERIOD_FRAMES`), at the distance the fixed camera would have,
    /// so LOD selection sees the same distances for that point.
    Orbit,
    /// bunny-sweep: the bunny stays where the sweep starts and the camera moves instead, backwards and forwards
    /// along its line of sight through the same distances, so every frame shows what `fixed` shows (the same
    /// relative geometry under a directional light) while the motion is the camera's, the motion eq. 2 of FSI
    /// reprojects. Elsewhere the same as `fixed`.
    Dolly,
}

/// `--sweep-start`: where the bunny scenes' path starts (bunny-sweep's bunny, bunny-grid's first bunny).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum SweepStart {
    /// Where the model's bounding sphere fits the view: the camera is never inside the model, and switches
    /// nearer than that are not reached (the run says which).
    Fit,
    /// A close-up: just before the first switch's band (0.9 of its near edge), even where that puts the camera
    /// inside the model's bounding sphere (the run says so), and `--pixel-error` 1 at the viewport by default.
    /// At small viewports this is the only way to see the bunny's LOD differences: at 96x72 even LOD3's error is
    /// under a pixel wherever the whole bunny is in view. The regress profile's default.
    CloseUp,
}

/// What a profile sets for one scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProfileValues {
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub warmup: u32,
    /// Where the bunny scenes' path starts unless `--sweep-start` says.
    pub sweep_start: SweepStart,
}

/// The paper's counts for bunny-grid (Sheliemietiev et al. 2023, section 6).
pub const PAPER_COUNTS: [u32; 5] = [50, 250, 500, 1000, 2000];

/// A scene `--scene` accepts: a built-in name, or a glTF file's path (a user scene, `scene/user.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SceneKind {
    /// The popping experiment of Sheliemietiev et al. 2023, section 6: one bunny moved along the line of
    /// sight and back.
    BunnySweep,
    /// The performance experiment of Sheliemietiev et al. 2023, section 6, eq. 1: n bunnies on the +x axis.
    BunnyGrid,
    /// Scherzer & Wimmer 2008's SIMPLE: a field of spheres whose LOD1 is a box.
    Simple,
    /// Scherzer & Wimmer 2008's WINDMILLS: a field of windmills with turning blades.
    Windmills,
    /// Scherzer & Wimmer 2008's TREES: a field of alpha-tested trees.
    Trees,
    /// Blow 2003, Unified Rendering LOD Part 3, Fig. 1: the bunny clipped in half, one half reduced to a
    /// quarter, the halves joined by the seam; a turntable around it.
    BunnyHalves,
    /// One large procedural heightfield (`geometry/terrain.rs`) in blocks, flown over low.
    Terrain,
    /// The user's glTF scene (`--scene PATH.gltf|PATH.glb`): every node with a mesh an instance, authored LOD
    /// chains kept (`scene/user.rs`). `name` (the CSVs' `scene` column, file names of dumps) is the file's name
    /// with every character but letters, digits, '.' and '-' made '-'. Both are interned for the run's
    /// lifetime, so the kind stays `Copy`.
    User {
        path: &'static str,
        name: &'static str,
    },
}

impl Serialize for SceneKind {
    /// As its name (the CSVs' `scene` column).
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// Whether `name` names a glTF file (`.gltf` or `.glb`, any case): a user scene.
pub fn is_gltf_path(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    lower.ends_with(".gltf") || lower.ends_with(".glb")
}

impl SceneKind {
    /// Every scene, in the order runs use when `--scene` is absent.
    pub const ALL: [SceneKind; 7] = [
        SceneKind::BunnySweep,
        SceneKind::BunnyGrid,
        SceneKind::Simple,
        SceneKind::Windmills,
        SceneKind::Trees,
        SceneKind::BunnyHalves,
        SceneKind::Terrain,
    ];

    /// The name `--scene` takes and the CSVs' `scene` column holds.
    pub const fn name(self) -> &'static str {
        match self {
            SceneKind::BunnySweep => "bunny-sweep",
            SceneKind::BunnyGrid => "bunny-grid",
            SceneKind::Simple => "simple",
            SceneKind::Windmills => "windmills",
            SceneKind::Trees => "trees",
            SceneKind::BunnyHalves => "bunny-halves",
            SceneKind::Terrain => "terrain",
            SceneKind::User { name, .. } => name,
        }
    }

    /// Every scene name, in [`SceneKind::ALL`]'s order.
    pub fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|k| k.name()).collect()
    }

    /// The scene called `name` (a glTF file's path is a user scene), or an error listing the valid names.
    pub fn from_name(name: &str) -> Result<SceneKind> {
        if is_gltf_path(name) {
            // Interned once per distinct path: a run names a handful of scenes.
            type Interned = Vec<(&'static str, &'static str)>;
            static PATHS: std::sync::Mutex<Interned> = std::sync::Mutex::new(Vec::new());
            let mut paths = PATHS.lock().unwrap_or_else(|e| e.into_inner());
            let (path, short) = match paths.iter().find(|p| p.0 == name) {
                Some(p) => *p,
                None => {
                    let file = std::path::Path::new(name)
                        .file_name()
                        .map_or(name.into(), |f| f.to_string_lossy());
                    let short: String = file
                        .chars()
                        .map(|c| match c {
                            'a'..='z' | 'A'..='Z' | '0'..='9' | '.' | '-' => c,
                            _ => '-',
                        })
                        .collect();
                    // Two files of one name (a/scene.glb, b/scene.glb) would share the CSVs' scene column.
                    if let Some(other) = paths.iter().find(|p| p.1 == short) {
                        return Err(Error::Config(format!(
                            "scenes {} and {name} would both be named {short} in the results; copy one to \
                             another file name",
                            other.0
                        )));
                    }
                    let p: (&'static str, &'static str) = (
                        Box::leak(name.to_string().into_boxed_str()),
                        Box::leak(short.into_boxed_str()),
                    );
                    paths.push(p);
                    p
                }
            };
            return Ok(SceneKind::User { path, name: short });
        }
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| {
                if let Some(remedy) = scene_remedy(std::path::Path::new(name)) {
                    return Error::Config(format!("--scene {name}: {remedy}"));
                }
                let mut valid = Self::names();
                valid.push("or a glTF file (PATH.gltf, PATH.glb)");
                Error::unknown("scene", name, &valid)
            })
    }

    /// `--scene`'s values, in the user's order without repeats (every built-in scene when empty).
    pub fn resolve(given: &[String]) -> Result<Vec<SceneKind>> {
        if given.is_empty() {
            return Ok(Self::ALL.to_vec());
        }
        let mut out: Vec<SceneKind> = Vec::new();
        for name in given {
            let k = Self::from_name(name.trim())?;
            if !out.contains(&k) {
                out.push(k);
            }
        }
        Ok(out)
    }

    /// A user's glTF scene.
    pub fn is_user(self) -> bool {
        matches!(self, SceneKind::User { .. })
    }

    /// A user scene's file path (None for the built-in scenes).
    pub fn user_path(self) -> Option<&'static str> {
        match self {
            SceneKind::User { path, .. } => Some(path),
            _ => None,
        }
    }

    /// The Stanford-bunny scenes of Sheliemietiev et al. 2023 (the others are Scherzer & Wimmer 2008's
    /// procedural camera flights).
    pub fn is_bunny(self) -> bool {
        matches!(self, SceneKind::BunnySweep | SceneKind::BunnyGrid)
    }

    /// The scenes of one large mesh divided into blocks (Blow 2003, Unified Rendering LOD Part 3) and
    /// clusters: unified LOD, where each block is a model of its own with one instance and the seams join
    /// them.
    pub fn is_unified(self) -> bool {
        matches!(self, SceneKind::BunnyHalves | SceneKind::Terrain)
    }

    /// Scenes that are one block of one instance count whatever `--count` says.
    pub fn single_count(self) -> bool {
        matches!(
            self,
            SceneKind::BunnySweep
                | SceneKind::BunnyHalves
                | SceneKind::Terrain
                | SceneKind::User { .. }
        )
    }

    /// Cells along a side of the terrain's heightfield under `profile` (2 triangles each): about 2 million
    /// triangles at the paper profile, 157 thousand at ci.
    pub fn terrain_quads(profile: Profile) -> u32 {
        match profile {
            Profile::Quick => 160,
            Profile::Ci => 280,
            Profile::Regress => 48,
            Profile::Paper => 1000,
        }
    }

    /// Blocks along the longest side of the terrain under `profile`, unless `--blocks` says.
    pub fn terrain_blocks(profile: Profile) -> u32 {
        match profile {
            Profile::Regress => 4,
            Profile::Paper => 16,
            _ => 8,
        }
    }

    /// What `profile` sets for this scene.
    ///
    /// bunny-grid is a static scene: every frame is the same picture, so its timing needs fewer frames at
    /// small profiles, and its instance counts make each frame far heavier on a software adapter. bunny-sweep
    /// needs many frames: `pop` compares consecutive error images, so the bunny must move by well under a
    /// pixel per frame for a LOD switch to stand out from the error pattern moving with the bunny
    /// (docs/measurement.md, "Reading pop"). At 320x240, 2,400 frames is the fewest for which every discrete
    /// switch frame is a local maximum of pop; 600 frames (quick) is only a look. The procedural scenes of
    /// Scherzer & Wimmer 2008 (simple, windmills, trees) are camera flights over a field: their frames are
    /// heavy on a software adapter, so the small profiles keep few frames and instances.
    pub fn profile(self, profile: Profile) -> ProfileValues {
        let frames = |grid: u32, flight: u32, sweep: u32| match self {
            SceneKind::BunnyGrid => grid,
            SceneKind::BunnySweep => sweep,
            _ => flight,
        };
        match profile {
            Profile::Quick => ProfileValues {
                width: 320,
                height: 240,
                frames: frames(20, 60, 600),
                warmup: 5,
                sweep_start: SweepStart::Fit,
            },
            Profile::Ci => ProfileValues {
                width: 320,
                height: 240,
                frames: frames(30, 120, 2400),
                warmup: 10,
                sweep_start: SweepStart::Fit,
            },
            Profile::Regress => ProfileValues {
                width: 96,
                height: 72,
                frames: frames(3, 40, 240),
                warmup: 2,
                sweep_start: SweepStart::CloseUp,
            },
            Profile::Paper => ProfileValues {
                width: 800,
                height: 600,
                frames: 3600,
                warmup: 120,
                sweep_start: SweepStart::Fit,
            },
        }
    }

    /// Instance counts under a profile, unless --count is given: bunny-grid's sweep of counts (Sheliemietiev
    /// et al. 2023), the paper's 4,000 windmills and trees (Scherzer & Wimmer 2008, section 4; SIMPLE's count
    /// is not given there: 1,000), and small fields for the small profiles. bunny-sweep is one bunny whatever
    /// --count says.
    pub fn profile_counts(self, profile: Profile) -> Vec<u32> {
        use Profile::*;
        use SceneKind::*;
        match (self, profile) {
            (BunnySweep | BunnyHalves | Terrain | User { .. }, _) => vec![1],
            (BunnyGrid, Quick) => vec![50],
            (BunnyGrid, Ci) => vec![50, 250],
            (BunnyGrid, Regress) => vec![50],
            (BunnyGrid, Paper) => PAPER_COUNTS.to_vec(),
            (Simple, Quick) => vec![36],
            (Simple, Ci) => vec![64],
            (Simple, Regress) => vec![36],
            (Simple, Paper) => vec![1000],
            (Windmills, Quick) => vec![9],
            (Windmills, Ci) => vec![16],
            (Windmills, Regress) => vec![9],
            (Windmills, Paper) => vec![4000],
            (Trees, Quick) => vec![4],
            (Trees, Ci) => vec![6],
            (Trees, Regress) => vec![3],
            (Trees, Paper) => vec![4000],
        }
    }
}

/// What `--scene` was given, where it names something on disk that is not a scene, and the remedy: a folder (the
/// glTF files in it), an OBJ or other mesh file (`--mesh`).
fn scene_remedy(path: &std::path::Path) -> Option<String> {
    if path.is_dir() {
        // Its glTF files, else its folders' (the Khronos sample assets' Model/glTF/, Model/glTF-Binary/).
        let entries = |dir: &std::path::Path| -> Vec<std::path::PathBuf> {
            let mut v: Vec<_> = std::fs::read_dir(dir)
                .map(|r| r.filter_map(|e| e.ok()).map(|e| e.path()).collect())
                .unwrap_or_default();
            v.sort();
            v
        };
        let gltf = |v: Vec<std::path::PathBuf>| -> Vec<String> {
            v.into_iter()
                .filter(|p| p.is_file() && is_gltf_path(&p.to_string_lossy()))
                .map(|p| p.display().to_string())
                .collect()
        };
        let top = entries(path);
        let below: Vec<_> = top
            .iter()
            .filter(|p| p.is_dir())
            .flat_map(|d| entries(d))
            .collect();
        let files = match gltf(top) {
            found if found.is_empty() => gltf(below),
            found => found,
        };
        return Some(match files.as_slice() {
            [] => "is a folder, not a scene: give a glTF file (PATH.gltf or PATH.glb) or a built-in scene's \
                   name (lodbench list)"
                .to_string(),
            [one] => format!("is a folder, not a scene: did you mean --scene {one}?"),
            many => format!(
                "is a folder, not a scene: did you mean one of its glTF files ({})?",
                many.join(", ")
            ),
        });
    }
    let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
    (ext == "obj").then(|| {
        "is an OBJ mesh, not a scene: --scene takes a glTF file or a built-in scene; a mesh file replaces the \
         bunny of the bunny scenes with --mesh (lodbench run --scene bunny-sweep --mesh FILE.obj)"
            .to_string()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_list_the_valid_ones() {
        for k in SceneKind::ALL {
            assert_eq!(SceneKind::from_name(k.name()).unwrap(), k);
        }
        let msg = SceneKind::from_name("bunny-swep").unwrap_err().to_string();
        assert!(msg.contains("bunny-swep") && msg.contains("trees"), "{msg}");
    }

    #[test]
    fn a_gltf_path_is_a_user_scene_named_by_its_file() {
        let k = SceneKind::from_name("some dir/My_Scene.GLB").unwrap();
        assert_eq!(k.name(), "My-Scene.GLB");
        assert_eq!(k.user_path(), Some("some dir/My_Scene.GLB"));
        assert!(k.is_user() && k.single_count() && !k.is_bunny() && !k.is_unified());
        assert_eq!(SceneKind::from_name("some dir/My_Scene.GLB").unwrap(), k);
        assert_eq!(serde_json::to_string(&k).unwrap(), "\"My-Scene.GLB\"");
        assert_eq!(
            serde_json::to_string(&SceneKind::BunnySweep).unwrap(),
            "\"bunny-sweep\""
        );
        let r = SceneKind::resolve(&["simple".into(), "a.gltf".into(), "simple".into()]).unwrap();
        assert_eq!(r.len(), 2);
        // Another file of the same name would share the scene column.
        let msg = SceneKind::from_name("other dir/My_Scene.GLB")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("would both be named My-Scene.GLB"), "{msg}");
    }

    #[test]
    fn profiles_per_kind() {
        use SceneKind::*;
        assert_eq!(BunnySweep.profile(Profile::Ci).frames, 2400);
        assert_eq!(BunnyGrid.profile(Profile::Ci).frames, 30);
        assert_eq!(Trees.profile(Profile::Quick).frames, 60);
        assert_eq!(Simple.profile(Profile::Paper).frames, 3600);
        assert_eq!(BunnySweep.profile_counts(Profile::Paper), vec![1]);
        assert_eq!(Windmills.profile_counts(Profile::Paper), vec![4000]);
    }
}
