//! An operation's flags, derived from its spec (`motion_homing::params`):
//! `SpecArgs<MoveSpec>` flattened into a subcommand gives it one flag per
//! parameter the operator sets — `--speed V`, a switch's `--flag`, `--to P
//! | --by D` — with the parameter's doc as help, and parses them back into
//! the spec the engine declared. A parameter added to a spec is a flag
//! here (and in the man page and completions) without a line of this
//! crate changing.
//!
//! Every number goes through the same parser as the rest of the command
//! line (finite, within ±1e9; an optional one, a magnitude, unsigned);
//! whether a value is allowed (a speed above `max_speed`, a deceleration
//! above `max_deceleration`) is the engine's to judge, with its ERR /
//! EXERR. A hold-to-run operation's lease is not a
//! flag: the tool renews it.

use clap::builder::PossibleValuesParser;
use clap::error::ErrorKind;
use clap::{Arg, ArgAction, ArgGroup, ArgMatches, Args, Command, FromArgMatches};
use motion_config::args::{axis, number};
use motion_control::params::{AxisRef, Carried, Form, Kind, Param, Place, Spec};
use std::marker::PhantomData;

/// The flags of spec `S`, and the spec they gave.
#[derive(Clone, Debug)]
pub struct SpecArgs<S> {
    pub spec: S,
    _of: PhantomData<S>,
}

/// The help line of a parameter: its doc comment, its unit and default
/// already in it.
fn help(p: &Param) -> String {
    let doc: Vec<&str> = p.doc.lines().map(str::trim).collect();
    doc.join(" ").replace('`', "")
}

/// The flag (or flags) of one parameter of a spec with `params`.
fn args_of(p: &Param, params: &[Param]) -> Vec<Arg> {
    let flag = |name: &'static str, metavar: &'static str| {
        let a = Arg::new(name).long(name).help(help(p));
        match p.kind {
            Kind::Switch => a.action(ArgAction::SetTrue),
            // Left out: the first choice (the engine's default variant).
            Kind::Choice(choices) => a
                .value_name(metavar)
                .value_parser(PossibleValuesParser::new(choices.iter().copied()))
                .default_value(choices[0]),
            Kind::Axis => a.value_name(metavar).value_parser(axis),
            Kind::Pair => a
                .num_args(2)
                .value_names(["LO", "HI"])
                .allow_negative_numbers(true)
                .value_parser(number),
            // A number that must be given may be signed (a jog's speed, a
            // target); the optional ones are magnitudes (speeds,
            // accelerations), as on every command line before.
            Kind::Number | Kind::Optional => a
                .value_name(metavar)
                .allow_negative_numbers(p.kind == Kind::Number)
                .value_parser(number)
                .required(p.kind == Kind::Number),
        }
    };
    match p.form {
        Form::Flag { flag: f, metavar } => vec![flag(f, metavar)],
        Form::Either { off, on, switch } => {
            let switched = params
                .iter()
                .find(|q| q.name == switch)
                .map_or(String::new(), help);
            vec![
                flag(off.0, off.1).required(false),
                flag(on.0, on.1)
                    .required(false)
                    .help(format!("As --{}, with {switch}: {switched}", off.0)),
            ]
        }
        Form::Implied | Form::Lease => Vec::new(),
    }
}

/// Writes what the flags of `p` gave into `c`.
fn carry(p: &Param, params: &[Param], m: &ArgMatches, c: &mut Carried) {
    let number = |id: &str| m.get_one::<f64>(id).copied();
    let set = |c: &mut Carried, x: f64| {
        if let Place::Slot(s) = p.place {
            c.values[s] = x;
        }
    };
    match p.form {
        Form::Flag { flag, .. } => match p.kind {
            Kind::Switch => {
                if let (Place::Bit(b), true) = (p.place, m.get_flag(flag)) {
                    c.switches |= 1 << b;
                }
            }
            Kind::Choice(choices) => {
                let given = m.get_one::<String>(flag);
                if let Some(i) = given.and_then(|g| choices.iter().position(|x| x == g)) {
                    set(c, i as f64);
                }
            }
            Kind::Axis => {
                let named = m.get_one::<String>(flag).and_then(|n| AxisRef::named(n));
                if let Some(AxisRef::Name(n)) = named {
                    c.name = n;
                }
            }
            Kind::Pair => {
                let pair: Vec<f64> = m
                    .get_many::<f64>(flag)
                    .into_iter()
                    .flatten()
                    .copied()
                    .collect();
                if let (Place::Slot(s), [lo, hi]) = (p.place, pair.as_slice()) {
                    (c.values[s], c.values[s + 1]) = (*lo, *hi);
                }
            }
            Kind::Number | Kind::Optional => {
                if let Some(x) = number(flag) {
                    set(c, x);
                }
            }
        },
        Form::Either { off, on, switch } => {
            let (x, on) = match (number(off.0), number(on.0)) {
                (Some(x), _) => (Some(x), false),
                (None, y) => (y, y.is_some()),
            };
            if let Some(x) = x {
                set(c, x);
            }
            let bit = params.iter().find(|q| q.name == switch).map(|q| q.place);
            if let (Some(Place::Bit(b)), true) = (bit, on) {
                c.switches |= 1 << b;
            }
        }
        Form::Implied | Form::Lease => {}
    }
}

impl<S: Spec> FromArgMatches for SpecArgs<S> {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut c = Carried::EMPTY;
        for p in S::PARAMS {
            carry(p, S::PARAMS, m, &mut c);
        }
        let spec = S::take(&c).map_err(|e| clap::Error::raw(ErrorKind::ValueValidation, e))?;
        Ok(SpecArgs {
            spec,
            _of: PhantomData,
        })
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl<S: Spec> Args for SpecArgs<S> {
    fn augment_args(mut cmd: Command) -> Command {
        for p in S::PARAMS {
            for a in args_of(p, S::PARAMS) {
                cmd = cmd.arg(a);
            }
            if let Form::Either { off, on, .. } = p.form {
                let group = ArgGroup::new(p.name)
                    .args([off.0, on.0])
                    .required(p.kind == Kind::Number);
                cmd = cmd.group(group);
            }
        }
        cmd
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use motion_control::{JogSpec, MoveSpec};

    #[derive(Debug, Parser)]
    struct Move {
        #[command(flatten)]
        spec: SpecArgs<MoveSpec>,
    }

    #[derive(Debug, Parser)]
    struct Jog {
        #[command(flatten)]
        spec: SpecArgs<JogSpec>,
    }

    fn parse<P: Parser>(args: &str) -> Result<P, clap::Error> {
        P::try_parse_from(std::iter::once("x").chain(args.split_whitespace()))
    }

    #[test]
    fn a_move_s_flags_are_its_spec_s_fields() {
        let m: Move = parse("--to -2.5 --speed 3").unwrap();
        assert_eq!(
            m.spec.spec,
            MoveSpec {
                speed: Some(3.0),
                ..MoveSpec::to(-2.5)
            }
        );
        // Each switch of the spec is a bare flag setting its bit.
        for p in MoveSpec::PARAMS {
            if let (Form::Flag { flag, .. }, Place::Bit(b)) = (p.form, p.place) {
                let m: Move = parse(&format!("--to 1 --{flag}")).unwrap();
                let mut c = Carried::EMPTY;
                m.spec.spec.carry(&mut c);
                assert_eq!(c.switches, 1 << b, "{flag}");
            }
        }
        let m: Move = parse("--by 4 --accel 100 --decel 200").unwrap();
        assert_eq!(
            m.spec.spec,
            MoveSpec {
                relative: true,
                accel: Some(100.0),
                decel: Some(200.0),
                ..MoveSpec::to(4.0)
            }
        );
        for bad in [
            "",
            "--to 1 --by 2",
            "--to nan",
            "--to 1 --relative",
            "--by 1 --lease 2",
        ] {
            assert!(parse::<Move>(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_jog_s_speed_is_required_and_its_lease_is_the_tool_s() {
        let j: Jog = parse("--speed -2 --decel 40").unwrap();
        assert_eq!(
            j.spec.spec,
            JogSpec {
                decel: Some(40.0),
                ..JogSpec::at(-2.0)
            }
        );
        assert!(parse::<Jog>("--accel 5").is_err());
        assert!(parse::<Jog>("--speed 1 --lease 1").is_err());
        assert!(parse::<Jog>("--speed 1 --duration 1").is_err());
    }
}
