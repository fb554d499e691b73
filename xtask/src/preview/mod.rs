//! `cargo xtask preview`: the stages of a loop as CSV and PNG, for people.
//! The core library's engine runs on the host (`generate_into` with a
//! `Trace` observer); `<out>/<stem>.csv` has the columns
//! `n,walk,smoothed,normalized,final` in degrees, `<out>/<stem>.png` the
//! stages as panels in the style of the paper's Figures 6 and 7.
//!
//! - `walk`: the random walk of step δ (the seamless closure's circular
//!   walk detrended, walk(n) = δ·Σ_{k≤n} (e(k) − D/N));
//! - `smoothed`: the engine's smoothed walk, shifted to the walk's mean
//!   (the engine defines it only up to a constant);
//! - `normalized`: the paper's min-max normalisation into [α1, α2];
//! - `final`: the stored loop in playback order, which starts at the split
//!   point p: `final(i)` is the closure's last stage at (i + p) mod N.

mod stages;

use std::{
    fs,
    path::{Path, PathBuf},
};

use anyhow::{Context, Result};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use idle_head_core::{
    Angle, AngleRange, Axis,
    motion::{AxisError, Closure, DEFAULT_HEAD},
};

use crate::{args::LoopShape, project};
use stages::LoopSpec;
pub use stages::{Stages, deg};

/// Options of `cargo xtask preview` (its help text is in `cli.rs`).
#[derive(Debug, Clone, PartialEq, Eq, clap::Args)]
pub struct Args {
    /// Axis whose default row fills in the loop options not given, and whose
    /// anatomical limits the range must respect [default: yaw].
    #[arg(long, ignore_case = true, value_parser = axis_parser())]
    pub axis: Option<Axis>,
    /// LCG seed r(0).
    #[arg(long, value_name = "u32", allow_negative_numbers = true)]
    pub seed: Option<u32>,
    #[command(flatten)]
    pub shape: LoopShape,
    /// Target range [α1, α2] in degrees (decimals allowed).
    #[arg(
        long,
        num_args = 2,
        value_names = ["A1", "A2"],
        allow_negative_numbers = true,
        value_parser = parse_degrees
    )]
    pub range: Option<Vec<Angle>>,
    /// Loop closure [default: seamless].
    #[arg(long, ignore_case = true, value_parser = closure_parser())]
    pub closure: Option<Closure>,
    /// Output directory [default: preview/ at the repository root].
    #[arg(long, value_name = "dir")]
    pub out: Option<PathBuf>,
    /// File stem [default: loop; for the default axes <stem>-<axis>].
    #[arg(long, value_name = "stem", value_parser = parse_stem)]
    pub name: Option<String>,
}

/// `pitch`, `roll` or `yaw`.
fn axis_parser() -> impl TypedValueParser<Value = Axis> {
    PossibleValuesParser::new(Axis::ALL.map(Axis::name)).try_map(|name| {
        Axis::ALL
            .into_iter()
            .find(|axis| axis.name().eq_ignore_ascii_case(&name))
            .ok_or("expected pitch, roll or yaw")
    })
}

/// `paper` or `seamless`.
fn closure_parser() -> impl TypedValueParser<Value = Closure> {
    let closures = [Closure::Paper, Closure::Seamless];
    PossibleValuesParser::new(closures.map(stages::closure_name)).try_map(move |name| {
        closures
            .into_iter()
            .find(|closure| stages::closure_name(*closure).eq_ignore_ascii_case(&name))
            .ok_or("expected paper or seamless")
    })
}

/// An angle in degrees (decimals allowed), to the nearest millidegree. How
/// far it may reach is the core's to say (`AxisConfig::validate`); this
/// only refuses what an [`Angle`] cannot hold at all.
fn parse_degrees(text: &str) -> Result<Angle, String> {
    let degrees: f64 = text
        .parse()
        .map_err(|_| "expected an angle in degrees".to_owned())?;
    let mdeg = (degrees * f64::from(Angle::SCALE)).round();
    if mdeg.is_nan() || mdeg.abs() > f64::from(i32::MAX) {
        return Err(format!("{text}° is not an angle"));
    }
    #[allow(clippy::cast_possible_truncation)] // in range, checked above
    Ok(Angle::from_millidegrees(mdeg as i32))
}

/// A file name stem, without a directory.
fn parse_stem(stem: &str) -> Result<String, String> {
    if stem.is_empty() || stem.contains(['/', '\\']) {
        return Err("expected a file name stem without a directory".to_owned());
    }
    Ok(stem.to_owned())
}

impl Args {
    /// Whether any option selects a single loop.
    fn single(&self) -> bool {
        self.axis.is_some()
            || self.seed.is_some()
            || self.shape.given()
            || self.range.is_some()
            || self.closure.is_some()
    }

    /// The output directory.
    fn out(&self) -> PathBuf {
        self.out
            .clone()
            .unwrap_or_else(|| project::root().join("preview"))
    }

    /// The loops to preview with their file stems, validated by the core: the
    /// three default axes with no loop option, else one loop.
    pub fn loops(&self) -> Result<Vec<(LoopSpec, String)>> {
        let specs = if self.single() {
            let axis = self.axis.unwrap_or(Axis::Yaw);
            let mut cfg = *DEFAULT_HEAD.axis(axis);
            if let Some(seed) = self.seed {
                cfg.seed = seed;
            }
            if let Some(w) = self.shape.w {
                cfg.window = w;
            }
            if let Some(&[min, max]) = self.range.as_deref() {
                cfg.range = AngleRange { min, max };
            }
            if let Some(closure) = self.closure {
                cfg.closure = closure;
            }
            let name = self.name.clone().unwrap_or_else(|| "loop".to_owned());
            let n = self.shape.n();
            vec![(LoopSpec { axis, n, cfg }, name)]
        } else {
            Axis::ALL
                .into_iter()
                .map(|axis| {
                    let spec = LoopSpec {
                        axis,
                        n: self.shape.n(),
                        cfg: *DEFAULT_HEAD.axis(axis),
                    };
                    let name = match &self.name {
                        Some(stem) => format!("{stem}-{}", axis.name()),
                        None => axis.name().to_owned(),
                    };
                    (spec, name)
                })
                .collect()
        };
        for (LoopSpec { axis, n, cfg }, _) in &specs {
            cfg.validate(*axis, *n)
                .map_err(|error| AxisError { axis: *axis, error })?;
        }
        Ok(specs)
    }
}

/// `path` as the user would name it: relative to the current folder when
/// inside it.
fn shown(path: &Path) -> String {
    let here = std::env::current_dir().unwrap_or_default();
    path.strip_prefix(&here)
        .unwrap_or(path)
        .display()
        .to_string()
}

/// `cargo xtask preview`.
pub fn command(args: &Args) -> Result<bool> {
    let loops = args.loops()?;
    let out = args.out();
    fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    for (spec, stem) in loops {
        let stages = Stages::compute(spec)?;
        let csv = out.join(format!("{stem}.csv"));
        let png = out.join(format!("{stem}.png"));
        fs::write(&csv, stages.csv()).with_context(|| format!("writing {}", csv.display()))?;
        crate::plot::stages(&stages, &png)?;
        println!("{}", stages.title());
        for line in &stages.metric_lines() {
            println!("  {line}");
        }
        println!("  wrote {} and {}", shown(&csv), shown(&png));
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use clap::Parser;
    use idle_head_core::motion::DEFAULT_N;

    use super::*;

    #[derive(Parser)]
    struct Preview {
        #[command(flatten)]
        args: Args,
    }

    fn parse(args: &[&str]) -> Result<Args, clap::Error> {
        Preview::try_parse_from(std::iter::once("preview").chain(args.iter().copied()))
            .map(|preview| preview.args)
    }

    fn error(args: &[&str]) -> String {
        parse(args).unwrap_err().to_string()
    }

    #[test]
    fn no_arguments_preview_the_three_default_axes() {
        let args = parse(&[]).unwrap();
        assert_eq!(args.out(), project::root().join("preview"));
        let loops = args.loops().unwrap();
        let names: Vec<&str> = loops.iter().map(|(_, name)| name.as_str()).collect();
        assert_eq!(names, ["pitch", "roll", "yaw"]);
        assert_eq!(loops[0].0.cfg, DEFAULT_HEAD.pitch);
        assert_eq!(loops[2].0.n, DEFAULT_N);
        // --out and --name alone keep the default preview.
        let args = parse(&["--out", "x", "--name", "head"]).unwrap();
        let loops = args.loops().unwrap();
        assert_eq!(loops[1].1, "head-roll");
        assert_eq!(args.out(), PathBuf::from("x"));
    }

    #[test]
    fn one_loop_from_options() {
        let args = "--seed 127 --n=450 --w 31 --range -4.5 12 --closure Paper --axis pitch";
        let loops = parse(&args.split(' ').collect::<Vec<_>>())
            .unwrap()
            .loops()
            .unwrap();
        let [(spec, name)] = &loops[..] else {
            panic!("{loops:?}")
        };
        assert_eq!(
            (name.as_str(), spec.axis, spec.n),
            ("loop", Axis::Pitch, 450)
        );
        let range = AngleRange {
            min: Angle::from_millidegrees(-4500),
            max: Angle::from_degrees(12),
        };
        let cfg = &spec.cfg;
        assert_eq!(
            (cfg.seed, cfg.window, cfg.range, cfg.closure),
            (127, 31, range, Closure::Paper)
        );
        // The yaw default row when only --n is given.
        let loops = parse(&["--n", "450"]).unwrap().loops().unwrap();
        assert_eq!(loops[0].0.cfg, DEFAULT_HEAD.yaw);
    }

    #[test]
    fn bad_options_are_named() {
        assert!(error(&["--closure", "smooth"]).contains("--closure"));
        assert!(error(&["--axis", "sideways"]).contains("--axis"));
        assert!(error(&["--range", "1"]).contains("--range"));
        assert!(error(&["--range", "1", "x"]).contains("--range"));
        assert!(error(&["--range", "1", "1e30"]).contains("--range"));
        assert!(error(&["--seed", "-1"]).contains("--seed"));
        assert!(error(&["--name", "a/b"]).contains("--name"));
        assert!(error(&["--bogus"]).contains("--bogus"));
    }

    #[test]
    fn limits_are_the_cores_to_judge() {
        // A range the firmware cannot play, and a window too small: the error
        // is the core's, as it prints itself.
        for (options, axis, cfg) in [
            (
                &["--range", "-50", "50"][..],
                Axis::Yaw,
                DEFAULT_HEAD.yaw.with_range(AngleRange::degrees(-50, 50)),
            ),
            (
                &["--axis", "pitch", "--range", "-30", "10"],
                Axis::Pitch,
                DEFAULT_HEAD.pitch.with_range(AngleRange::degrees(-30, 10)),
            ),
            (&["--w", "2"], Axis::Yaw, DEFAULT_HEAD.yaw.with_window(2)),
        ] {
            let error = parse(options).unwrap().loops().unwrap_err();
            let core = AxisError {
                axis,
                error: cfg.validate(axis, DEFAULT_N).unwrap_err(),
            };
            assert_eq!(format!("{error:#}"), core.to_string());
        }
    }
}
