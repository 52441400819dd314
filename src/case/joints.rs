//! `boundary.joints` and `boundary.joint_stiffness`: what the crossings are, and the springs
//! of elastic joints.

use super::error::CaseError;
use super::limits::{num, JOINT_STIFFNESS_MAX};
use super::raw::RawBoundary;
use super::tables::{span, Checker};
use crate::model::boundary::{JointStiffness, Joints};
use toml::Value;

/// The names `boundary.joints` takes besides `true` (pin) and `false` (none).
pub const JOINT_NAMES: [&str; 5] = ["pin", "welded", "elastic", "sliding", "none"];

/// The joints of `[boundary]`: pins when not given; springs given exactly when elastic.
pub(super) fn joints(b: &RawBoundary, ck: &Checker) -> Result<Joints, CaseError> {
    let expected = || {
        let names: Vec<String> = JOINT_NAMES.iter().map(|n| format!("\"{n}\"")).collect();
        format!("true (pin), false (none) or one of {}", names.join(", "))
    };
    let kind = match &b.joints {
        None => Joints::Pin,
        Some(v) => match v.get_ref() {
            Value::Boolean(true) => Joints::Pin,
            Value::Boolean(false) => Joints::None,
            Value::String(s) if s == "pin" => Joints::Pin,
            Value::String(s) if s == "none" => Joints::None,
            Value::String(s) if s == "welded" => Joints::Welded,
            Value::String(s) if s == "sliding" => Joints::Sliding,
            Value::String(s) if s == "elastic" => Joints::Elastic(stiffness(b, ck)?),
            Value::String(s) => {
                return Err(ck.invalid(
                    "boundary.joints",
                    v.span(),
                    format!("expected {}, found \"{s}\"", expected()),
                ))
            }
            other => {
                let found = match other {
                    Value::Float(f) => num(*f),
                    Value::Integer(i) => i.to_string(),
                    other => format!("a {}", other.type_str()),
                };
                return Err(ck.invalid(
                    "boundary.joints",
                    v.span(),
                    format!("expected {}, found {found}", expected()),
                ));
            }
        },
    };
    if let (Some(k), false) = (&b.joint_stiffness, matches!(kind, Joints::Elastic(_))) {
        return Err(ck.invalid(
            "boundary.joint_stiffness",
            k.span(),
            format!(
                "springs belong to elastic joints: expected joints = \"elastic\" with them, found joints = {}",
                kind.name()
            ),
        ));
    }
    Ok(kind)
}

/// The springs of elastic joints: both stiffnesses given, from 0 to [`JOINT_STIFFNESS_MAX`].
fn stiffness(b: &RawBoundary, ck: &Checker) -> Result<JointStiffness, CaseError> {
    let Some(raw) = &b.joint_stiffness else {
        let at = b.joints.as_ref().map_or(0..0, |v| v.span());
        return Err(ck.invalid(
            "boundary.joint_stiffness",
            at,
            "elastic joints need their springs: expected joint_stiffness = { scissor = …, out_of_plane = … } (N m/rad)",
        ));
    };
    let inner = raw.get_ref();
    let one = |half: &str, value: &Option<toml::Spanned<f64>>| -> Result<f64, CaseError> {
        let key = format!("boundary.joint_stiffness.{half}");
        let expected = format!(
            "a stiffness in N m/rad from 0 to {}",
            num(JOINT_STIFFNESS_MAX)
        );
        match value {
            None => Err(ck.invalid(
                &key,
                raw.span(),
                format!("expected {half} = {expected}, found none"),
            )),
            Some(v) => {
                let k = *v.get_ref();
                if k.is_finite() && (0.0..=JOINT_STIFFNESS_MAX).contains(&k) {
                    Ok(k)
                } else {
                    Err(ck.invalid(
                        &key,
                        span(value),
                        format!("expected {expected}, found {}", num(k)),
                    ))
                }
            }
        }
    };
    Ok(JointStiffness {
        scissor: one("scissor", &inner.scissor)?,
        out_of_plane: one("out_of_plane", &inner.out_of_plane)?,
    })
}
