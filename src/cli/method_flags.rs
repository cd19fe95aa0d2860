//! The methods' own command-line flags (`crate::methods::MethodFlag`, declared by each module
//! beside its settings), offered by `render` and `sheet` as one clap argument group built from
//! the registry: a new method's flags need no line here.

use clap::{Arg, ArgAction, ArgMatches, Command, FromArgMatches};

use crate::methods::{FlagKind, MethodFlag, flags};
use crate::settings::RenderSettings;

/// The methods' flags given on the command line, as (flag, settings path, TOML value).
#[derive(Clone, Debug, Default)]
pub struct MethodFlagArgs {
    pub given: Vec<(&'static str, &'static str, String)>,
}

impl MethodFlagArgs {
    /// Writes each given flag's value into the settings (the error names the flag).
    pub fn apply(&self, s: &mut RenderSettings) -> anyhow::Result<()> {
        for (long, path, value) in &self.given {
            s.set_path(path, value)
                .map_err(|e| anyhow::anyhow!("--{long}: {e}"))?;
        }
        Ok(())
    }
}

fn arg(f: &'static MethodFlag) -> Arg {
    let a = Arg::new(f.long).long(f.long).help(f.help);
    match f.kind {
        FlagKind::Number(name) => a
            .value_name(name)
            .value_parser(clap::value_parser!(f64))
            .action(ArgAction::Set),
        FlagKind::Choice(words) => a
            .value_parser(clap::builder::PossibleValuesParser::new(
                words.iter().map(|(w, _)| *w),
            ))
            .action(ArgAction::Set),
        FlagKind::Switch(_) => a.action(ArgAction::SetTrue),
    }
}

impl clap::Args for MethodFlagArgs {
    fn augment_args(mut cmd: Command) -> Command {
        for f in flags() {
            cmd = cmd.arg(arg(f));
        }
        cmd
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl FromArgMatches for MethodFlagArgs {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut given = Vec::new();
        for f in flags() {
            let value = match f.kind {
                FlagKind::Number(_) => m.get_one::<f64>(f.long).map(|v| number(*v)),
                FlagKind::Choice(words) => m
                    .get_one::<String>(f.long)
                    .and_then(|w| words.iter().find(|(c, _)| c == w))
                    .map(|(_, v)| format!("\"{v}\"")),
                FlagKind::Switch(v) => m.get_flag(f.long).then(|| v.to_string()),
            };
            if let Some(v) = value {
                given.push((f.long, f.path, v));
            }
        }
        Ok(Self { given })
    }
    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

/// A number as a TOML value: an integer where it is one (an integer setting refuses 8.0).
fn number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        flags: MethodFlagArgs,
    }

    #[test]
    fn every_declared_flag_parses_and_sets_its_path() {
        for f in flags() {
            let mut argv = vec!["x".to_string(), format!("--{}", f.long)];
            match f.kind {
                FlagKind::Number(_) => argv.push("1".into()),
                FlagKind::Choice(words) => argv.push(words[words.len() - 1].0.into()),
                FlagKind::Switch(_) => {}
            }
            let cli = Cli::try_parse_from(&argv).unwrap_or_else(|e| panic!("{argv:?}: {e}"));
            assert_eq!(cli.flags.given.len(), 1, "{argv:?}");
            let mut s = RenderSettings::default();
            cli.flags
                .apply(&mut s)
                .unwrap_or_else(|e| panic!("{argv:?}: {e}"));
            // The path now holds the flag's value.
            let root = toml::Table::try_from(&s).unwrap();
            let mut v = &toml::Value::Table(root);
            for p in f.path.split('.') {
                v = v
                    .get(p)
                    .unwrap_or_else(|| panic!("{argv:?}: {} not written", f.path));
            }
            let want: toml::Value =
                toml::from_str::<toml::Table>(&format!("v = {}", cli.flags.given[0].2)).unwrap()["v"].clone();
            let num = |x: &toml::Value| x.as_float().or(x.as_integer().map(|i| i as f64));
            if matches!(f.kind, FlagKind::Number(_)) {
                assert_eq!(num(v), num(&want), "{argv:?}");
            } else {
                assert_eq!(v, &want, "{argv:?}");
            }
        }
        assert!(Cli::try_parse_from(["x", "--cut-size", "many"]).is_err());
        assert_eq!(number(8.0), "8");
        assert_eq!(number(0.05), "0.05");
    }
}
