//! Strategies for hostile values, changes to a field, and TOML-ish text.

use proptest::prelude::*;
use toml::{Table, Value};

/// Zero, negative, NaN, infinite, huge, tiny and arbitrary numbers.
pub(crate) fn number() -> impl Strategy<Value = Value> {
    prop_oneof![
        prop::sample::select(vec![
            0.0,
            -0.0,
            -1.0,
            0.5,
            1.0,
            2.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e300,
            -1e300,
            1e-300,
            -1e-300,
            5e-324,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            1e15,
        ])
        .prop_map(Value::Float),
        prop::sample::select(vec![
            0i64,
            -1,
            1,
            2,
            3,
            4,
            8,
            9,
            64,
            65,
            10_001,
            i64::MAX,
            i64::MIN
        ])
        .prop_map(Value::Integer),
        // Any bit pattern: subnormals, NaN payloads, everything.
        any::<u64>().prop_map(|b| Value::Float(f64::from_bits(b))),
        // Log-uniform over the whole range, either sign.
        (any::<bool>(), -320.0..308.0f64).prop_map(|(neg, e)| {
            let v = 10f64.powf(e);
            Value::Float(if neg { -v } else { v })
        }),
        any::<i64>().prop_map(Value::Integer),
    ]
}

/// Values of every other TOML type.
pub(crate) fn mistyped() -> impl Strategy<Value = Value> {
    prop_oneof![
        Just(Value::String(String::new())),
        Just(Value::String("x".into())),
        ".{0,12}".prop_map(Value::String),
        Just(Value::Boolean(true)),
        Just(Value::Array(Vec::new())),
        Just(Value::Table(Table::new())),
        prop::collection::vec(number(), 0..5).prop_map(Value::Array),
        Just(Value::Array(vec![
            Value::String("1".into()),
            Value::Float(1.0)
        ])),
        Just(Value::Table(
            [("x".to_string(), Value::Float(1.0))].into_iter().collect()
        )),
    ]
}

pub(crate) fn any_value() -> impl Strategy<Value = Value> {
    prop_oneof![3 => number(), 1 => mistyped()]
}

/// How to change a field.
#[derive(Clone, Debug)]
pub(crate) enum Change {
    Set(Value),
    /// Multiply a number (or every component of a vector) by this factor.
    Scale(f64),
    Delete,
}

pub(crate) fn change() -> impl Strategy<Value = Change> {
    prop_oneof![
        6 => any_value().prop_map(Change::Set),
        2 => prop::sample::select(vec![-1.0, 0.0, 0.5, 0.999, 1.001, 2.0, 10.0, 1e-3, 1e3])
            .prop_map(Change::Scale),
        1 => Just(Change::Delete),
    ]
}

/// Mostly small rescalings (most of them still valid, so that combinations reach the particle
/// builder), sometimes any change.
pub(crate) fn gentle_change() -> impl Strategy<Value = Change> {
    prop_oneof![
        3 => (-2.5..2.5f64).prop_map(|e| Change::Scale(e.exp())),
        1 => change(),
    ]
}

/// The changed value, `None` for a deletion.
pub(crate) fn apply(change: &Change, old: &Value) -> Option<Value> {
    match change {
        Change::Set(v) => Some(v.clone()),
        Change::Delete => None,
        Change::Scale(k) => Some(match old {
            Value::Float(x) => Value::Float(x * k),
            Value::Integer(x) => Value::Float(*x as f64 * k),
            Value::Array(items) => Value::Array(
                items
                    .iter()
                    .map(|v| apply(change, v).unwrap_or_else(|| v.clone()))
                    .collect(),
            ),
            other => other.clone(),
        }),
    }
}

pub(crate) fn is_number(v: &Value) -> bool {
    matches!(v, Value::Float(_) | Value::Integer(_))
}

pub(crate) fn finite_number(v: &Value) -> bool {
    match v {
        Value::Float(x) => x.is_finite(),
        Value::Integer(_) => true,
        _ => false,
    }
}

/// TOML-ish tokens, so that arbitrary text gets past the parser now and then.
pub(crate) fn token() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "\n",
            " = ",
            "[",
            "]",
            "[[",
            "]]",
            "{",
            "}",
            ",",
            ".",
            "#",
            "\"",
            "'",
            "'''",
            "\"\"\"",
            "dimension",
            "particles",
            "dx_m",
            "physics",
            "time",
            "end_s",
            "output_every_s",
            "tank",
            "min_m",
            "max_m",
            "fluid_block",
            "probe",
            "body",
            "motion",
            "kind",
            "nan",
            "inf",
            "-inf",
            "1e400",
            "-0",
            "0x7f",
            "1979-05-27T07:32:00Z",
            "true",
            "2",
            "3",
            "0.01",
            "\"circle\"",
            "\\u0000",
            "\u{feff}",
            "\r",
        ])
        .prop_map(str::to_string),
        "[a-z_]{1,10}",
        any::<f64>().prop_map(|x| x.to_string()),
    ]
}
