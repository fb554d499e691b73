//! Small helpers for the commands that take their own options
//! (`preview`, `metrics`): `--flag value` and `--flag=value`.

use std::str::FromStr;

use anyhow::{Context, Result};

/// Splits `--flag=value` into the flag and its inline value.
pub fn split(arg: &str) -> (&str, Option<&str>) {
    match arg.split_once('=') {
        Some((flag, value)) if flag.starts_with("--") => (flag, Some(value)),
        _ => (arg, None),
    }
}

/// The value of `flag`: the inline one, or the next argument.
pub fn value(
    flag: &str,
    inline: Option<&str>,
    args: &mut impl Iterator<Item = String>,
    what: &str,
) -> Result<String> {
    match inline {
        Some(value) => Ok(value.to_owned()),
        None => args
            .next()
            .with_context(|| format!("`{flag}` needs {what}")),
    }
}

/// Parses `value` of `flag` as a `T`, naming both on failure.
pub fn parse<T: FromStr>(flag: &str, value: &str, what: &str) -> Result<T>
where
    T::Err: std::error::Error + Send + Sync + 'static,
{
    value
        .replace('_', "")
        .parse()
        .with_context(|| format!("`{flag} {value}`: expected {what}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inline_and_separate_values() {
        assert_eq!(split("--n=900"), ("--n", Some("900")));
        assert_eq!(split("--n"), ("--n", None));
        assert_eq!(split("x=1"), ("x=1", None));
        let mut rest = ["450".to_owned()].into_iter();
        assert_eq!(value("--n", None, &mut rest, "N").unwrap(), "450");
        assert!(value("--n", None, &mut rest, "N").is_err());
        assert_eq!(value("--n", Some("9"), &mut rest, "N").unwrap(), "9");
        assert_eq!(
            parse::<u32>("--seeds", "10_000", "a count").unwrap(),
            10_000
        );
        assert!(parse::<u32>("--seeds", "-1", "a count").is_err());
    }
}
