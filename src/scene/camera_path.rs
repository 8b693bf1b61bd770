//! `--camera-path FILE`: the user's own camera path, a CSV of keys resampled to the run's `--frames`.
//!
//! Columns (a header row names them; any order; an unknown column is an error, so a typo is not ignored):
//! - `time` or `frame` (exactly one): the key's place on the path, strictly increasing. Either is a parameter:
//!   the run's frame f of N takes the point at `first + (last - first) * f / (N - 1)`, so the path is resampled
//!   to `--frames` whatever its own rate.
//! - `x`, `y`, `z`: the eye, world units.
//! - the view: either `target_x`, `target_y`, `target_z` (a point looked at, up +y) or `qx`, `qy`, `qz`, `qw`
//!   (the camera's orientation as glTF writes it: it looks along its local -z, up its local +y).
//! - `fov_deg` (optional): the vertical field of view, the same on every key (it replaces `--fov`; LOD switch
//!   distances are computed for one field of view, so a path that zooms is refused).
//!
//! Between keys the eye and the target are interpolated linearly, orientations by slerp.

use crate::error::{Error, Result};
use glam::{Mat4, Quat, Vec3};
use serde::Serialize;
use std::path::Path;

/// One key: where on the path, the eye, and what it looks at.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Key {
    t: f64,
    eye: Vec3,
    look: Look,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Look {
    Target(Vec3),
    Orientation(Quat),
}

/// A camera path read from a CSV file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CameraPath {
    /// The file it was read from.
    pub file: String,
    /// Keys in the file.
    pub keys: usize,
    /// The path's vertical field of view, when the file gives one.
    pub fov_deg: Option<f32>,
    #[serde(skip)]
    points: Vec<Key>,
}

const POSITION: [&str; 3] = ["x", "y", "z"];
const TARGET: [&str; 3] = ["target_x", "target_y", "target_z"];
const QUAT: [&str; 4] = ["qx", "qy", "qz", "qw"];

impl CameraPath {
    /// Reads the CSV at `path`.
    pub fn load(path: &Path) -> Result<CameraPath> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::Config(format!("--camera-path {name}: cannot be read ({e})")))?;
        CameraPath::parse(&name, &text)
    }

    /// Parses CSV `text` (`name` in errors).
    pub fn parse(name: &str, text: &str) -> Result<CameraPath> {
        let bad = |problem: String| Error::Config(format!("--camera-path {name}: {problem}"));
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let headers: Vec<String> = reader
            .headers()
            .map_err(|e| bad(format!("not a CSV file ({e})")))?
            .iter()
            .map(str::to_string)
            .collect();
        let columns = Columns::of(name, headers)?;
        let mut points: Vec<Key> = Vec::new();
        let mut fovs: Vec<f32> = Vec::new();
        for (row, record) in reader.records().enumerate() {
            let line = row + 2;
            let record = record.map_err(|e| bad(format!("line {line}: {e}")))?;
            let (key, fov) = columns.key(name, line, &record, points.last())?;
            if let Some(f) = fov {
                fovs.push(f);
            }
            points.push(key);
        }
        if points.len() < 2 {
            return Err(bad(format!(
                "has {} keys; a path needs at least two",
                points.len()
            )));
        }
        let fov_deg = one_fov(name, &fovs)?;
        Ok(CameraPath {
            file: name.to_string(),
            keys: points.len(),
            fov_deg,
            points,
        })
    }

    /// A path from keys already read (a glTF camera animation): (time, eye, orientation looking along -z).
    pub fn from_orientations(
        file: &str,
        keys: &[(f64, Vec3, Quat)],
        fov_deg: Option<f32>,
    ) -> Result<CameraPath> {
        let bad = |problem: String| Error::Config(format!("camera path of {file}: {problem}"));
        if keys.len() < 2 {
            return Err(bad(format!(
                "has {} keys; a path needs at least two",
                keys.len()
            )));
        }
        if keys
            .iter()
            .any(|k| !(k.0.is_finite() && k.1.is_finite() && k.2.is_finite()))
        {
            return Err(bad("a key is not finite".into()));
        }
        if keys.windows(2).any(|w| w[1].0 <= w[0].0) {
            return Err(bad("key times must increase".into()));
        }
        Ok(CameraPath {
            file: file.to_string(),
            keys: keys.len(),
            fov_deg,
            points: keys
                .iter()
                .map(|&(t, eye, q)| Key {
                    t,
                    eye,
                    look: Look::Orientation(q.normalize()),
                })
                .collect(),
        })
    }

    /// The eye and view matrix on frame `frame` of `frames`.
    pub fn view(&self, frame: u32, frames: u32) -> (Vec3, Mat4) {
        let (first, last) = (self.points[0].t, self.points[self.points.len() - 1].t);
        let u = if frames > 1 {
            frame.min(frames - 1) as f64 / (frames - 1) as f64
        } else {
            0.0
        };
        let t = first + (last - first) * u;
        let i = self
            .points
            .windows(2)
            .position(|w| t <= w[1].t)
            .unwrap_or(self.points.len() - 2);
        let (a, b) = (&self.points[i], &self.points[i + 1]);
        let s = (((t - a.t) / (b.t - a.t)).clamp(0.0, 1.0)) as f32;
        let eye = a.eye.lerp(b.eye, s);
        let view = match (a.look, b.look) {
            (Look::Target(p), Look::Target(q)) => {
                // Between two keys the target may pass through the eye: look along -z there.
                let dir = (p.lerp(q, s) - eye).normalize_or(Vec3::NEG_Z);
                let up = if dir.cross(Vec3::Y).length() < 1e-4 {
                    Vec3::Z
                } else {
                    Vec3::Y
                };
                Mat4::look_to_rh(eye, dir, up)
            }
            (Look::Orientation(p), Look::Orientation(q)) => {
                Mat4::from_rotation_translation(p.slerp(q, s), eye).inverse()
            }
            _ => Mat4::look_at_rh(eye, eye + Vec3::NEG_Z, Vec3::Y),
        };
        (eye, view)
    }

    /// Every key's eye (to size the far plane).
    pub fn eyes(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.points.iter().map(|k| k.eye)
    }
}

/// Where a path file's columns are.
struct Columns {
    headers: Vec<String>,
    /// The time or the frame column.
    time: usize,
    position: Vec<usize>,
    /// Exactly one of the target's and the quaternion's columns.
    target: Option<Vec<usize>>,
    quat: Option<Vec<usize>>,
    fov: Option<usize>,
}

impl Columns {
    /// The columns of `headers` (`name` in errors): known names only, a time or a frame column (not both), x, y,
    /// z, and either a target or a quaternion, each complete.
    fn of(name: &str, headers: Vec<String>) -> Result<Columns> {
        let bad = |problem: String| Error::Config(format!("--camera-path {name}: {problem}"));
        let known: Vec<&str> = ["time", "frame", "fov_deg"]
            .into_iter()
            .chain(POSITION)
            .chain(TARGET)
            .chain(QUAT)
            .collect();
        if let Some(h) = headers.iter().find(|h| !known.contains(&h.as_str())) {
            return Err(bad(format!(
                "unknown column '{h}' (the columns are {})",
                known.join(", ")
            )));
        }
        let col = |c: &str| headers.iter().position(|h| h == c);
        let time = match (col("time"), col("frame")) {
            (Some(t), None) | (None, Some(t)) => t,
            (Some(_), Some(_)) => {
                return Err(bad("has both a time and a frame column; give one".into()))
            }
            (None, None) => return Err(bad("has no time or frame column".into())),
        };
        let need = |cols: &[&str]| -> Result<Option<Vec<usize>>> {
            let found: Vec<Option<usize>> = cols.iter().map(|c| col(c)).collect();
            match (
                found.iter().all(Option::is_some),
                found.iter().any(Option::is_some),
            ) {
                (true, _) => Ok(Some(found.into_iter().flatten().collect())),
                (false, false) => Ok(None),
                (false, true) => Err(bad(format!("needs all of the columns {}", cols.join(", ")))),
            }
        };
        let position = need(&POSITION)?.ok_or_else(|| bad("has no x, y, z columns".into()))?;
        let (target, quat) = (need(&TARGET)?, need(&QUAT)?);
        if target.is_some() == quat.is_some() {
            return Err(bad(
                "needs either target_x, target_y, target_z (a point looked at) or qx, qy, qz, qw (an orientation)"
                    .into(),
            ));
        }
        let fov = col("fov_deg");
        Ok(Columns {
            headers,
            time,
            position,
            target,
            quat,
            fov,
        })
    }

    /// The key on line `line` (`record`; `name` in errors), after the `prev` key, and its field of view where the
    /// file has the column.
    fn key(
        &self,
        name: &str,
        line: usize,
        record: &csv::StringRecord,
        prev: Option<&Key>,
    ) -> Result<(Key, Option<f32>)> {
        let bad = |problem: String| Error::Config(format!("--camera-path {name}: {problem}"));
        let headers = &self.headers;
        let num = |i: usize| -> Result<f64> {
            let cell = record.get(i).unwrap_or("");
            // Finite as the f32 the path is kept in (1e39 is not), and small enough that differences of
            // times stay finite.
            cell.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && (*v as f32).is_finite() && v.abs() < 1e30)
                .ok_or_else(|| {
                    bad(format!(
                        "line {line}: {} is '{cell}', not a finite number",
                        headers[i]
                    ))
                })
        };
        let v3 = |c: &[usize]| -> Result<Vec3> {
            Ok(Vec3::new(
                num(c[0])? as f32,
                num(c[1])? as f32,
                num(c[2])? as f32,
            ))
        };
        let t = num(self.time)?;
        if let Some(prev) = prev {
            if t <= prev.t {
                return Err(bad(format!(
                    "line {line}: {} {t} does not come after the previous key's {} (keys must go forward)",
                    headers[self.time], prev.t
                )));
            }
        }
        let eye = v3(&self.position)?;
        let look = match (&self.target, &self.quat) {
            (Some(c), _) => {
                let target = v3(c)?;
                if target.distance(eye) <= f32::EPSILON * eye.length().max(1.0) {
                    return Err(bad(format!("line {line}: the target is the eye")));
                }
                Look::Target(target)
            }
            (_, Some(c)) => {
                let q = Quat::from_xyzw(
                    num(c[0])? as f32,
                    num(c[1])? as f32,
                    num(c[2])? as f32,
                    num(c[3])? as f32,
                );
                if q.length() < 1e-6 {
                    return Err(bad(format!("line {line}: the quaternion is zero")));
                }
                Look::Orientation(q.normalize())
            }
            _ => unreachable!("checked above"),
        };
        let fov = match self.fov {
            Some(f) => Some(num(f)? as f32),
            None => None,
        };
        Ok((Key { t, eye, look }, fov))
    }
}

/// The path's one field of view from its keys' `fovs` (`name` in errors): None without the column; an error
/// where it changes or lies outside (1, 170) degrees.
fn one_fov(name: &str, fovs: &[f32]) -> Result<Option<f32>> {
    let bad = |problem: String| Error::Config(format!("--camera-path {name}: {problem}"));
    Ok(match fovs.first() {
        None => None,
        Some(&f) if fovs.iter().all(|&g| g == f) && f > 1.0 && f < 170.0 => Some(f),
        Some(_) if fovs.iter().all(|&g| g == fovs[0]) => {
            return Err(bad(format!("fov_deg {} must be between 1 and 170", fovs[0])))
        }
        Some(_) => {
            return Err(bad(
                "fov_deg changes along the path; LOD switch distances are computed for one field of view, \
                 so give one value (or leave the column out and use --fov)"
                    .into(),
            ))
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_are_resampled_to_the_frames() {
        let p = CameraPath::parse(
            "p.csv",
            "time,x,y,z,target_x,target_y,target_z\n0,0,0,10,0,0,0\n2,0,0,30,0,0,0\n",
        )
        .unwrap();
        assert_eq!((p.keys, p.fov_deg), (2, None));
        let (eye, view) = p.view(1, 5);
        assert!(eye.abs_diff_eq(Vec3::new(0.0, 0.0, 15.0), 1e-5), "{eye}");
        // The target is straight ahead: it lands on the view's -z axis.
        let o = view.transform_point3(Vec3::ZERO);
        assert!(o.abs_diff_eq(Vec3::new(0.0, 0.0, -15.0), 1e-4), "{o}");
        assert!(p.view(4, 5).0.abs_diff_eq(Vec3::new(0.0, 0.0, 30.0), 1e-5));
    }

    #[test]
    fn orientations_look_along_their_minus_z() {
        let p = CameraPath::parse(
            "p.csv",
            "frame,x,y,z,qx,qy,qz,qw,fov_deg\n0,1,2,3,0,0,0,1,45\n10,1,2,3,0,0.7071068,0,0.7071068,45\n",
        )
        .unwrap();
        assert_eq!(p.fov_deg, Some(45.0));
        let (_, v) = p.view(0, 2);
        assert!(v
            .transform_point3(Vec3::new(1.0, 2.0, 2.0))
            .abs_diff_eq(Vec3::new(0.0, 0.0, -1.0), 1e-5));
        // Turned 90 degrees about +y: the camera looks along world -x.
        let (_, v) = p.view(1, 2);
        let ahead = v.transform_point3(Vec3::new(0.0, 2.0, 3.0));
        assert!(
            ahead.abs_diff_eq(Vec3::new(0.0, 0.0, -1.0), 1e-5),
            "{ahead}"
        );
    }

    /// Between two keys the target passes through the eye: the view stays finite.
    #[test]
    fn a_target_through_the_eye_keeps_a_finite_view() {
        let p = CameraPath::parse(
            "p.csv",
            "time,x,y,z,target_x,target_y,target_z\n0,0,0,0,0,0,1\n1,0,0,1,0,0,0\n",
        )
        .unwrap();
        let (_, v) = p.view(1, 3);
        assert!(v.is_finite(), "{v}");
    }

    #[test]
    fn bad_paths_say_what_is_wrong() {
        let err = |text: &str| CameraPath::parse("p.csv", text).unwrap_err().to_string();
        let head = "time,x,y,z,target_x,target_y,target_z\n";
        assert!(err(&format!("{head}0,0,0,1,0,0,0\n")).contains("at least two"));
        assert!(err(&format!("{head}0,0,0,1,0,0,0\n0,0,0,2,0,0,0\n")).contains("go forward"));
        assert!(
            err(&format!("{head}0,0,0,1,0,0,0\n1,0,NaN,2,0,0,0\n")).contains("line 3: y is 'NaN'")
        );
        assert!(err("time,x,y,z,taget_x\n").contains("unknown column 'taget_x'"));
        assert!(err("time,x,y,z\n0,0,0,0\n1,0,0,1\n").contains("either target_x"));
        assert!(err("x,y,z,qx,qy,qz,qw\n").contains("no time or frame"));
        assert!(
            err("time,x,y,z,qx,qy,qz,qw,fov_deg\n0,0,0,0,0,0,0,1,40\n1,0,0,1,0,0,0,1,50\n")
                .contains("changes")
        );
        assert!(err(&format!("{head}0,0,0,1,0,0,1\n1,0,0,2,0,0,0\n")).contains("target is the eye"));
    }
}
