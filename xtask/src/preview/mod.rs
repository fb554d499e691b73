//! `cargo xtask preview`: the stages of a loop from the core's engine, as
//! `<out>/<stem>.csv` and `.png` (`stages.rs`).

mod stages;

use std::path::PathBuf;

use anyhow::Result;
use idle_head_core::{
    Angle, AngleRange, Axis,
    motion::{AxisError, Closure, DEFAULT_HEAD},
};

use crate::{args::LoopShape, project};
use stages::LoopSpec;
pub use stages::Stages;

/// Options of `cargo xtask preview` (its help text is in `cli.rs`).
#[derive(Debug, Clone, PartialEq, Eq, clap::Args)]
pub struct Args {
    /// Axis (pitch, roll or yaw) whose default row fills in the loop options
    /// not given, and whose anatomical limits the range must respect
    /// [default: yaw].
    #[arg(long, value_parser = |s: &str| one_of(s, Axis::ALL, Axis::name))]
    pub axis: Option<Axis>,
    /// LCG seed r(0).
    #[arg(long, value_name = "u32", allow_negative_numbers = true)]
    pub seed: Option<u32>,
    #[command(flatten)]
    pub shape: LoopShape,
    /// Target range [α1, α2] in degrees (decimals allowed).
    #[arg(long, num_args = 2, value_names = ["A1", "A2"], allow_negative_numbers = true,
          value_parser = parse_degrees)]
    pub range: Option<Vec<Angle>>,
    /// Loop closure, paper or seamless [default: seamless].
    #[arg(long, value_parser = |s: &str| one_of(s, [Closure::Paper, Closure::Seamless], stages::closure_name))]
    pub closure: Option<Closure>,
    /// Output directory [default: preview/ at the repository root].
    #[arg(long, value_name = "dir")]
    pub out: Option<PathBuf>,
    /// File stem [default: loop; for the default axes <stem>-<axis>].
    #[arg(long, value_name = "stem", value_parser = parse_stem)]
    pub name: Option<String>,
}

/// The one of `values` whose `name` is `text`, whatever its case.
fn one_of<T: Copy, const N: usize>(
    text: &str,
    values: [T; N],
    name: fn(T) -> &'static str,
) -> Result<T, String> {
    let found = values
        .into_iter()
        .find(|&v| name(v).eq_ignore_ascii_case(text));
    found.ok_or_else(|| format!("expected one of {}", values.map(name).join(", ")))
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
    /// The loops to preview with their file stems, validated by the core:
    /// the three default axes with no loop option, else one loop.
    pub fn loops(&self) -> Result<Vec<(LoopSpec, String)>> {
        let single = self.axis.is_some()
            || self.seed.is_some()
            || self.shape != LoopShape::default()
            || self.range.is_some()
            || self.closure.is_some();
        let n = self.shape.n();
        let specs = if single {
            let axis = self.axis.unwrap_or(Axis::Yaw);
            let mut cfg = *DEFAULT_HEAD.axis(axis);
            cfg.seed = self.seed.unwrap_or(cfg.seed);
            cfg.window = self.shape.w.unwrap_or(cfg.window);
            if let Some(&[min, max]) = self.range.as_deref() {
                cfg.range = AngleRange { min, max };
            }
            cfg.closure = self.closure.unwrap_or(cfg.closure);
            let name = self.name.clone().unwrap_or_else(|| "loop".to_owned());
            vec![(LoopSpec { axis, n, cfg }, name)]
        } else {
            let stem = |axis: Axis| match &self.name {
                Some(stem) => format!("{stem}-{}", axis.name()),
                None => axis.name().to_owned(),
            };
            let spec = |axis: Axis| {
                let cfg = *DEFAULT_HEAD.axis(axis);
                (LoopSpec { axis, n, cfg }, stem(axis))
            };
            Axis::ALL.map(spec).into()
        };
        for (LoopSpec { axis, n, cfg }, _) in &specs {
            cfg.validate(*axis, *n)
                .map_err(|error| AxisError { axis: *axis, error })?;
        }
        Ok(specs)
    }
}

pub fn command(args: &Args) -> Result<bool> {
    let out = (args.out.clone()).unwrap_or_else(|| project::root().join("preview"));
    // Paths as the user would name them: relative to the current folder.
    let here = std::env::current_dir().unwrap_or_default();
    for (spec, stem) in args.loops()? {
        let stages = Stages::compute(spec)?;
        let [csv, png] = ["csv", "png"].map(|ext| out.join(format!("{stem}.{ext}")));
        project::write(&csv, stages.csv())?;
        stages::draw(&stages, &png)?;
        println!("{}", stages.title());
        for line in &stages.metric_lines() {
            println!("  {line}");
        }
        let [csv, png] =
            [csv, png].map(|p| p.strip_prefix(&here).unwrap_or(&p).display().to_string());
        println!("  wrote {csv} and {png}");
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

    fn loops(args: &str) -> Result<Vec<(LoopSpec, String)>> {
        let args = std::iter::once("preview").chain(args.split_whitespace());
        Preview::try_parse_from(args)?.args.loops()
    }

    #[test]
    fn the_default_axes_one_loop_from_options_and_the_cores_limits() {
        let three = loops("--name head").unwrap();
        let names: Vec<&str> = three.iter().map(|(_, name)| name.as_str()).collect();
        assert_eq!(names, ["head-pitch", "head-roll", "head-yaw"]);
        let first = (three[0].0.cfg, three[2].0.n);
        assert_eq!(first, (DEFAULT_HEAD.pitch, DEFAULT_N));
        let one = loops("--seed 127 --n=450 --w 31 --range -4.5 12 --closure Paper --axis pitch");
        let one = one.unwrap();
        let [(spec, name)] = &one[..] else {
            panic!("{one:?}")
        };
        assert_eq!((name.as_str(), spec.axis), ("loop", Axis::Pitch));
        assert_eq!(spec.n, 450);
        let range = AngleRange {
            min: Angle::from_millidegrees(-4500),
            max: Angle::from_degrees(12),
        };
        let cfg = &spec.cfg;
        assert_eq!((cfg.seed, cfg.window), (127, 31));
        assert_eq!((cfg.range, cfg.closure), (range, Closure::Paper));
        let bad = "--closure smooth|--axis sideways|--range 1 1e30|--name a/b";
        for bad in bad.split('|') {
            assert!(loops(bad).is_err(), "{bad}");
        }
        // A range the firmware cannot play: the error is the core's.
        let cfg = DEFAULT_HEAD.yaw.with_range(AngleRange::degrees(-50, 50));
        let core = AxisError {
            axis: Axis::Yaw,
            error: cfg.validate(Axis::Yaw, DEFAULT_N).unwrap_err(),
        };
        let error = loops("--range -50 50").unwrap_err();
        assert_eq!(format!("{error:#}"), core.to_string());
    }
}
