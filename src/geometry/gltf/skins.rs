//! Skins (glTF 2.0 section 3.7.3): the joints, their inverse bind matrices, and the skeleton root.

use super::accessors::Doc;
use super::json::{array, index, opt_index};
use glam::Mat4;

/// A skin: joint nodes and, per joint, the inverse bind matrix (identity where the file gives none).
#[derive(Debug, Clone, PartialEq)]
pub struct Skin {
    pub name: String,
    pub joints: Vec<usize>,
    pub inverse_bind: Vec<Mat4>,
    /// `skeleton`: the common root the file names, when it names one.
    pub skeleton: Option<usize>,
}

impl Doc<'_> {
    /// Skin `i`, its joints checked to be nodes and its inverse bind matrices one finite MAT4 per joint.
    pub fn skin(&mut self, i: usize) -> Result<Skin, String> {
        let what = format!("skin {i}");
        let skins = array(&self.json, "skins");
        let s = skins
            .get(i)
            .ok_or_else(|| format!("{what} does not exist ({} skins)", skins.len()))?
            .clone();
        let nodes = array(&self.json, "nodes").len();
        let joints = array(&s, "joints")
            .iter()
            .map(|j| index(j, || format!("a joint of {what}"), nodes))
            .collect::<Result<Vec<usize>, String>>()?;
        if joints.is_empty() {
            return Err(format!("{what} has no joints"));
        }
        let accessors = array(&self.json, "accessors").len();
        let inverse_bind = match opt_index(
            &s["inverseBindMatrices"],
            || format!("{what}'s inverseBindMatrices"),
            accessors,
        )? {
            None => vec![Mat4::IDENTITY; joints.len()],
            Some(a) => {
                let (v, c) = self.read_floats(a)?;
                if c != 16 || v.len() != 16 * joints.len() {
                    return Err(format!(
                        "{what}'s inverseBindMatrices hold {} values, not one MAT4 for each of its {} joints",
                        v.len(),
                        joints.len()
                    ));
                }
                if v.iter().any(|x| !x.is_finite()) {
                    return Err(format!(
                        "{what}'s inverseBindMatrices hold a non-finite value"
                    ));
                }
                v.chunks_exact(16).map(Mat4::from_cols_slice).collect()
            }
        };
        Ok(Skin {
            name: s["name"].as_str().unwrap_or("").to_string(),
            skeleton: opt_index(&s["skeleton"], || format!("{what}'s skeleton"), nodes)?,
            joints,
            inverse_bind,
        })
    }
}
