//! A calibration: the display a popping experiment was made for (`lodbench calibrate`), and what its observers'
//! responses say (calibration.json, written by `scripts/calibration.py fit`): per stimulus metric, the 75 %
//! threshold of a two-interval forced choice between a switch and the same frames without it. One JND of a
//! metric is its threshold. `tune --calibration` and `run --calibration` read it.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// calibration.json's `format`.
pub const CALIBRATION_FORMAT: &str = "lodbench-calibration";

/// The display a calibration holds for. Written into stimuli.json by `lodbench calibrate` and copied into
/// calibration.json by the fit.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Display {
    pub width_px: u32,
    pub height_px: u32,
    pub refresh_hz: f64,
    pub diagonal_in: f64,
    pub viewing_distance_cm: f64,
    pub peak_luminance_cd_m2: f64,
    /// Pixels per visual degree at the centre of the screen (from the size, resolution and distance).
    pub pixels_per_degree: f64,
}

impl Display {
    /// A display, each number checked (finite and above zero).
    pub fn new(
        (width_px, height_px): (u32, u32),
        refresh_hz: f64,
        diagonal_in: f64,
        viewing_distance_cm: f64,
        peak_luminance_cd_m2: f64,
    ) -> Result<Display> {
        let checks = [
            ("--refresh-hz", refresh_hz),
            ("--diagonal-in", diagonal_in),
            ("--viewing-distance-cm", viewing_distance_cm),
            ("--peak-luminance", peak_luminance_cd_m2),
        ];
        for (flag, v) in checks {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Config(format!(
                    "{flag} {v}: the display needs a number above 0"
                )));
            }
        }
        if width_px == 0 || height_px == 0 {
            return Err(Error::Config(format!(
                "display {width_px}x{height_px}: --display-width and --display-height must be above 0"
            )));
        }
        Ok(Display {
            width_px,
            height_px,
            refresh_hz,
            diagonal_in,
            viewing_distance_cm,
            peak_luminance_cd_m2,
            pixels_per_degree: pixels_per_degree(
                (width_px, height_px),
                diagonal_in,
                viewing_distance_cm,
            ),
        })
    }

    /// One line: "1920x1080 at 60 Hz, 24-inch, seen from 60 cm (41.0 pixels per degree)".
    pub fn describe(&self) -> String {
        format!(
            "{}x{} at {} Hz, {}-inch, seen from {} cm ({:.1} pixels per degree)",
            self.width_px,
            self.height_px,
            self.refresh_hz,
            self.diagonal_in,
            self.viewing_distance_cm,
            self.pixels_per_degree
        )
    }
}

/// Pixels per degree at the screen's centre, as ColorVideoVDP's display geometry computes it
/// (`Geometry::from_diagonal`): the height from the diagonal and the aspect, one pixel's angle at the distance.
pub fn pixels_per_degree((w, h): (u32, u32), diagonal_in: f64, distance_cm: f64) -> f64 {
    let aspect = w as f64 / h as f64;
    let height_m = ((diagonal_in * 0.0254).powi(2) / (1.0 + aspect * aspect)).sqrt();
    let pixel_m = height_m / h as f64;
    let pixel_deg = 2.0 * (0.5 * pixel_m / (distance_cm / 100.0)).atan().to_degrees();
    1.0 / pixel_deg
}

/// One metric's fit in calibration.json.
#[derive(Debug, Clone, Deserialize)]
pub struct MetricFit {
    /// The 75 % point in the metric's own unit (JOD for `jod_popping`).
    pub threshold: f64,
    pub ci95: [f64; 2],
}

/// calibration.json as the fit writes it (the fields lodbench reads).
#[derive(Debug, Clone, Deserialize)]
struct CalibrationFile {
    format: String,
    simulated: bool,
    label: String,
    display: Display,
    best_metric: String,
    metrics: BTreeMap<String, MetricFit>,
}

/// A metric a JND can be of: what lodbench measures per switch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JndMetric {
    /// lodpop: the RMS over the frame of a switch's change (sRGB, 0 to 1); more is more visible.
    Lodpop,
    /// ColorVideoVDP's JOD of the switch against its counterfactual (10: invisible); less is more visible.
    JodPopping,
}

impl JndMetric {
    pub fn name(self) -> &'static str {
        match self {
            JndMetric::Lodpop => "lodpop",
            JndMetric::JodPopping => "jod_popping",
        }
    }

    fn of(name: &str) -> Option<JndMetric> {
        [JndMetric::Lodpop, JndMetric::JodPopping]
            .into_iter()
            .find(|m| m.name() == name)
    }
}

/// The unit a calibration gives: one JND of one metric, for one display.
#[derive(Debug, Clone, Serialize)]
pub struct Jnd {
    pub path: PathBuf,
    pub metric: JndMetric,
    /// The metric's 75 % threshold: 1 JND.
    pub threshold: f64,
    pub ci95: [f64; 2],
    pub simulated: bool,
    /// The fit's words for where the responses came from ("SIMULATED observer ...", or the observers).
    pub label: String,
    pub display: Display,
}

impl Jnd {
    /// Reads `path`: the JND of `metric` (default: the file's best metric), which must be one of `supported`
    /// (what the reading command measures).
    pub fn load(path: &Path, metric: Option<&str>, supported: &[JndMetric]) -> Result<Jnd> {
        let bad = |problem: String| Error::Calibration {
            path: path.to_path_buf(),
            problem,
        };
        let text =
            std::fs::read_to_string(path).map_err(|e| bad(format!("cannot be read ({e})")))?;
        let file: CalibrationFile = serde_json::from_str(&text).map_err(|e| {
            bad(format!(
                "is not a calibration.json ({e}); `python3 scripts/calibration.py fit` writes one"
            ))
        })?;
        if file.format != CALIBRATION_FORMAT {
            return Err(bad(format!(
                "its format is '{}', not '{CALIBRATION_FORMAT}'",
                file.format
            )));
        }
        let name = metric.unwrap_or(&file.best_metric);
        let names = |ms: &[JndMetric]| ms.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ");
        let chosen = JndMetric::of(name)
            .filter(|m| supported.contains(m))
            .ok_or_else(|| {
                bad(format!(
                    "its metric {name} is not one this command measures ({})",
                    names(supported)
                ))
            })?;
        let fit = file.metrics.get(name).ok_or_else(|| {
            bad(format!(
                "holds no fit of {name} (it has: {})",
                file.metrics.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })?;
        let valid = match chosen {
            JndMetric::Lodpop => fit.threshold > 0.0 && fit.threshold < 1.0,
            JndMetric::JodPopping => fit.threshold > 0.0 && fit.threshold < 10.0,
        };
        if !fit.threshold.is_finite() || !valid {
            return Err(bad(format!(
                "its {name} threshold {} is out of range",
                fit.threshold
            )));
        }
        Ok(Jnd {
            path: path.to_path_buf(),
            metric: chosen,
            threshold: fit.threshold,
            ci95: fit.ci95,
            simulated: file.simulated,
            label: file.label,
            display: file.display,
        })
    }

    /// `--calibration FILE --budget-jnd K` as `run` and `tune` read them: the file's lodpop JND, and the budget
    /// `K` JNDs (default 1) in lodpop; `K` must be above 0.
    pub fn lodpop_budget(path: &Path, budget_jnd: Option<f64>) -> Result<(Jnd, f64)> {
        let k = budget_jnd.unwrap_or(1.0);
        if !(k.is_finite() && k > 0.0) {
            return Err(Error::Config(format!(
                "--budget-jnd {k}: a budget of JNDs is above 0"
            )));
        }
        let jnd = Jnd::load(path, Some(JndMetric::Lodpop.name()), &[JndMetric::Lodpop])?;
        let budget = jnd.value_of(k);
        Ok((jnd, budget))
    }

    /// A value of the metric in JNDs: lodpop over its threshold; a JOD's drop from 10 over the threshold's.
    pub fn of(&self, value: f64) -> f64 {
        match self.metric {
            JndMetric::Lodpop => value / self.threshold,
            JndMetric::JodPopping => (10.0 - value) / (10.0 - self.threshold),
        }
    }

    /// `k` JNDs in the metric's unit: the inverse of [`Jnd::of`].
    pub fn value_of(&self, k: f64) -> f64 {
        match self.metric {
            JndMetric::Lodpop => k * self.threshold,
            JndMetric::JodPopping => 10.0 - k * (10.0 - self.threshold),
        }
    }

    /// Refuses a viewport other than the display's: a calibration holds for the display it was measured on.
    pub fn check_viewport(&self, width: u32, height: u32, flags: &str) -> Result<()> {
        let d = &self.display;
        if (width, height) != (d.width_px, d.height_px) {
            return Err(Error::Calibration {
                path: self.path.clone(),
                problem: format!(
                    "it was measured on a {}x{} display and this draws at {width}x{height}: draw at the \
                     display's size ({flags}) or calibrate for this one",
                    d.width_px, d.height_px
                ),
            });
        }
        Ok(())
    }

    /// One line for a report: "1 JND = lodpop 0.0081 (95 % 0.0062 to 0.0101), SIMULATED observer ...".
    pub fn describe(&self) -> String {
        format!(
            "1 JND = {} {:.4} (95 % interval {:.4} to {:.4}) on a {}, from {}{}",
            self.metric.name(),
            self.threshold,
            self.ci95[0],
            self.ci95[1],
            self.display.describe(),
            self.path.display(),
            match self.simulated {
                true => format!(": {} (simulated, not human data)", self.label),
                false => format!(": {}", self.label),
            }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_display_has_colorvideovdps_standard_fhd_pixels_per_degree() {
        // ColorVideoVDP's standard_fhd: 24-inch 1920x1080 at 0.6 m; its Geometry::from_diagonal gives the same.
        let d = Display::new((1920, 1080), 60.0, 24.0, 60.0, 200.0).unwrap();
        let geometry = colorvideovdp::Geometry::from_diagonal([1920, 1080], 24.0, 0.6).unwrap();
        assert!((d.pixels_per_degree - geometry.pixels_per_degree()).abs() < 1e-9);
        assert!(Display::new((1920, 1080), f64::NAN, 24.0, 60.0, 200.0).is_err());
        assert!(Display::new((0, 1080), 60.0, 24.0, 60.0, 200.0).is_err());
    }

    fn file(metric: &str, threshold: f64, display: (u32, u32)) -> String {
        let d = Display::new(display, 60.0, 24.0, 60.0, 200.0).unwrap();
        serde_json::json!({
            "format": CALIBRATION_FORMAT, "version": 1, "simulated": true, "label": "SIMULATED",
            "display": d, "best_metric": metric,
            "metrics": {metric: {"threshold": threshold, "ci95": [threshold * 0.8, threshold * 1.2]}}
        })
        .to_string()
    }

    #[test]
    fn a_jnd_converts_both_ways_and_bad_files_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("calibration.json");
        std::fs::write(&p, file("lodpop", 0.008, (1920, 1080))).unwrap();
        let all = [JndMetric::Lodpop, JndMetric::JodPopping];
        let j = Jnd::load(&p, None, &all).unwrap();
        assert_eq!(j.metric, JndMetric::Lodpop);
        assert!((j.of(0.016) - 2.0).abs() < 1e-12);
        assert!((j.value_of(1.5) - 0.012).abs() < 1e-12);
        assert!(j.check_viewport(1920, 1080, "").is_ok());
        let other = j
            .check_viewport(320, 240, "--width 1920 --height 1080")
            .unwrap_err()
            .to_string();
        assert!(
            other.contains("1920x1080 display") && other.contains("320x240"),
            "{other}"
        );

        std::fs::write(&p, file("jod_popping", 9.5, (1920, 1080))).unwrap();
        let j = Jnd::load(&p, None, &all).unwrap();
        assert!((j.of(9.0) - 2.0).abs() < 1e-12 && (j.value_of(2.0) - 9.0).abs() < 1e-12);

        std::fs::write(&p, file("flip", 0.01, (1920, 1080))).unwrap();
        let e = Jnd::load(&p, None, &all).unwrap_err().to_string();
        assert!(e.contains("flip is not one this command measures"), "{e}");
        let e = Jnd::load(&p, Some("lodpop"), &all).unwrap_err().to_string();
        assert!(e.contains("holds no fit of lodpop"), "{e}");
        std::fs::write(&p, "{}").unwrap();
        let e = Jnd::load(&p, None, &all).unwrap_err().to_string();
        assert!(e.contains("is not a calibration.json"), "{e}");
    }
}
