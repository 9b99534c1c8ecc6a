//! The method handlers' decoding and answering, fuzzed: any argument list
//! (names, NaN, huge numbers, wrong types, too few or too many) is decoded
//! into a bounded request or refused with a status — never a panic — and
//! any control answer becomes outputs matching the declared arguments.

use super::*;
use opcua::types::{LocalizedText, UAString};
use proptest::prelude::*;

fn any_variant() -> impl Strategy<Value = Variant> {
    let name = prop_oneof![
        "[A-Za-z0-9_.-]{0,40}",
        any::<String>(),
        Just("X\0Y".to_string()),
        Just("x".repeat(33)),
    ];
    prop_oneof![
        Just(Variant::Empty),
        any::<bool>().prop_map(Variant::from),
        any::<f64>().prop_map(Variant::from),
        prop_oneof![
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(-1.0),
            Just(1e308),
            Just(86_400.0),
            Just(86_400.5),
            Just(0.0)
        ]
        .prop_map(Variant::from),
        any::<f32>().prop_map(Variant::from),
        any::<i64>().prop_map(Variant::from),
        any::<u16>().prop_map(Variant::from),
        name.clone().prop_map(|s| Variant::from(UAString::from(s))),
        proptest::collection::vec(name, 0..70)
            .prop_map(|v| { Variant::from(v.into_iter().map(UAString::from).collect::<Vec<_>>()) }),
        proptest::collection::vec(any::<i32>(), 0..5).prop_map(Variant::from),
        Just(Variant::from(LocalizedText::new("", "X"))),
    ]
}

fn check_request(call: &Call) {
    let r = call.request();
    assert!((r.axis_count as usize) <= MAX_AXES);
    assert!(r.timeout_s.is_finite() && (0.0..=MAX_TIMEOUT_S).contains(&r.timeout_s));
    let names = r.axis_names();
    match call {
        Call::Home { axes, .. } | Call::Stop { axes } | Call::Unhome { axes } => {
            assert!(matches!(r.kind, REQ_HOME | REQ_STOP | REQ_UNHOME));
            assert_eq!(&names, axes, "every name carried as given");
        }
        Call::Operate { axis, op } => {
            assert_eq!(r.kind, REQ_OPERATE);
            assert_eq!(names, vec![axis.clone()]);
            // What the daemon decodes is the operation decoded here.
            let Ok(Request::Operate { op: got, .. }) = Request::decode(&r) else {
                panic!("{op:?} does not decode");
            };
            assert_eq!(got, *op);
            let c = op.carried();
            for (p, x) in op.kind().params().iter().zip(0..) {
                if let params::Place::Slot(s) = p.place {
                    let v = c.values[s];
                    assert!(v.is_nan() || v.abs() <= MAX_ABS, "{p:?} {x}");
                }
            }
            if let Operation::Jog(j) = op {
                assert!(j.speed.is_finite() && j.speed.abs() <= MAX_ABS);
                assert!(j.lease.is_none_or(|l| l > 0.0 && l <= MAX_JOG_S));
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn any_arguments_are_decoded_or_refused(
        m in 0..methods().len(),
        axis in prop_oneof![Just(None), Just(Some("X")), "[A-Z]{1,3}".prop_map(|s| Some(Box::leak(s.into_boxed_str()) as &str))],
        args in proptest::collection::vec(any_variant(), 0..5),
    ) {
        let spec = &methods()[m];
        match decode(spec, axis, &args) {
            Ok(op) => {
                prop_assert!(args.len() <= spec.inputs.len());
                check_request(&op);
                if spec.scope == Scope::Axis {
                    let r = op.request();
                    prop_assert_eq!(r.axis_names(), vec![axis.unwrap().to_string()]);
                }
            }
            Err(CallError::Status(s)) => prop_assert!(s.is_bad()),
            Err(CallError::Args(a)) => {
                prop_assert_eq!(a.len(), args.len());
                prop_assert!(a.iter().any(|s| s.is_bad()));
            }
        }
    }

    #[test]
    fn any_answer_becomes_declared_outputs(
        result in 0u32..6,
        n in 0u32..80,
        accepted in any::<bool>(),
        reason in any::<u8>(),
        err in any::<u16>(),
        msg in any::<String>(),
    ) {
        let mut r = ControlResponse::zeroed();
        r.result = result;
        r.axis_count = n; // hostile counts are clamped by answers()
        for a in r.axes.iter_mut() {
            put_str(&mut a.name, "X");
            a.accepted = accepted as u8;
            a.reason = reason;
            a.err = err;
        }
        put_str(&mut r.message, &msg);
        for scope in [Scope::Axis, Scope::Machine] {
            let out = outputs(scope, &r);
            prop_assert_eq!(out.len(), output_args(scope).len());
        }
        let s = status_of(&r);
        prop_assert_eq!(s.is_good(), result == RESULT_ACCEPTED);
    }
}

#[test]
fn a_home_call_carries_its_timeout_and_refusals_say_why() {
    let home = spec("Home", Scope::Axis).unwrap();
    assert_eq!(
        decode(home, Some("X"), &[Variant::from(5.0)]),
        Ok(Call::Home {
            axes: vec!["X".into()],
            parallel: false,
            timeout_s: 5.0
        })
    );
    assert_eq!(
        decode(home, Some("X"), &[Variant::from(f64::NAN)]),
        Err(CallError::Args(vec![StatusCode::BadOutOfRange]))
    );
    assert_eq!(
        decode(home, Some("X"), &[Variant::from("5")]),
        Err(CallError::Args(vec![StatusCode::BadTypeMismatch]))
    );
    assert_eq!(
        decode(home, Some("X"), &[]),
        Err(CallError::Status(StatusCode::BadArgumentsMissing))
    );
    let all = spec("HomeAll", Scope::Machine).unwrap();
    let op = decode(
        all,
        None,
        &[
            Variant::from(vec![UAString::from("X"), UAString::from("Z")]),
            Variant::from(true),
            Variant::from(0.0),
        ],
    )
    .unwrap();
    assert_eq!(op.request().flags, FLAG_PARALLEL);
    // A refusal: BadInvalidState with the reason and ERR/EXERR as outputs.
    let mut r = ControlResponse::zeroed();
    r.result = RESULT_REFUSED;
    r.axis_count = 1;
    put_str(&mut r.axes[0].name, "X");
    r.axes[0].reason = REASON_INSTRUCTION;
    r.axes[0].err = 41;
    r.axes[0].exerr = 20;
    assert_eq!(status_of(&r), StatusCode::BadInvalidState);
    let out = outputs(Scope::Axis, &r);
    assert_eq!(out[0], Variant::from(false));
    assert_eq!(out[1], Variant::from("refused by the Home instruction"));
    assert_eq!(
        (out[2].clone(), out[3].clone()),
        (Variant::from(41u16), Variant::from(20u16))
    );
    r.axes[0].reason = REASON_UNKNOWN_AXIS;
    assert_eq!(status_of(&r), StatusCode::BadInvalidArgument);
}

#[test]
fn operations_decode_with_their_bounds() {
    let jog = spec("Jog", Scope::Axis).unwrap();
    let names: Vec<&str> = jog.inputs.iter().map(|a| a.name).collect();
    assert_eq!(names, ["Speed", "Duration", "Accel", "Decel", "Jerk"]);
    assert_eq!(
        decode(jog, Some("X"), &[Variant::from(-5.0), Variant::from(0.5)]),
        Ok(Call::Operate {
            axis: "X".into(),
            op: Operation::Jog(JogSpec {
                lease: Some(0.5),
                ..JogSpec::at(-5.0)
            })
        })
    );
    // The lease is the caller's to state: hold to run.
    assert_eq!(
        decode(jog, Some("X"), &[Variant::from(2.0)]),
        Err(CallError::Status(StatusCode::BadArgumentsMissing))
    );
    assert_eq!(
        decode(jog, Some("X"), &[Variant::from(2.0), Variant::Empty]),
        Err(CallError::Args(vec![
            StatusCode::Good,
            StatusCode::BadTypeMismatch
        ]))
    );
    for (speed, dur, bad) in [
        (f64::NAN, 1.0, [StatusCode::BadOutOfRange, StatusCode::Good]),
        (1e300, 1.0, [StatusCode::BadOutOfRange, StatusCode::Good]),
        (1.0, 0.0, [StatusCode::Good, StatusCode::BadOutOfRange]),
        // Hold to run: a lease longer than a second is refused.
        (1.0, 10.0, [StatusCode::Good, StatusCode::BadOutOfRange]),
        (
            1.0,
            MAX_JOG_S + 0.1,
            [StatusCode::Good, StatusCode::BadOutOfRange],
        ),
        (
            1.0,
            f64::INFINITY,
            [StatusCode::Good, StatusCode::BadOutOfRange],
        ),
    ] {
        assert_eq!(
            decode(jog, Some("X"), &[Variant::from(speed), Variant::from(dur)]),
            Err(CallError::Args(bad.to_vec())),
            "{speed} {dur}"
        );
    }
    assert_eq!(
        decode(jog, Some("X"), &[]),
        Err(CallError::Status(StatusCode::BadArgumentsMissing))
    );
    let mv = spec("Move", Scope::Axis).unwrap();
    let names: Vec<&str> = mv.inputs.iter().map(|a| a.name).collect();
    assert_eq!(
        names,
        [
            "Target",
            "Relative",
            "Speed",
            "Accel",
            "Decel",
            "Supersede",
            "Jerk"
        ]
    );
    let call = decode(
        mv,
        Some("X"),
        &[Variant::from(12.5), Variant::from(true), Variant::Empty],
    )
    .unwrap();
    assert_eq!(
        call,
        Call::Operate {
            axis: "X".into(),
            op: Operation::Move(MoveSpec {
                relative: true,
                ..MoveSpec::to(12.5)
            })
        }
    );
    let r = call.request();
    assert_eq!((r.kind, r.op), (REQ_OPERATE, OpKind::Move as u32));
    assert!(r.values[1].is_nan(), "Speed null: the default");
    assert_eq!(
        decode(
            mv,
            Some("X"),
            &[
                Variant::from(1.0),
                Variant::from(false),
                Variant::from(3.0),
                Variant::Empty,
                Variant::from(40.0),
                Variant::from(true)
            ]
        ),
        Ok(Call::Operate {
            axis: "X".into(),
            op: Operation::Move(MoveSpec {
                speed: Some(3.0),
                decel: Some(40.0),
                supersede: true,
                ..MoveSpec::to(1.0)
            })
        })
    );
    assert_eq!(
        decode(
            mv,
            Some("X"),
            &[Variant::from(1.0), Variant::from(1i32), Variant::from("3")]
        ),
        Err(CallError::Args(vec![
            StatusCode::Good,
            StatusCode::BadTypeMismatch,
            StatusCode::BadTypeMismatch
        ]))
    );
    for (name, op) in [
        ("Enable", Operation::Enable),
        ("Disable", Operation::Disable),
        ("Reset", Operation::Reset),
    ] {
        let call = decode(spec(name, Scope::Axis).unwrap(), Some("X"), &[]).unwrap();
        assert_eq!(
            call,
            Call::Operate {
                axis: "X".into(),
                op
            }
        );
        assert_eq!(call.request().axis_names(), vec!["X".to_string()]);
    }
}

/// Every operation a client may ask for is a method on every axis, with
/// its spec's parameters as arguments — none written here.
#[test]
fn every_client_operation_is_a_method_with_its_spec_s_arguments() {
    for k in OpKind::ALL.iter().filter(|k| k.client()) {
        let m = spec(k.title(), Scope::Axis).expect("a method per operation");
        assert_eq!(m.verb, Verb::Op(*k));
        let args: Vec<&str> = m.inputs.iter().map(|a| a.name).collect();
        let titles: Vec<&str> = k.params().iter().map(|p| p.title).collect();
        assert_eq!(args, titles, "{k:?}");
    }
    assert!(spec("StreamStart", Scope::Axis).is_none());
}
